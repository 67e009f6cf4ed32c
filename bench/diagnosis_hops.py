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

"""What basin hopping costs and gains in a diagnosis's identifications.

Diagnoses a concealed bag (``bags/``, the cases of
``test/diagnosis/test_concealed_bags.py``) with the baseline's hopping at
each ``--hops`` value and prints, per hopping call, its seconds, the samples,
where it started and ended (%e_r over the estimated floor; ``-`` when no jump
did better), then the verdict and the diagnosis's seconds. The default of
``DiagnoseSettings.hops`` (docs/diagnosis.md, "Baseline") is read from it.

Run from the repository root (about 3 minutes on 1 core)::

    python bench/diagnosis_hops.py
    python bench/diagnosis_hops.py --bag case_d --hops 100 20 0
    python bench/diagnosis_hops.py --blind 27          # a recording of the blind family
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'bench'))

from hyst_id.diagnosis import diagnose  # noqa: E402
from hyst_id.identification import driver  # noqa: E402
from hyst_id.io.readers import read_recording  # noqa: E402


def main() -> int:
    """Print the figures."""
    from test_concealed_bags import CASES, SETTINGS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--bag', default='case_h', choices=sorted(CASES))
    ap.add_argument('--blind', type=int, default=None, metavar='N',
                    help="recording N of bench/blind_family.py's family instead of a bag")
    ap.add_argument('--hops', type=int, nargs='+', default=[100, 20])
    args = ap.parse_args()
    calls = []
    hop = driver.hop_with_cost

    def timed(spec, rec, best, settings, floor, *rest, **kwargs):
        t0 = time.perf_counter()
        run, nfev = hop(spec, rec, best, settings, floor, *rest, **kwargs)
        end = f'{run.er_percent / floor:.3f}' if run is not None else '-'
        calls.append(f'    hop {time.perf_counter() - t0:5.1f} s  {rec.n_samples} samples  '
                     f'{best.er_percent / floor:.3f} -> {end} x floor, {nfev} evaluations')
        return run, nfev

    driver.hop_with_cost = timed
    rec = read_recording(ROOT / 'bags' / args.bag, CASES[args.bag][0])
    name = args.bag
    if args.blind is not None:
        from blind_family import draw

        from hyst_id.io.recording import Recording
        case = draw(args.blind)
        rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                        source=f'blind #{args.blind}')
        name = f'blind #{args.blind}'
    for hops in args.hops:
        calls.clear()
        t0 = time.perf_counter()
        d = diagnose(rec, settings=replace(SETTINGS, hops=hops))
        print(f'{name} hops {hops}: {d.verdict}, baseline held-out '
              f'{d.baseline.er_holdout_percent:.4g} %, final {d.final.er_holdout_percent:.4g} %, '
              f'{time.perf_counter() - t0:.1f} s', flush=True)
        print('\n'.join(calls), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
