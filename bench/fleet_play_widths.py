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


"""The fleet's maintenance signal on a play that widens, from a simulator written apart.

Two valves, four recordings each (60 s at 20 Hz, the decaying 10 s sine of Eq. 24
scaled to ±150 V): a play operator (half-width 10, 15, 20, 25 V on valve A; 15 V on
every recording of valve B) behind a gain of 0.13, an offset of 5 and a 0.15 s
first-order sensor, with white noise of 0.5 % of the span. The play, the sensor
and the excitation are written here in plain numpy (not the package's chain, nor the
test suite's reference simulator): a new-user trial's data. ``hyst-id fleet``'s
engine (:func:`hyst_id.fleet.run_fleet`, ``--channel pressure --seeds 2``) identifies
them; printed per recording: %e_r over the noise floor, ``loop_width`` (the whole
loop's width in command units), ``h_width`` (``c_r - c_l``) and ``backlash_width``
(``c_br - c_bl``), then the trends. A play of half-width r makes a loop 2 r wide.

Usage: ``python bench/fleet_play_widths.py [--workers 2]`` (about 10 s on 2 cores).
"""

from __future__ import annotations

import argparse
from pathlib import Path
import tempfile

import numpy as np

from hyst_id.fleet import find_recordings, FleetOptions, loop_trends, run_fleet
from hyst_id.fleet.table import fleet_rows


def play(u: np.ndarray, half_width: float) -> np.ndarray:
    """A play operator starting at its lower edge."""
    y, out = -half_width, np.empty_like(u)
    for i, ui in enumerate(u):
        y = min(max(y, ui - half_width), ui + half_width)
        out[i] = y
    return out


def lag(t: np.ndarray, x: np.ndarray, tau_s: float) -> np.ndarray:
    """First-order lag, the previous input held over each step."""
    y = np.empty_like(x)
    y[0] = x[0]
    for i in range(1, x.size):
        a = np.exp(-(t[i] - t[i - 1]) / tau_s)
        y[i] = a * y[i - 1] + (1 - a) * x[i - 1]
    return y


def write_fleet(root: Path) -> None:
    """Valve A's play widens; valve B's stays."""
    t = np.arange(0.0, 60.0, 0.05)
    u = 150.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    for valve, widths in (('valve_a', (10, 15, 20, 25)), ('valve_b', (15, 15, 15, 15))):
        (root / valve).mkdir(parents=True)
        for k, r in enumerate(widths):
            y = lag(t, 0.13 * play(u, r) + 5.0, 0.15)
            y = y + np.random.default_rng(100 + k).normal(0.0, 0.005 * np.ptp(y), y.size)
            np.savetxt(root / valve / f'2026-11-0{k + 1}.csv', np.column_stack([t, u, y]),
                       delimiter=',', header='t,command,measurement', comments='', fmt='%.6g')


def main() -> None:
    """Write the fleet, run it, print the widths and trends."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--workers', type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        write_fleet(root / 'fleet')
        docs = run_fleet(find_recordings([str(root / 'fleet')]), root / 'out',
                         FleetOptions(channel='pressure', seeds=2), workers=args.workers)
        rows = sorted(fleet_rows(docs), key=lambda r: r['recording'])
        print('valve    recording       e_r/floor  loop_width  h_width  backlash_width')
        for r in rows:
            print(f'{r["valve"]}  {Path(r["recording"]).name}  {r["er_over_floor"]:9.3f}  '
                  f'{r["loop_width"]:10.1f}  {r["h_width"]:7.2f}  {r["backlash_width"]:14.2f}')
        for t in loop_trends(rows, metrics=('loop_width', 'h_width', 'backlash_width')):
            print(f'trend {t["valve"]} {t["metric"]}: {t["first"]:.3g} -> {t["last"]:.3g}, '
                  f'{t["change_percent"]:+.0f} %, flagged {t["flagged"]}')


if __name__ == '__main__':
    main()
