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

"""How the blind family's commands' swings trend with time (``split_notes.swing_note``).

For each of the family's 180 recordings (``bench/blind_family.py``'s draws): the
rank correlation of the command's reversal-to-reversal swings with their times;
printed per excitation kind: how many reach ``SWING_RHO`` (the note's threshold,
given a time gain or level shape is named) and the range.

Usage: ``python bench/swing_trends.py`` (about 20 s).
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
import sys

import numpy as np

from hyst_id.diagnosis.split_notes import SWING_RHO, swing_trend

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blind_family  # noqa: E402, I100


def main() -> None:
    """Print one line per excitation kind."""
    rho = defaultdict(list)
    for i in range(180):
        case = blind_family.draw(i)
        rho[case['excitation']].append(swing_trend(case['t'], case['command'])[0])
    print(f'{"excitation":16s} {"n":>3s} {"|rho| >= " + str(SWING_RHO):>12s}  rho range')
    for kind, r in rho.items():
        r = np.asarray(r)
        print(f'{kind:16s} {r.size:3d} {int(np.sum(np.abs(r) >= SWING_RHO)):12d}  '
              f'{np.nanmin(r):+.2f} .. {np.nanmax(r):+.2f}')


if __name__ == '__main__':
    main()
