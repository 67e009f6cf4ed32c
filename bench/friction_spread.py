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

"""Spread of the friction block's figures over seeds and round-off (test_friction's bounds).

The recordings of ``test/diagnosis/test_friction.py``: the reference simulator's
chain with a force leading the travel (``chain``, seeds 0-5) and a flat force
with a friction band (``flat``, seeds 0-5), each diagnosed unperturbed and under
the round-off probes (``HYST_ID_ROUNDOFF_PROBE``, another CPU's last bits).
Prints one line per run (verdict, force and presliding over the truth, final
held-out over the floor) and the ranges the tests and docs/diagnosis.md quote.

Run from the repository root (about 8 minutes on 2 cores with the default probes)::

    python bench/friction_spread.py [--probes 0,1,2] [--seeds 6]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

from test_friction import flat_friction_recording, friction_recording  # noqa: E402, I100
from test_friction import SETTINGS  # noqa: E402, I100

from hyst_id.diagnosis import diagnose  # noqa: E402, I100


def run(case: str, seed: int) -> dict:
    """Diagnose one recording; force and presliding over the truth, final over the floor."""
    if case == 'chain':
        rec, force, length = friction_recording(seed)
        length /= 1.05          # in command units: the right line times the backlash
    else:
        rec, force, length = flat_friction_recording(seed), 2.0, 0.15
    d = diagnose(rec, settings=SETTINGS)
    p = d.findings[0].params if d.findings and d.verdict == 'friction' else {}
    return {'verdict': d.verdict,
            'force': p['friction_force'].value / force if p else float('nan'),
            'presliding': p['presliding'].value / length if p else float('nan'),
            'final': d.final.er_holdout_percent / d.noise_floor_percent}


def main() -> None:
    """Run every case under every probe and print the lines and the ranges."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--probes', default='0,1,2', help='0 = unperturbed')
    ap.add_argument('--seeds', type=int, default=6)
    args = ap.parse_args()
    out: dict[str, list] = {'chain': [], 'flat': []}
    for probe in (int(p) for p in args.probes.split(',')):
        os.environ['HYST_ID_ROUNDOFF_PROBE'] = str(probe) if probe else ''
        for case in out:
            for seed in range(args.seeds):
                r = run(case, seed)
                out[case].append(r)
                print(f'probe {probe} {case} seed {seed}: {r["verdict"]}, force '
                      f'{r["force"]:.4f} x, presliding {r["presliding"]:.4f} x, final '
                      f'{r["final"]:.2f} x the floor', flush=True)
    for case, rows in out.items():
        right = [r for r in rows if r['verdict'] == 'friction']
        print(f'\n{case}: named {len(right)}/{len(rows)}')
        for key in ('force', 'presliding', 'final'):
            vals = [r[key] for r in right]
            if vals:
                print(f'  {key}: {min(vals):.4g} - {max(vals):.4g}')


if __name__ == '__main__':
    main()
