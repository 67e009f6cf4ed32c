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

"""``hyst-id experiment``: reproduce the paper's section 4 on the simulated rig.

Identification from the three sensors (Eq. 24, ten GAASS seeds), Table 1,
compensation with Eq. 25 and %ε_c (Eq. 26), Figs. 2 and 4-7; and issue 17's
columns: (a) the paper's fixed H⁻¹, (b) the model augmented with what a
diagnosis of the identification run found, (c) adaptive tracking
(``--no-adaptive`` skips (b) and (c)). Writes
``results.json``, ``results.md`` and the PNG figures into ``--out`` and prints
the headline tables; see ``docs/RESULTS.md``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import shutil
import sys

from hyst_id.commands.common import progress_bar
from hyst_id.diagnosis import DiagnoseSettings
from hyst_id.errors import ConfigError
from hyst_id.identification import IdentifySettings
from hyst_id.io.outputs import make_output_folder

__all__ = ['add_arguments', 'run', 'QUICK_DIAGNOSIS', 'QUICK_SETTINGS', 'DEFAULT_PARAMS']

DEFAULT_PARAMS = 'params/paper_rig.yaml'
#: ``--quick``: a short GAASS and a light refinement, for tests and smoke runs.
QUICK_SETTINGS = IdentifySettings(maxiter=150, seeds=(0, 1), restarts=1, refine_top=1,
                                  refine_max_nfev=600)
#: ``--quick``: one GAASS seed, a short run and 20 hops for the diagnosis of columns (b)/(c).
QUICK_DIAGNOSIS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=2, hops=20)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``experiment``."""
    parser.add_argument('--params', metavar='YAML', default=DEFAULT_PARAMS,
                        help=f"rig params file (default {DEFAULT_PARAMS}: the paper's rig)")
    parser.add_argument('--out', metavar='DIR', default='results/experiment',
                        help='output directory (default results/experiment)')
    parser.add_argument('--seeds', type=int, default=None,
                        help='GAASS seeds 0..N-1 (default 10, the paper; 2 with --quick)')
    parser.add_argument('--gaass-only', action='store_true',
                        help="only the paper's procedure (no GAASS + refinement run)")
    parser.add_argument('--regulation', choices=('off', 'on', 'both'), default='off',
                        help='supply pressure regulation: off = blow-down as in the paper '
                        '(default), on, or both (to see what the decay explains)')
    parser.add_argument('--quick', action='store_true',
                        help='150 generations, 2 seeds, light refinement (smoke test)')
    parser.add_argument('--workers', type=int, default=0,
                        help='processes for the GAASS seeds (0: one per core)')
    parser.add_argument('--compensate-with', choices=('best', 'mean'), default='best',
                        help="parameter set for H^-1: best seed (default) or the seeds' mean")
    parser.add_argument('--copy-figures', metavar='DIR', default=None,
                        help='also copy the Fig. 4-7 PNGs into DIR (e.g. docs/figures)')
    parser.add_argument('--no-fig2', action='store_true', help='skip Fig. 2 (GAASS on F1)')
    parser.add_argument('--no-adaptive', action='store_true',
                        help="skip issue 17's columns (b) augmented by a diagnosis of the "
                        'identification run and (c) adaptive tracking')
    parser.add_argument('--quiet', action='store_true', help='no progress bar')


def _params_path(text: str) -> Path:
    path = Path(text)
    if path.is_file() or text != DEFAULT_PARAMS:
        return path
    candidates = [Path(__file__).resolve().parents[2] / DEFAULT_PARAMS]
    try:  # installed package: share/hyst_id/params
        from ament_index_python.packages import get_package_share_directory
        candidates.append(Path(get_package_share_directory('hyst_id')) / DEFAULT_PARAMS)
    except Exception:  # noqa: BLE001 - ament index absent or package not installed
        pass
    for cand in candidates:
        if cand.is_file():
            return cand
    raise ConfigError(f'cannot find {DEFAULT_PARAMS}; give --params')


def _command_line(args: argparse.Namespace) -> str:
    parts = ['hyst-id experiment', f'--params {args.params}', f'--out {args.out}']
    if args.seeds is not None:
        parts.append(f'--seeds {args.seeds}')
    parts += [f'--regulation {args.regulation}']
    for flag in ('gaass_only', 'quick', 'no_fig2', 'no_adaptive'):
        if getattr(args, flag):
            parts.append('--' + flag.replace('_', '-'))
    if args.compensate_with != 'best':
        parts.append(f'--compensate-with {args.compensate_with}')
    if args.copy_figures:
        parts.append(f'--copy-figures {args.copy_figures}')
    return ' '.join(parts)


def run(args: argparse.Namespace) -> int:
    """Run the experiment, write the outputs, print the headline tables."""
    from dataclasses import replace

    from hyst_id.experiment import ExperimentConfig, MODES, run_experiment
    from hyst_id.experiment.report import format_markdown, write_outputs

    base = QUICK_SETTINGS if args.quick else IdentifySettings()
    n_seeds = args.seeds if args.seeds is not None else len(base.seeds)
    if n_seeds < 1:
        raise ConfigError('--seeds must be >= 1')
    settings = replace(base, workers=args.workers)
    regulation = {'off': (False,), 'on': (True,), 'both': (False, True)}[args.regulation]
    modes = ('gaass',) if args.gaass_only else MODES
    command = _command_line(args)
    params = _params_path(args.params)
    make_output_folder(Path(args.out), '--out', args.out)      # before the work, not after
    if args.copy_figures:
        make_output_folder(Path(args.copy_figures), '--copy-figures', args.copy_figures)
    print(f'{command}\nrig {params}; regulation {args.regulation}; modes {", ".join(modes)}; '
          f'{n_seeds} seeds', file=sys.stderr)
    bar = None
    if not args.quiet:
        bar = progress_bar(desc='GAASS seeds', unit='seed', dynamic_ncols=True)

    def progress(advance: int, total: int, message: str) -> None:
        if bar is not None:
            bar.total = total
            bar.update(advance)
            bar.set_postfix_str(message, refresh=False)

    try:
        result = run_experiment(params, settings=settings, seeds=n_seeds,
                                regulation=regulation, modes=modes,
                                config=ExperimentConfig(compensate_with=args.compensate_with),
                                progress=progress, adaptive=not args.no_adaptive,
                                diagnose_settings=QUICK_DIAGNOSIS if args.quick else None)
    finally:
        if bar is not None:
            bar.close()
    paths = write_outputs(result, args.out, command=command, fig2=not args.no_fig2)
    markdown = format_markdown(result, command)
    print(markdown.split('## %e_r (Eq. 7)')[0].rstrip())
    if args.copy_figures:
        dest = Path(args.copy_figures)
        for name, path in paths.items():
            if path.suffix == '.png' and name != 'fig2':
                shutil.copy2(path, dest / path.name)
                print(f'copied {path.name} to {dest}', file=sys.stderr)
    for path in paths.values():
        print(f'wrote {path}', file=sys.stderr)
    print(f'total {result.timings_s["total"]:.0f} s', file=sys.stderr)
    return 0
