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

"""Which boundary the diagnosis's baseline starts the chain on, over the blind family.

Every recording of ``bench/blind_family.py`` is simulated starting on the
rising boundary (the reference simulator's default), with or without effects.
The baseline (:func:`hyst_id.diagnosis.challenge.chain_fit`) keeps a chain on
the falling boundary only where the training part says so clearly (a training
BIC lower by ``criteria.bic_drop``); this prints, per recording, the boundary
the diagnosis ran on (``--json``'s ``initial``), from diagnoses with no
mechanism rounds (``max_mechanisms=0``: the baseline and its start checks
only), and how many switched. Run from the repository root (about 15 minutes
for 180 recordings on 2 cores)::

    python bench/start_boundary_family.py [--n 180] [--workers 2]
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from blind_family import draw  # noqa: E402, I100

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.io.recording import Recording  # noqa: E402


def one(index: int) -> tuple[int, str, str, str, float]:
    """Recording ``index``: its channel, effects, the boundary its baseline ran on, seconds."""
    case = draw(index)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    t0 = time.monotonic()
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, max_mechanisms=0))
    return (index, case['channel'], '+'.join(case['effects']) or 'clean',
            str(d.extra.get('initial', '')), time.monotonic() - t0)


def main(argv: list[str] | None = None) -> int:
    """Print each recording's boundary and the count of falling ones."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=180)
    ap.add_argument('--workers', type=int, default=2)
    args = ap.parse_args(argv)
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, range(args.n)))
    for index, channel, effects, initial, seconds in rows:
        print(f'#{index:3d} {channel:8s} {effects:36s} {initial:8s} {seconds:5.1f} s')
    falling = [r for r in rows if r[3] == 'falling']
    print(f'baselines on the falling boundary: {len(falling)} of {len(rows)} (every recording '
          'starts rising)' + (': ' + ', '.join(f'#{r[0]} ({r[2]})' for r in falling)
                              if falling else ''))
    return 0


if __name__ == '__main__':
    sys.exit(main())
