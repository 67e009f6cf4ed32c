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

"""A gain falling over the run on the position reading, with and without ``gain_loss``.

Recordings (100 s at 20 Hz, a play operator of half-width 20 V behind a gain of
0.13 and an offset of 5, white noise of 0.5 % of the span) written here in plain
numpy (the play of ``test/play_reference.py``), not with the package's chain nor the
test suite's reference simulator:

* ``play, 25 % loss`` / ``play, 10 % loss``: a ±150 V sine (period 6-12 s) whose
  amplitude swings between 20 % and 100 % with a 23 s period; the gain falls
  linearly by 25 % (10 %) over the run about the play's middle;
* ``trial's force reading``: the new-user trial's record (the decaying 10 s sine of
  Eq. 24, a 0.15 s first-order sensor, the gain falling 30 % over the run), where the
  excitation's amplitude falls with time, so a gain falling in time and a curve over
  the level are hard to tell apart;
* ``play, steady gain``: no loss (nothing may be claimed).

Each is diagnosed (default settings) with the library without ``gain_loss`` and
with it; the trial's record also with only the two blocks that made it
(``gain_loss``, ``sensor_lag``). Printed: verdict, findings, the loss found
(%), the final held-out %e_r over the noise floor, and whether the report notes that
the command's swing trends with time (``split_notes.swing_note``).

Usage: ``python bench/gain_loss_trial.py`` (about 5 minutes on 2 cores).
"""

from __future__ import annotations

from pathlib import Path
import sys

from fleet_play_widths import lag   # the bench folder's own first-order lag
import numpy as np

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms.registry import get_mechanisms
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))
from play_reference import play  # noqa: E402, I100


def recordings() -> dict[str, tuple[Recording, float]]:
    """Name -> (recording, true gain loss over the run in %)."""
    t = np.arange(0, 100, 0.05)
    out = {}
    for name, seed, loss in (('play, 25 % loss', 1, 0.25), ('play, 10 % loss', 2, 0.10),
                             ('play, steady gain', 3, 0.0)):
        rng = np.random.default_rng(seed)
        u = 150 * (0.6 + 0.4 * np.sin(2 * np.pi * t / 23.0 + rng.uniform(0, 6))) \
            * np.sin(2 * np.pi * t / rng.uniform(6, 12))
        y = (1 - loss * t / 100) * 0.13 * play(u, 20.0, float(u[0])) + 5.0
        y += rng.normal(0, 0.005 * np.ptp(y), y.size)
        out[name] = (Recording(t, u, y, 'position', 'V', 'um', name), 100 * loss)
    u = 150 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    y = lag(t, 0.13 * play(u, 20.0, float(u[0])) + 5.0, 0.15)
    y += np.random.default_rng(9).normal(0, 0.005 * np.ptp(y), y.size)
    y = 5.0 + (y - 5.0) * (1 - 0.003 * t)
    out["trial's force reading"] = (Recording(t, u, y, 'position', 'V', 'N',
                                              'force, gain falling'), 30.0)
    return out


def main() -> None:
    """Print the table."""
    without = tuple(m.id for m in get_mechanisms(channel='position') if m.id != 'gain_loss')
    print(f'{"recording":24s} {"library":22s} {"verdict":20s} {"findings":38s} '
          f'{"loss %":>7s} {"final/floor":>11s} swing note')
    for name, (rec, loss) in recordings().items():
        libraries = [('without gain_loss', without), ('with gain_loss', None)]
        if name.startswith('trial'):
            libraries.append(('gain_loss, sensor_lag', ('gain_loss', 'sensor_lag')))
        for label, ids in libraries:
            d = diagnose(rec, settings=DiagnoseSettings(mechanisms=ids))
            found = [f.mechanism for f in d.findings]
            lost = next((f.params['gain_loss_percent'].value for f in d.findings
                         if f.mechanism == 'gain_loss'), float('nan'))
            print(f'{name:24s} {label:22s} {d.verdict:20s} {", ".join(found) or "-":38s} '
                  f'{lost:7.1f} {d.final.er_holdout_percent / d.noise_floor_percent:11.2f} '
                  f'{"yes" if any("swing" in n for n in d.notes) else "no"}', flush=True)
        print(f'{"":24s} (true loss {loss:.0f} %)')


if __name__ == '__main__':
    main()
