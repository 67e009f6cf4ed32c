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

"""Spread of the re-identification's figures over noise seeds and round-off probes.

``test/diagnosis/test_refit.py`` asserts on three noise seeds of a gain drift
about a distant zero (moves and holds, the reference simulator) whose block,
fitted locally from a chain the drift biased, stops short of the floor. This
prints, for ``--seeds`` seeds, each unperturbed and under the round-off
probes (the measurement perturbed by 1e-12 relative, another CPU's last
bits): the local fit's and the re-identified fit's training %e_r over the
training floor, the re-identified growth rate (truth 0.0008 /s) and the
seconds the re-identification took, so that the test's seeds and bounds sit
outside what the computation gives elsewhere. Then the backward check of
``test/diagnosis/test_null_control.py`` (``control.drop_superseded``) over the
same seeds and probes: what it withdrew from ``offset_drift`` + ``gain_drift``
on a gain drift about a distant zero and from ``dead_time`` + ``offset_drift``
on a record with both, and the final held-out %e_r over the floor.

Run from the repository root (about five minutes on 2 cores)::

    python bench/refit_spread.py [--seeds 16] [--probes 3]
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

import test_null_control as pair  # noqa: E402, I100
import test_refit as case  # noqa: E402

from hyst_id.diagnosis.control import drop_superseded  # noqa: E402, I100
from hyst_id.diagnosis.refit import reidentify  # noqa: E402
from hyst_id.diagnosis.result import DiagnoseSettings  # noqa: E402
from hyst_id.diagnosis.select import Criteria  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    """Print local and re-identified fits per seed and probe, then the spreads."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=16)
    ap.add_argument('--probes', type=int, default=3)
    args = ap.parse_args(argv)
    print('| seed | probe | local / floor | re-identified / floor | growth [1/s] | s |')
    print('|---|---|---|---|---|---|')
    stuck, after = [], []
    for seed in range(args.seeds):
        for probe in [None, *range(1, args.probes + 1)]:
            data, ctx, spec, local, floor = case._local_fit(seed, probe)
            t0 = time.perf_counter()
            again = reidentify(local, data, ctx, spec, DiagnoseSettings(),
                               floor_train_percent=floor)
            sec = time.perf_counter() - t0
            a, b = local.er_train_percent / floor, again.er_train_percent / floor
            rate = float(again.model.theta(again.p, 'gain_drift')[0])
            print(f'| {seed} | {probe or "-"} | {a:.3f} | {b:.3f} | {rate:.3g} | {sec:.1f} |',
                  flush=True)
            if a > case.REFIT_ABOVE_TEST:
                stuck.append((seed, probe))
                after.append(b)
    print(f'\nlocal fits above {case.REFIT_ABOVE_TEST} x the floor: {len(stuck)} '
          f'({sorted({s for s, _ in stuck})} by seed); re-identified: '
          f'{min(after, default=float("nan")):.3f} - {max(after, default=float("nan")):.3f} x')
    print('\n| pair | seed | probe | withdrawn | final held-out / floor |')
    print('|---|---|---|---|---|')
    for effects in ('gain', 'delay+drift'):
        for seed in range(args.seeds):
            for probe in [None, *range(1, args.probes + 1)]:
                data, order, current = pair._two_blocks(effects, seed, probe)
                final, out = drop_superseded(current, list(order), data, Criteria(),
                                             max_nfev=1200)
                print(f'| {effects} | {seed} | {probe or "-"} | {",".join(out) or "-"} | '
                      f'{final.er_holdout_percent / data.floor_holdout_percent:.3f} |',
                      flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
