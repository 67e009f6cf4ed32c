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

"""The drift exchange's decision over seeds (figures of test/diagnosis/test_drift_exchange.py).

The reference chain (``test/reference_sim``, written apart) read through a gain
growing 4 % over the record about a zero five spans below the travel, or
through a zero drifting 4 % of the span (``test/drift_cases.py: forced_offset``),
``offset_drift`` forced in as the final model's block; for each seed, each
time-gain block tried in its place: training BIC and held-out z against the
final model, its own trial, whether the exchange is made and the growth it
fits. Run from the repository root (about a minute)::

    python bench/drift_exchange_spread.py [--seeds 0 1 2 3 4 5]
    HYST_ID_ROUNDOFF_PROBE=1 python bench/drift_exchange_spread.py   # another CPU's round-off
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from drift_cases import forced_offset  # noqa: E402, I100

from hyst_id.diagnosis.exchange import drift_exchange  # noqa: E402, I100


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, nargs='+', default=list(range(6)))
    args = ap.parse_args()
    for drift in ('gain', 'offset'):
        for seed in args.seeds:
            lines: list[str] = []
            x = drift_exchange(**forced_offset(drift, seed), say=lines.append)
            made = 'none'
            if x is not None:
                fit = x.comparison.fit
                rate = float(fit.model.theta(fit.p, x.comparison.mechanism)[0])
                made = f'{x.comparison.mechanism}, growth {100.0 * rate * 120.0:.2f} %'
            print(f'{drift} seed {seed}: exchange {made}')
            for line in lines:
                if 'against the final model' in line:
                    print('   ', line.replace('exchange: ', ''))
    return 0


if __name__ == '__main__':
    sys.exit(main())
