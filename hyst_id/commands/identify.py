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
    prepare_outputs,
    progress_bar,
    reading_notes,
)
from hyst_id.errors import ConfigError
from hyst_id.identification import identify

__all__ = ['add_arguments', 'run']


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``identify``."""
    add_recording_arguments(parser)
    add_settings_arguments(parser)
    add_output_arguments(parser, 'the full result',
                         'DIR:write loop, residual and convergence figures (PNG) into DIR')
    parser.add_argument('--params-out', metavar='FILE',
                        help='write a ROS params file for the compensator node (of the best '
                        'proper loop found when the loop kept is not proper)')
    parser.add_argument('--model', default='tk', metavar='tk|smooth|auto',
                        help="H's family: tk (the paper's piecewise-linear loop, default), "
                        'smooth (Prandtl-Ishlinskii, curved branches) or auto (fit both on '
                        'the first 70 %% of the duration, keep the lower held-out error, '
                        'print both)')


def run(args: argparse.Namespace) -> int:
    """Identify and print the report."""
    from hyst_id.identification.domains import format_domains
    from hyst_id.identification.model_choice import format_choice
    from hyst_id.identification.report import format_table, plot_identification, write_json

    from hyst_id.models.registry import FAMILIES
    if args.model != 'auto' and args.model not in FAMILIES:
        raise ConfigError(f'--model {args.model!r}: not a hysteresis family; known: '
                          f'{sorted(FAMILIES)} or auto')
    rec = load_recording(args)
    settings = make_settings(args)
    prepare_outputs(args, plot_is_folder=True)
    print(f'{rec.source}: {rec.n_samples} samples over {rec.duration_s:.1f} s, '
          f'channel {rec.channel}', file=sys.stderr)
    for note in reading_notes(rec.notes):   # what reading did: stamps sorted, repeats dropped
        print(f'note: {note}', file=sys.stderr)
    choice = None
    if args.model == 'auto':
        choice = _choose(args, rec, settings)
        ident = choice.identification
    else:
        spec = make_spec(args, rec, family=args.model)
        print(f'H family {spec.family.id}; search domains ({spec.domain_source}): '
              + format_domains(spec), file=sys.stderr)
        print('  (the search scales: output-side domains before the calibration to '
              'measurement units and the canonical gauge, so the parameters reported may lie '
              'outside them)', file=sys.stderr)
        bar = _progress_bar(args, settings)
        try:
            ident = identify(rec, spec=spec, settings=settings, progress=bar)
        finally:
            if bar is not None:
                bar.close()
    print(format_table(ident))
    if choice is not None:
        print()
        print(format_choice(choice))
    if args.json:
        try:
            write_json(ident, args.json, extra=None if choice is None
                       else {'model_choice': choice.to_dict()})
        except OSError as exc:
            raise ConfigError(f'cannot write {args.json}: {exc.strerror}') from None
        print(f'wrote {args.json}', file=sys.stderr)
    if args.plot:
        for path in plot_identification(ident, rec, args.plot):
            print(f'wrote {path}', file=sys.stderr)
    if args.params_out:
        _write_params(ident, rec, args.params_out)
    return 0


def _write_params(ident, rec, path: str) -> None:
    """The compensator's params file: of the loop kept, or of the best proper one."""
    from hyst_id.compensation.params_file import command_limits_for, write_compensator_params
    written, why = ident, ''
    if not ident.proper:
        if ident.proper_alternative is None:
            raise ConfigError(f'{path} not written: the loop identified is not proper (see '
                              'the first warning), and the compensator has no exact inverse '
                              'of it; --proper-loops identifies the best proper loop')
        written = ident.proper_alternative
        floor = written.noise_floor_percent
        times = f', {written.er_percent / floor:.2f} x the noise floor' if floor > 0 else ''
        why = (f' with the best proper loop found (%e_r {written.er_percent:.4g}{times}; the '
               f'loop kept, {ident.er_percent:.4g}, is not proper, and the compensator has no '
               'exact inverse of it: see the first warning)')
    limits = command_limits_for(rec.command)
    write_compensator_params(written, path, command_limits=limits)
    said = '' if limits is None else (
        f' (with min_command {limits[0]:g}, max_command {limits[1]:g}, initial_command '
        f"{limits[2]:g}: the recording's commands leave the node's default 4-20)")
    print(f'wrote {path}{why}{said}', file=sys.stderr)


def _choose(args: argparse.Namespace, rec, settings):
    from hyst_id.identification.model_choice import AUTO_FAMILIES, choose_family
    if args.domains != 'auto':
        raise ConfigError("--model auto derives each family's domains from the data; "
                          '--domains must be auto')
    bar = _progress_bar(args, settings, total=len(settings.seeds) * (len(AUTO_FAMILIES) + 1))

    def stage(family: str, what: str) -> None:
        part = 'the first 70 %' if what == 'train' else 'the whole recording'
        print(f'{family}: identify on {part}', file=sys.stderr)

    try:
        return choose_family(rec, AUTO_FAMILIES, settings=settings,
                             progress=None if args.quiet else stage, seed_progress=bar)
    finally:
        if bar is not None:
            bar.close()


def _progress_bar(args: argparse.Namespace, settings,
                  total: int | None = None):
    if getattr(args, 'quiet', False):
        return None
    bar = progress_bar(total=total or len(settings.seeds), desc='GAASS seeds', unit='seed',
                       leave=False)

    def progress(done: int, total: int, run) -> None:
        if run.seed < 0:                # a global run: its most runs grow the total
            bar.total = max(bar.total, total, bar.n + 1)
            bar.set_description('GAASS seeds, global phase')
        bar.update(1)
        bar.set_postfix_str(f'{"run" if run.seed < 0 else "seed"} {run.seed}: '
                            f'%e_r {run.er_percent:.3f}')

    def hopping(jump: int, jumps: int, er: float) -> None:
        if not bar.disable:
            bar.set_postfix_str(f'hopping {jump + 1}/{jumps}: %e_r {er:.3f}' if jump < jumps
                                else f'hopped: %e_r {er:.3f}')

    def restart(what: str) -> None:     # identify tries the record from its first reversal
        bar.reset(total=len(settings.seeds))
        bar.set_description(what)

    progress.restart = restart
    progress.close = bar.close          # the caller's, after identify: hopping and the
    #                                     global phase follow the seeds, and may end early
    progress.hopping = hopping          # basin hopping between the seeds and the global phase
    progress.bar = bar                  # the bar itself (tests)
    return progress
