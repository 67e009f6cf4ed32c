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

"""Stick-slip over noise seeds: verdict, slip band and held-out %e_r / noise floor per seed.

The synthetic stiction record of ``test/diagnosis/test_diagnose.py`` (the paper's chain,
slip band 4 % of the travel, 0.005 noise) with seeds 5-16, diagnosed with the
test's settings, one seed at a time. The spread over seeds and round-off
that the tests' thresholds come from is ``bench/claim_spreads.py``.

Usage (from the repository root)::

    python bench/stiction_seeds.py [--seeds 5-16]
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))

from test_diagnose import FAST, synthetic  # noqa: E402,I100

from hyst_id.diagnosis import diagnose  # noqa: E402


def main(argv=None) -> int:
    """Diagnose every seed and print one line each, then the count at the floor."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', default='5-16', help='first-last seed')
    args = ap.parse_args(argv)
    first, last = (int(x) for x in args.seeds.split('-'))
    at_floor = 0
    for seed in range(first, last + 1):
        d = diagnose(synthetic('stiction', seed=seed), settings=FAST)
        ratio = d.final.er_holdout_percent / d.noise_floor_percent
        band = d.findings[0].params['slip_band'].value if d.findings else float('nan')
        at_floor += ratio < 1.5
        print(f'seed {seed}: {d.verdict}, slip band {band:.4g}, held-out %e_r '
              f'{d.baseline.er_holdout_percent:.3g} -> {d.final.er_holdout_percent:.3g} '
              f'= {ratio:.2f} x the floor', flush=True)
    print(f'{at_floor} of {last - first + 1} at the noise floor (< 1.5 x) on held-out data')
    return 0


if __name__ == '__main__':
    sys.exit(main())
