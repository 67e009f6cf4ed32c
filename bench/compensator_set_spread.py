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

"""Spread behind ``test/diagnosis/test_compensator_set.py``'s bounds (issue 17).

For each seed: a decaying-gain, a dead-time, a bent (static curve) and a clean recording from the
independent reference simulator are diagnosed, the compensator set is
exported and a fresh run of the same plant compensated with and without the
in-line corrections. Prints the rms error of the reading against the
desired value (the recording's noise sd is about 1).

Usage: ``PYTHONPATH=.:test python bench/compensator_set_spread.py [--seeds 4]``
(about 3 minutes for 4 seeds).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

import diagnosis.test_compensator_set as t  # noqa: E402, I100

from hyst_id.compensation.augment import Augmentation  # noqa: E402, I100
from hyst_id.diagnosis import diagnose  # noqa: E402
from hyst_id.diagnosis.export import compensator_set  # noqa: E402

RATE = 1.0 / 600.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=4)
    n = ap.parse_args().seeds
    print('| recording | seed | verdict | fitted | without correction | with |')
    print('|---|---|---|---|---|---|')
    for seed in range(n):
        d = diagnose(t._recording(seed, rate=RATE), settings=t.SETTINGS)
        m, a, _ = compensator_set(d)
        print(f'| decaying gain (rate x 600 s = 1) | {seed} | {d.verdict} | rate x 600 s '
              f'{a.gain_rate_per_s * 600:.3f}, centre {a.gain_centre:.1f} | '
              f'{t._rms_error(m, None, rate=RATE):.3f} | '
              f'{t._rms_error(m, a, rate=RATE):.3f} |', flush=True)
        d = diagnose(t._recording(seed, delay_s=0.5), settings=t.SETTINGS)
        m, a, _ = compensator_set(d)
        print(f'| dead time 0.5 s | {seed} | {d.verdict} | {a.dead_time_s:.4f} s | '
              f'{t._rms_error(m, Augmentation(), delay_s=0.5):.3f} | '
              f'{t._rms_error(m, a, delay_s=0.5):.3f} |', flush=True)
        d = diagnose(t._recording(seed, curve=True), settings=t.SETTINGS)
        m, a, _ = compensator_set(d)
        straight = replace(a, poly_c2=0.0, poly_c3=0.0)
        print(f'| static curve | {seed} | {d.verdict} | {a.describe()} | '
              f'{t._rms_error(m, straight, curve=True):.3f} (straight part of the curve) | '
              f'{t._rms_error(m, a, curve=True):.3f} |', flush=True)
        d = diagnose(t._recording(seed + 4), settings=t.SETTINGS)
        m, a, _ = compensator_set(d)
        print(f'| clean | {seed + 4} | {d.verdict} | {a.describe()} | - | '
              f'{t._rms_error(m, a):.3f} |', flush=True)


if __name__ == '__main__':
    main()
