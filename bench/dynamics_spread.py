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

"""Spread of the dynamics blocks' figures on the reference simulator, over seeds and round-off.

The recordings of ``test/diagnosis/test_actuator_dynamics.py`` (the independent
reference simulator, quick moves and holds): a second-order actuator (zeta 0.3,
2.5 rad/s) on noise seeds 0-7 and a 0.4 s first-order lag on seeds 3-8, each
diagnosed unperturbed and under the round-off probes (``HYST_ID_ROUNDOFF_PROBE``,
another CPU's last bits). Prints one line per run (verdict, fitted parameters,
hold convention, training and held-out %e_r over their floors, the judged
held-out rows) and the ranges the tests' bounds and docs/diagnosis.md quote.

Run from the repository root (about 12 minutes on 2 cores)::

    python bench/dynamics_spread.py [--probes 0,1,2,3]
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

from test_actuator_dynamics import _recording, SETTINGS  # noqa: E402, I100

from hyst_id.diagnosis import diagnose  # noqa: E402, I100

CASES = [('actuator_dynamics', s) for s in range(8)] + [('sensor_lag', s) for s in range(3, 9)]
PARAMS = {'actuator_dynamics': ('zeta', 'omega_n_rad_s'), 'sensor_lag': ('tau_lag_s',)}


def run(case: str, seed: int) -> dict:
    """Diagnose one recording; the figures of one line."""
    rec = _recording(seed, 0.3) if case == 'actuator_dynamics' else \
        _recording(seed, None, lag_s=0.4)
    d = diagnose(rec, settings=SETTINGS)
    j = d.extra['judged_holdout']
    f = d.findings[0] if d.findings else None
    return {'verdict': d.verdict, 'hold': d.extra['hold'],
            'params': {k: f.params[k].value for k in PARAMS[case] if f and k in f.params},
            'train': d.final.er_train_percent / d.noise_floor_train_percent,
            'holdout': d.final.er_holdout_percent / d.noise_floor_percent,
            'before': d.baseline.er_holdout_percent / d.noise_floor_percent,
            'judged': j['final_er_percent'] / j['noise_floor_percent'],
            'n_judged': j['n_samples'], 'n_holdout': j['n_holdout']}


def main() -> None:
    """Run every case under every probe and print the lines and the ranges."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--probes', default='0,1,2,3', help='0 = unperturbed')
    probes = [int(p) for p in ap.parse_args().probes.split(',')]
    out = {case: [] for case, _ in CASES}
    for probe in probes:
        os.environ['HYST_ID_ROUNDOFF_PROBE'] = str(probe) if probe else ''
        for case, seed in CASES:
            r = run(case, seed)
            out[case].append(r)
            ps = ' '.join(f'{k} {v:.4g}' for k, v in r['params'].items())
            print(f'probe {probe} {case:17s} seed {seed}: {r["verdict"]:17s} {ps:30s} hold '
                  f'{r["hold"] or "-":6s} train {r["train"]:.2f} x, held-out {r["holdout"]:.2f} x '
                  f'(before {r["before"]:.1f} x), judged {r["n_judged"]}/{r["n_holdout"]} '
                  f'{r["judged"]:.2f} x', flush=True)
    for case, rows in out.items():
        right = [r for r in rows if r['verdict'] == case]
        print(f'\n{case}: named {len(right)}/{len(rows)}, hold after '
              f'{sum(r["hold"] == "after" for r in right)}/{len(right)}')
        for k in PARAMS[case]:
            vals = [r['params'][k] for r in right if k in r['params']]
            if vals:
                print(f'  {k}: {min(vals):.4g} - {max(vals):.4g}')
        for key in ('train', 'judged', 'holdout', 'before'):
            vals = [r[key] for r in right]
            if vals:
                print(f'  {key} / floor: {min(vals):.2f} - {max(vals):.2f}')


if __name__ == '__main__':
    main()
