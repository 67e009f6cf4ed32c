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

"""Identify's data-built incumbent: the four splits alone, then five more above the floor.

``python bench/start_splits.py [--indices 59 122 ...]``

For clean recordings of ``bench/blind_family.py`` (the independent reference
simulator) whose diagnosis baseline stopped above the floor at 46a79ee, the
training part (first 70 %) in a diagnosis's normalised command scale and the
paper's domains: the best chain
:func:`hyst_id.identification.incumbent.data_incumbent` finds under each
sensor hold from the starts of :data:`hyst_id.identification.starts.SPLITS`
alone (no floor given: identify's default), and with the noise floor given
(the starts of :data:`~hyst_id.identification.starts.MORE_SPLITS` too while
the four stay above it: as identify runs it with ``more_starts``), as %e_r
and as a multiple of the training part's floor; which single split of the
nine reaches the best, and the seconds each took; and what the reference's own
parameters score in the chain under that hold (column ``truth``). Under
``HYST_ID_ROUNDOFF_PROBE=k`` the training part is perturbed at round-off
level first, as identify perturbs what it is given.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

import blind_family  # noqa: E402, I100

from hyst_id.identification import incumbent  # noqa: E402, I100
from hyst_id.identification.chains import chain_spec, er_percent, HOLDS  # noqa: E402
from hyst_id.identification.result import IdentifySettings  # noqa: E402
from hyst_id.identification.starts import MORE_SPLITS, SPLITS  # noqa: E402
from hyst_id.io.recording import Recording, roundoff_probe, validate_recording  # noqa: E402
from hyst_id.signals.noise import noise_floor_percent  # noqa: E402
from hyst_id.signals.split import split_index  # noqa: E402

#: Clean recordings whose baseline stopped above 1.1 x the floor at 46a79ee
#: (docs/diagnosis_blind.json), and #2, a clean one that did not.
DEFAULT_INDICES = (59, 63, 122, 32, 111, 87, 65, 19, 2)


def _incumbent(spec, t, v, y, floor: float | None, splits: tuple = SPLITS) -> float:
    """%e_r of data_incumbent's chain (``splits`` as its first set)."""
    real = incumbent.SPLITS
    incumbent.SPLITS = splits
    try:
        got = incumbent.data_incumbent(spec, t, v, y, IdentifySettings(), floor)
    finally:
        incumbent.SPLITS = real
    if got is None:
        return float('nan')
    return float(er_percent(got[1], y))


def main(argv: list[str] | None = None) -> int:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--indices', type=int, nargs='+', default=list(DEFAULT_INDICES))
    args = ap.parse_args(argv)
    print(f'{"#":>4} {"channel":9} {"hold":7} {"floor":>7} {"truth":>14} {"4 splits":>14} '
          f'{"as identify":>14}'
          f'  best single split   s (4 / as identify)')
    for i in args.indices:
        case = blind_family.draw(i)
        t, u, y = case['t'], case['command'], case['measurement']
        n = split_index(t, 0.7)
        t, u, y = t[:n], u[:n], y[:n]
        lo, hi = float(u.min()), float(u.max())
        half = 0.5 * (hi - lo)
        v = (u - (0.5 * (lo + hi) - 4.5 * half)) / (half / 2.0)   # as diagnose: 7-11
        # perturbed at round-off level under HYST_ID_ROUNDOFF_PROBE, as identify would
        rec = roundoff_probe(validate_recording(Recording(t, v, y, case['channel'])))
        t, v, y = rec.t_s, rec.command, rec.measurement
        floor = noise_floor_percent(y)
        for hold in (HOLDS if case['channel'] != 'position' else HOLDS[:1]):
            spec = replace(chain_spec(case['channel']), hold=hold)
            # the reference's own parameters (a band of 0 included), on its command before
            # the affine map, with the calibration fitted by least squares
            s = spec.signal(spec.from_dict(case['chain_params']), t,
                            case['reference_command'][:n], validate=False)
            kb = np.linalg.lstsq(np.column_stack([s, np.ones_like(s)]), y, rcond=None)[0]
            truth = y - (kb[0] * s + kb[1])
            er_truth = 100.0 * float(np.sqrt(np.sum(truth ** 2) / np.sum(y ** 2)))
            t0 = time.perf_counter()
            old = _incumbent(spec, t, v, y, None)
            t1 = time.perf_counter()
            new = _incumbent(spec, t, v, y, floor)
            t2 = time.perf_counter()
            single = [(_incumbent(spec, t, v, y, None, (s,)), s) for s in SPLITS + MORE_SPLITS]
            best = min(single, key=lambda z: z[0] if np.isfinite(z[0]) else np.inf)
            print(f'{i:>4} {case["channel"]:9} {hold:7} {floor:7.4f} '
                  f'{er_truth:7.4f} {er_truth / floor:5.2f}x '
                  f'{old:7.4f} {old / floor:5.2f}x {new:7.4f} {new / floor:5.2f}x  '
                  f'{best[1]!s:18} {t1 - t0:4.1f} / {t2 - t1:4.1f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
