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

"""Whether a gain drift's chain can be found once the drift is taken out (issue 14, 4).

On the blind family's recordings with one gain drift (``bench/blind_family.py``)
the diagnosis ends several times the floor above it on some (#42, #43, #77,
all random steps), named ``gain_drift`` or ``offset_drift``. This script
separates the two possible causes: ``identify`` (defaults) on the training
part (the first 70 %) as recorded, and on the same part with the true drift
divided out about the sensor's true zero (``(y - zero) / g(t) + zero``, known
from the simulation). If the second reaches the floor, the chain is findable
and what fails is the joint fit of the block and the chain from the
drift-biased baseline, not identification.

Prints per recording: the channel and excitation, the drift over the record,
how far the sensor's zero lies from the readings (in spans), and both
training %e_r over the training noise floor (the package's noise estimate).

Usage, from the repository root (about 20 s per recording on 2 cores)::

    python bench/drift_refit.py [--indices 42 43 64 74 75 77 93 143]
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

from blind_family import draw  # noqa: E402, I100

#: The blind family's single gain drifts that cost more than 3 x the floor.
DEFAULT_INDICES = (42, 43, 64, 74, 75, 77, 93, 143)
TRAIN_FRACTION = 0.7


def main(argv: list[str] | None = None) -> int:
    """Print identify's training fit with and without the true drift, per recording."""
    from hyst_id.identification import identify, IdentifySettings
    from hyst_id.io.recording import Recording
    from hyst_id.signals.noise import estimate_noise_std, floor_percent
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--indices', type=int, nargs='+', default=list(DEFAULT_INDICES))
    args = ap.parse_args(argv)
    print('| # | channel | excitation | drift over record | zero from readings (spans) | '
          'identify / floor | drift divided out / floor | s |')
    print('|---|---|---|---|---|---|---|---|')
    for i in args.indices:
        case = draw(i)
        if case['effects'] != ['gain_drift']:
            print(f'#{i}: effects {case["effects"]}, not one gain drift; skipped')
            continue
        t, y, zero = case['t'], case['measurement'], case['sensor_zero']
        g = case['magnitudes']['gain_drift']
        n = int(TRAIN_FRACTION * t.size)
        undone = (y - zero) / (1.0 + g * t / t[-1]) + zero
        t0 = time.perf_counter()
        ratios = []
        for yy in (y, undone):
            rec = Recording(t[:n], case['command'][:n], yy[:n], case['channel'],
                            source=f'blind #{i}')
            ident = identify(rec, settings=IdentifySettings(workers=2))
            floor = floor_percent(yy[:n], estimate_noise_std(yy[:n]))
            ratios.append(ident.er_percent / floor)
        span = float(np.ptp(y))
        away = abs(float(np.mean(y)) - zero) / span
        print(f'| {i} | {case["channel"]} | {case["excitation"]} | {100 * g:.1f} % | '
              f'{away:.1f} | {ratios[0]:.2f} | {ratios[1]:.2f} | '
              f'{time.perf_counter() - t0:.0f} |', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
