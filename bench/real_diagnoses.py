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

"""``diagnose`` on every real recording in ``../shared/data``: the tables of docs/diagnosis.md.

The recordings are read as in ``bench/real_recordings.py`` (cylinder force
against piston displacement; B(H) loops with the sample index as time) and
diagnosed blind with the default settings. Printed per recording: the
baseline's training and held-out %e_r, the measured loop in words (its
direction, half-width and rate signature, from the data alone:
:mod:`hyst_id.diagnosis.measured_loop`), every finding with its block's
parameters and the held-out %e_r after it, the final held-out %e_r over the
noise floor, the rows the criteria judged on, the hold convention, the notes,
and each finding's blocked cross-validation (time blocks better / worse).

Usage (from the repository root; a few minutes in all)::

    python bench/real_diagnoses.py [--data ../shared/data] [--only Circle_1bar]
    python bench/real_diagnoses.py --figures docs/figures    # the docs' figures too
    python bench/real_diagnoses.py --only pneumatic --cli-reader --workers 2   # as the CLI
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from real_recordings import load_all  # noqa: E402, I100

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.diagnosis.blocked_cv import confirmed  # noqa: E402
from hyst_id.diagnosis.export import compensator_set  # noqa: E402
from hyst_id.diagnosis.report import plot_diagnosis  # noqa: E402
from hyst_id.errors import HystIdError  # noqa: E402
from hyst_id.io.csv_reader import read_csv  # noqa: E402


def _params(finding) -> str:
    return ', '.join(f'{k} {q.value:.3g} {q.unit}' for k, q in list(finding.params.items())[:3])


def _as_the_cli(data: Path, rec):
    """The recording as ``hyst-id diagnose`` reads it; prints how many stamps differ."""
    cli = read_csv(data / rec.source, 'position', columns=(0, 4, 6), time_scale=0.001,
                   command_unit='mm', measurement_unit='N')
    if cli.t_s.shape == rec.t_s.shape:
        differ = int(np.count_nonzero(cli.t_s != rec.t_s))
        print(f'{rec.source}: {differ} of {rec.t_s.size} time stamps differ from the '
              "bench reader's in the last bits (t x 0.001 against t / 1000)")
    return cli


def main() -> int:
    """Diagnose each recording and print what the docs' tables hold."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--data', default=str(ROOT.parent / 'shared' / 'data'))
    ap.add_argument('--only', default='', help='substring of the recordings to run')
    ap.add_argument('--figures', metavar='DIR',
                    help="write each diagnosis's figure as DIR/real_<file>.png (docs/figures)")
    ap.add_argument('--workers', type=int, default=1,
                    help="DiagnoseSettings.workers (the CLI's --workers)")
    ap.add_argument('--cli-reader', action='store_true',
                    help="read the cylinder's files as hyst-id diagnose FILE --columns 0,4,6 "
                         '--time-scale 0.001 does (t x 0.001 rather than t / 1000: the last bit '
                         'of some stamps differs)')
    args = ap.parse_args()
    recs = load_all(Path(args.data))
    if args.cli_reader:
        recs = [_as_the_cli(Path(args.data), r) if r.source.startswith('pneumatic') else r
                for r in recs]
    for rec in recs:
        if args.only and args.only not in rec.source:
            continue
        t0 = time.time()
        d = diagnose(rec, settings=DiagnoseSettings(workers=args.workers))
        j = d.extra['judged_holdout']
        print(f'\n{rec.source} ({rec.n_samples} samples, {time.time() - t0:.0f} s): verdict '
              f'{d.verdict}; baseline %e_r train {d.baseline.er_train_percent:.3g} / held-out '
              f'{d.baseline.er_holdout_percent:.3g}; noise floor {d.noise_floor_percent:.3g}')
        print('  ' + d.measured_loop.words(d.measurement_name or 'measurement',
                                           d.measurement_unit))
        for f in d.findings:
            cv = f.blocked_cv
            print(f'  {f.mechanism}: {_params(f)} (held-out {f.er_holdout_before_percent:.3g} '
                  f'-> {f.er_holdout_after_percent:.3g}); blocked CV better {cv["better"]}, '
                  f'worse {cv["worse"]} of {cv["blocks"]}'
                  + ('' if confirmed(cv) else ': not confirmed'))
            for a in f.alternatives:      # judgement calls, and why the finding was chosen
                line = (f'    {a["kind"]} {a["mechanism"]}: judged held-out '
                        f'{a.get("er_judged_after_percent", float("nan")):.3g}, all held-out '
                        f'{a.get("er_holdout_after_percent", float("nan")):.3g}')
                if a['kind'] == 'split':
                    b = a['blocked_cv']
                    line += (f' (the split judged {a["n_judged"]} of {a["n_holdout"]}; '
                             f'{f.mechanism} judged {a["er_judged_chosen_percent"]:.3g}; per '
                             f'block %e_r {a["mechanism"]} '
                             f'{[round(x, 2) for x in b["er_a_percent"]]}, {f.mechanism} '
                             f'{[round(x, 2) for x in b["er_b_percent"]]})')
                print(line)
        try:
            model, aug, _ = compensator_set(d)
            print(f'  compensator set ({model.family}): in-line {aug.describe()}')
        except HystIdError as exc:
            print(f'  compensator set refused: {exc}')
        print(f'  final held-out {d.final.er_holdout_percent:.3g} = '
              f'{d.final.er_holdout_percent / d.noise_floor_percent:.0f} x floor; judged on '
              f'{j["n_samples"]}/{j["n_holdout"]} rows ({j["final_er_percent"]:.3g}); hold '
              f'{d.extra["hold"] or "-"}')
        for note in d.notes:
            print(f'  note: {note}')
        if args.figures:
            name = Path(rec.source).stem
            Path(args.figures).mkdir(parents=True, exist_ok=True)
            path = plot_diagnosis(d, Path(args.figures) / f'real_{name}.png', dpi=72)
            print(f'  figure: {path}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
