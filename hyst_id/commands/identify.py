# Copyright 2026 The hyst_id authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""``hyst-id identify RECORDING``: GAASS identification with a Table 1 report."""

from __future__ import annotations

import argparse
import sys

from hyst_id.commands.common import (
    add_output_arguments,
    add_recording_arguments,
    add_settings_arguments,
    load_recording,
    make_settings,
    make_spec,
)
from hyst_id.identification import identify

__all__ = ['add_arguments', 'run']


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``identify``."""
    add_recording_arguments(parser)
    add_settings_arguments(parser)
    add_output_arguments(parser, 'the full result',
                         'DIR:write loop, residual and convergence figures (PNG) into DIR')
    parser.add_argument('--params-out', metavar='FILE',
                        help='write a ROS params file for the compensator node')


def run(args: argparse.Namespace) -> int:
    """Identify and print the report."""
    from hyst_id.identification.report import format_table, plot_identification, write_json

    rec = load_recording(args)
    spec = make_spec(args, rec)
    settings = make_settings(args)
    print(f'{rec.source}: {rec.n_samples} samples over {rec.duration_s:.1f} s, '
          f'channel {rec.channel}', file=sys.stderr)
    print('search domains (' + spec.domain_source + '): ' + ', '.join(
        f'{n} [{lo:.4g}, {hi:.4g}]' for n, (lo, hi) in zip(spec.names, spec.bounds)),
        file=sys.stderr)
    ident = identify(rec, spec=spec, settings=settings, progress=_progress_bar(args, settings))
    print(format_table(ident))
    if args.json:
        write_json(ident, args.json)
        print(f'wrote {args.json}', file=sys.stderr)
    if args.plot:
        for path in plot_identification(ident, rec, args.plot):
            print(f'wrote {path}', file=sys.stderr)
    if args.params_out:
        from hyst_id.compensation.params_file import write_compensator_params
        write_compensator_params(ident, args.params_out)
        print(f'wrote {args.params_out}', file=sys.stderr)
    return 0


def _progress_bar(args: argparse.Namespace, settings):
    if getattr(args, 'quiet', False):
        return None
    from tqdm import tqdm
    bar = tqdm(total=len(settings.seeds), desc='GAASS seeds', unit='seed', file=sys.stderr,
               leave=False)

    def progress(done: int, total: int, run) -> None:
        bar.update(1)
        bar.set_postfix_str(f'seed {run.seed}: %e_r {run.er_percent:.3f}')
        if done == total:
            bar.close()

    return progress
