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

"""Spread of the dead-time block's figures in ``test/diagnosis/test_trial.py``'s round.

The test asserts that the block is accepted, so that the round it compares
between one and two processes is one that decides. This prints the block's
held-out z, training delta BIC and acceptance over ``--seeds`` noise seeds,
each unperturbed and under the round-off probes (the measurement perturbed by
1e-12 relative: another CPU's last bits).

Run from the repository root (about half a minute)::

    python bench/trial_spread.py [--seeds 8] [--probes 3]
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

import test_trial as case  # noqa: E402, I100

from hyst_id.diagnosis.mechanisms import get_mechanisms  # noqa: E402, I100
from hyst_id.diagnosis.result import DiagnoseSettings  # noqa: E402
from hyst_id.diagnosis.trial import try_mechanism  # noqa: E402


def main() -> int:
    """Print the dead-time block's figures over seeds and probes."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=8)
    ap.add_argument('--probes', type=int, default=3)
    args = ap.parse_args()
    m = get_mechanisms(('dead_time',), channel='position')[0]
    rows = []
    for probe in [None, *range(1, args.probes + 1)]:
        for seed in range(args.seeds):
            data, ctx, current, loc = case.delayed_case(seed, probe)
            c = try_mechanism(m, current, data, ctx, DiagnoseSettings(fit_budget=300), loc, [])
            rows.append((c.accepted, c.holdout_z, c.delta_bic))
    z = [r[1] for r in rows]
    bic = [r[2] for r in rows]
    print(f'dead_time: {len(rows)} runs; accepted {sum(r[0] for r in rows)}/{len(rows)}; '
          f'held-out z {min(z):.1f}-{max(z):.1f}; training delta BIC {min(bic):.0f} to '
          f'{max(bic):.0f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
