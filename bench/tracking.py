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

"""Adaptive tracking against the fixed inverse: a drifting plant and the paper's rig.

1. The drifting plant of ``test/compensation/test_tracking.py`` (the
   independent reference simulator's H, B and first-order sensor; gain
   falling 35 %, offset rising over 90 s): late rms error of the reading
   against the lagged desired value, fixed and adaptive, over noise seeds.
2. The paper's rig with the supply not regulated (``params/paper_rig.yaml``):
   identification as ``hyst-id experiment`` (refined mode, ``--seeds`` GAASS
   seeds), then the compensation run of Eq. 25 closed sample by sample with
   the rig simulator, fixed and adaptive, %eps_c as in docs/RESULTS.md and
   the rms error against the compensator's own desired value.

Usage: ``PYTHONPATH=.:test python bench/tracking.py [--seeds 3] [--forget 5 20 60]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys


sys.path[:0] = [str(Path(__file__).resolve().parents[1] / 'test'),
                str(Path(__file__).resolve().parents[1] / 'test' / 'compensation')]

from hyst_id.compensation import CommandLimits  # noqa: E402, I100
from hyst_id.experiment import run_experiment  # noqa: E402
from hyst_id.experiment.columns import closed_loop_tracking  # noqa: E402
from hyst_id.experiment.run import CLEAN_SERIES, eps_c_percent  # noqa: E402
import test_tracking as drifting  # noqa: E402, I100, I201


def drifting_plant(seeds: int) -> None:
    """Part 1: the reference-simulator plant with gain and offset drift."""
    print('# drifting reference plant: late rms error (reading - lagged desired), noise 0.01')
    print('| seed | fixed | adaptive | final gain (true 0.65) |')
    print('|---|---|---|---|')
    for seed in range(seeds):
        _, fixed, _ = drifting._run(drifting.DESIRED, adaptive=False, seed=seed)
        _, adapt, tracker = drifting._run(drifting.DESIRED, adaptive=True, seed=seed)
        print(f'| {seed} | {drifting._error_late(drifting.DESIRED, fixed):.3f} | '
              f'{drifting._error_late(drifting.DESIRED, adapt):.3f} | {tracker.gain:.3f} |')


def _closed_loop(rig, t, desired, x, sign, channel, seed, forget_s):
    return closed_loop_tracking(rig, t, desired, x, sign, channel, seed, forget_s,
                                CommandLimits(4.0, 20.0))


def paper_rig(seeds: int, forgets: list[float]) -> None:
    """Part 2: the unregulated paper rig, fixed and adaptive."""
    res = run_experiment('params/paper_rig.yaml', regulation=(False,), modes=('refined',),
                         seeds=seeds)
    sc = res.scenarios['off']
    rig = res.rig.with_values({'supply.regulation': False})
    t = sc.reference.t_s
    print('\n# paper rig, supply not regulated: %eps_c (Eq. 26, position-equivalent) / rms '
          'error against the desired value in % of its mean distance from the offset')
    print('| channel | fixed | ' + ' | '.join(f'adaptive, forgetting {f:g} s' for f in forgets)
          + ' |')
    print('|---|---|' + '---|' * len(forgets))
    for ch in ('position', 'pressure', 'flow'):
        r = sc.channels[('refined', ch)]
        cal = sc.calibrations[ch]
        w_ud = sc.reference.truth[CLEAN_SERIES[ch]]
        cells = []
        for f in [None] + forgets:
            w, adaptive = _closed_loop(rig, t, r.desired, r.x_used, r.ident.output_sign, ch,
                                       res.config.comp_noise_seed, f)
            cell = (f'{eps_c_percent(w, w_ud, cal.b):.2f} / '
                    f'{eps_c_percent(w, r.desired, cal.b):.2f}')
            if adaptive is not None:
                cell += f' (gain {adaptive.tracker.gain:.2f})'
            cells.append(cell)
        print(f'| {ch} | ' + ' | '.join(cells) + ' |')


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=3, help='GAASS seeds and plant noise seeds')
    ap.add_argument('--forget', type=float, nargs='+', default=[5.0, 20.0, 60.0])
    args = ap.parse_args()
    drifting_plant(args.seeds)
    paper_rig(args.seeds, args.forget)


if __name__ == '__main__':
    main()
