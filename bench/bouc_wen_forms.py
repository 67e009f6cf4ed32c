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

"""What ``diagnose`` names on Bouc-Wen loops in their two forms, written apart from the package.

The recordings of ``test/bouc_wen_reference.py`` (a Bouc-Wen state ``dz/dx = 1 - (beta
sign(z dx) + gamma) |z|``, n = 1, explicit Euler, on a sine whose swing comes and goes;
2,000 samples at 20 Hz):

* ``force``: the structural form, a restoring force against its displacement,
  ``F = 0.3 x + 0.7 z`` (beta = gamma = 0.5). The loop runs clockwise (higher while
  the displacement rises), the loop of a sliding element in parallel with a spring:
  a new-user trial's simulator made this loop and counted the ``friction`` verdict
  as a miss. ``z`` saturates at 1: the band is ±0.7.
* ``piezo``: the actuator form, ``x = V - 0.4 z`` (beta 0.8, gamma 0.2), a
  counter-clockwise loop with curved branches: the ``bouc_wen`` block's physics (a
  Dahl state lagging the travel; before that block it was named ``creep``).

Each seed is diagnosed with the tests' quick settings (one GAASS seed, 120
generations, one round, 20 hops) and with the defaults. Printed: verdict, every
finding, the tied and close alternatives of the first, the band where named
(``friction``'s force or ``bouc_wen``'s state height), final held-out %e_r over the
noise floor.

Usage: ``python bench/bouc_wen_forms.py [--seeds 3]`` (about 8 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

from hyst_id.diagnosis import diagnose, DiagnoseSettings

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))
from bouc_wen_reference import bouc_wen_recording  # noqa: E402, I100

QUICK = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1, hops=20)


def main() -> None:
    """Print one line per form, seed and settings."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=3)
    args = ap.parse_args()
    print(f'{"form":6s} {"seed":>4s} {"settings":8s} {"verdict":20s} {"findings":28s} '
          f'{"alternatives":28s} {"band":>6s} {"final/floor":>11s}')
    for form in ('force', 'piezo'):
        for seed in range(args.seeds):
            for label, settings in (('quick', QUICK), ('default', DiagnoseSettings())):
                d = diagnose(bouc_wen_recording(seed, form), settings=settings)
                found = ', '.join(f.mechanism for f in d.findings) or '-'
                alts = ', '.join(a['mechanism'] for a in d.findings[0].alternatives) \
                    if d.findings else ''
                # the band: friction's force, or the height of a Bouc-Wen state in the travel
                force = next((f.params['friction_force'].value if f.mechanism == 'friction'
                              else f.params['state_height'].value for f in d.findings
                              if f.mechanism in ('friction', 'bouc_wen')), float('nan'))
                print(f'{form:6s} {seed:4d} {label:8s} {d.verdict:20s} {found:28s} '
                      f'{alts or "-":28s} {force:6.3f} '
                      f'{d.final.er_holdout_percent / d.noise_floor_percent:11.2f}', flush=True)


if __name__ == '__main__':
    main()
