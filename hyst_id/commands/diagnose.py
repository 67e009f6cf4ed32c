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

"""``hyst-id diagnose RECORDING``: where the record departs from the model, and which physics.

Without ``--sim`` the paper's chain of the channel is fitted on the first
part of the record (``--train-fraction``, default 0.7) and the library of
mechanisms is tested against the held-out rest (:mod:`hyst_id.diagnosis`).
With ``--sim PARAMS.yaml`` the rig simulator is driven by the recording's
command instead, its found effects are switched on and the updated
parameters written (``--sim-out``). ``--params-out FILE`` writes the
compensator's params file from the diagnosis's final model: H and B refitted
with the accepted blocks, and the blocks' in-line corrections
(:mod:`hyst_id.diagnosis.export`).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
import sys

from hyst_id.commands.common import (
    add_output_arguments,
    add_recording_arguments,
    add_settings_arguments,
    load_recording,
    make_spec,
    prepare_outputs,
)
from hyst_id.errors import ConfigError

__all__ = ['add_arguments', 'MAX_JOINT_GENERATIONS', 'run']

#: Most generations of the joint search (``--joint-generations``): beyond 33 times the
#: default a typo is likelier than a wish.
MAX_JOINT_GENERATIONS = 10000


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``diagnose``."""
    add_recording_arguments(parser)
    add_settings_arguments(parser, identify=False)
    parser.set_defaults(seeds=2, generations=200)
    g = parser.add_argument_group('diagnosis')
    g.add_argument('--train-fraction', type=float, default=0.7,
                   help='share of the duration used for fitting; the rest is held out')
    g.add_argument('--mechanisms', default=None, metavar='ID,ID',
                   help='mechanisms to test (default: all of them)')
    g.add_argument('--max-mechanisms', type=int, default=2,
                   help='most mechanisms added one after the other (default 2)')
    g.add_argument('--joint-generations', type=int, default=0, metavar='N',
                   help="generations of each round's joint search of its leading blocks "
                   'with the chain over the whole box (300 finds what the local fits miss '
                   'where the chain absorbed the effect, at seconds per search; default 0: '
                   'none)')
    add_output_arguments(g, 'the diagnosis', 'FILE.png|DIR:write the figure')
    g.add_argument('--params-out', metavar='FILE.yaml',
                   help="compensator params file: the final model's H and B with the "
                   'in-line corrections of what was found (augment.*)')
    g.add_argument('--sim', metavar='PARAMS.yaml',
                   help='compare the rig simulator with these parameters against the '
                   'recording (no baseline fit)')
    g.add_argument('--sim-out', metavar='FILE.yaml',
                   help='updated simulator parameters (default: <params>_diagnosed.yaml in '
                   'the current directory)')


def _settings(args: argparse.Namespace):
    from hyst_id.diagnosis import DiagnoseSettings
    from hyst_id.diagnosis.mechanisms import get_mechanisms

    if args.seeds < 1 or args.pop_size < 2 or args.generations < 1:
        raise ConfigError('need --seeds >= 1, --pop-size >= 2 and --generations >= 1')
    if args.max_mechanisms < 1:
        raise ConfigError('--max-mechanisms must be at least 1')
    if args.hops < 0:
        raise ConfigError('--hops must be at least 0')
    if not 0 <= args.joint_generations <= MAX_JOINT_GENERATIONS:
        raise ConfigError(f'--joint-generations must be 0 to {MAX_JOINT_GENERATIONS}, got '
                          f'{args.joint_generations}')
    if args.workers < 0:
        raise ConfigError(f'--workers must be >= 0 (0: one per core), got {args.workers}')
    mechs = None
    if args.mechanisms is not None:
        mechs = tuple(m.strip() for m in args.mechanisms.split(','))
        if not all(mechs):
            raise ConfigError(f'--mechanisms {args.mechanisms!r}: an empty name; give ids '
                              'separated by commas (leave the option out for all of them)')
        get_mechanisms(mechs)
    return DiagnoseSettings(
        train_fraction=args.train_fraction,
        seeds=tuple(range(args.seed_offset, args.seed_offset + args.seeds)),
        generations=args.generations, pop_size=args.pop_size, workers=args.workers,
        mechanisms=mechs, max_mechanisms=args.max_mechanisms, hops=args.hops,
        more_starts=args.more_starts, start_state=not args.whole_record,
        loose_loops=not args.proper_loops,
        joint_generations=args.joint_generations)


def _write_params(diag, path: str) -> None:
    from hyst_id.compensation.params_file import command_limits_for, write_compensator_params
    from hyst_id.diagnosis.export import compensator_set
    from hyst_id.errors import InvalidParametersError

    if diag.mode != 'model':
        raise ConfigError('--params-out needs the model diagnosis (not --sim)')
    if diag.extra.get('proper_loop') is False:
        raise ConfigError(f'cannot write {path}: the loop the diagnosis ran over is not a proper '
                          'one (its output jumps at some reversals: see the notes) '
                          'and the compensator cannot invert it; `hyst-id identify '
                          '--proper-loops --params-out` writes the best proper loop')
    try:
        model, aug, applied = compensator_set(diag)
    except InvalidParametersError as exc:
        raise ConfigError(f'cannot write {path}: {exc}; identify the set with '
                          '`hyst-id identify --params-out`') from None
    values = {'channel': diag.channel, 'er_percent': diag.final.er_holdout_percent,
              **model.as_mapping(), 'augment': aug}
    limits = command_limits_for(diag.command)
    write_compensator_params(values, path, command_limits=limits)
    if limits is not None:
        print(f'compensator: min_command {limits[0]:g}, max_command {limits[1]:g}, '
              f'initial_command {limits[2]:g} (the '
              "recording's commands leave the node's default 4-20)", file=sys.stderr)
    diag.extra['compensator'] = {'params_out': str(path),
                                 'applied': [{'mechanism': m, 'how': how} for m, how in applied]}
    for mech, how in applied:
        print(f'compensator: {mech}: {how}', file=sys.stderr)
    print(f'wrote {path} (compensator set: the final model and its in-line corrections: '
          f'{aug.describe()})', file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    """Diagnose and print the report."""
    from hyst_id.diagnosis import diagnose
    from hyst_id.diagnosis.report import plot_diagnosis

    settings = _settings(args)
    if not 0.0 < args.train_fraction < 1.0:
        raise ConfigError(f'--train-fraction must be in (0, 1), got {args.train_fraction}')
    if args.sim_out and not args.sim:
        raise ConfigError('--sim-out names where the diagnosed simulator params go: it needs '
                          '--sim PARAMS.yaml')
    rec = load_recording(args)
    prepare_outputs(args, plot_is_folder=False)
    say = None if args.quiet else (lambda msg: print(f'[diagnose] {msg}', file=sys.stderr))
    print(f'{rec.source}: {rec.n_samples} samples over {rec.duration_s:.1f} s, channel '
          f'{rec.channel}', file=sys.stderr)
    updated = None
    if args.sim:
        from hyst_id.diagnosis.sim_compare import diagnose_sim
        from hyst_id.rig import load_rig_params
        base = load_rig_params(args.sim)
        diag, updated = diagnose_sim(rec, base, settings=settings, progress=say)
    else:
        spec = None if args.domains == 'auto' else make_spec(args, rec)
        diag = diagnose(rec, spec=spec, settings=settings, progress=say)
    print(diag.report())
    params_error = None
    if args.params_out:
        try:
            _write_params(diag, args.params_out)
        except ConfigError as exc:      # the report, JSON and figure are still written
            params_error = exc
    if updated is not None:
        from hyst_id.rig import save_rig_params
        out = Path(args.sim_out) if args.sim_out else Path(
            f'{Path(args.sim).stem}_diagnosed.yaml')
        save_rig_params(updated, out)
        diag.extra['simulator_params_out'] = str(out)
        print(f'wrote {out} (simulator with the found effects switched on)', file=sys.stderr)
    if args.json:
        try:
            Path(args.json).write_text(json.dumps(diag.to_dict(), indent=2) + '\n',
                                       encoding='utf-8')
        except OSError as exc:
            raise ConfigError(f'cannot write {args.json}: {exc.strerror}') from None
        print(f'wrote {args.json}', file=sys.stderr)
    if args.plot:
        try:
            path = plot_diagnosis(diag, args.plot)
        except OSError as exc:
            raise ConfigError(f'cannot write the figure {args.plot}: {exc.strerror}') from None
        print(f'wrote {path}', file=sys.stderr)
    if params_error is not None:
        raise params_error
    return 0
