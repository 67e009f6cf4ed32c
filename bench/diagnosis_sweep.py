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

"""Sweep: every mechanism at three magnitudes and three seeds, plus clean runs.

Each run is a recording of the pipeline rig simulator (:mod:`hyst_id.rig`)
with one effect switched on at a magnitude from barely above the noise to
strong (:data:`SWEEP`), diagnosed blind with the default settings. Prints
the confusion matrix (true mechanism x verdict), the detection rate per
magnitude and the detection threshold per mechanism (the smallest magnitude
found in every seed), and writes them to ``docs/diagnosis_sweep.md`` and
the raw results to ``docs/diagnosis_sweep.json``.

Usage (from the repository root)::

    python bench/diagnosis_sweep.py [--workers 2] [--seeds 3] [--only dead_time,...]
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import json
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402
from hyst_id.diagnosis.mechanisms import MECHANISM_IDS  # noqa: E402
from hyst_id.rig import RigParams, simulate_rig  # noqa: E402
from hyst_id.signals.excitation import multisine  # noqa: E402

DT_S, DURATION_S = 0.05, 120.0
PRESSURE = {'pressure_sensor.noise_std_pa': 1000.0}
#: Actuator whose hysteron shows its own top line above 9.6 mA (travel top 9.71 mA-eq):
#: with the default one a fitted hysteron reproduces any end stop with its top line.
TOP_LINE_ACTUATOR = {'actuator.m_t': 0.3, 'actuator.c_t': 6.675, 'actuator.c_b': 5.0}

#: mechanism -> (channel, magnitude name, unit, three magnitudes, rig settings for one)
SWEEP = {
    'dead_time': ('position', 'delay_s', 's', (0.06, 0.09, 0.15),
                  lambda x: {'effects.dead_time.enabled': True, 'effects.dead_time.delay_s': x}),
    'sensor_lag': ('position', 'tau_s', 's', (0.02, 0.05, 0.3),
                   lambda x: {'effects.sensor_lag.enabled': True,
                              'effects.sensor_lag.position_tau_s': x}),
    'supply_decay': ('pressure', 'vessel volume x', '1', (10.0, 3.0, 1.0),
                     lambda x: {**PRESSURE, 'supply.regulation': False,
                                'supply.vessel_volume_m3': 0.681374 * x}),
    'offset_drift': ('position', 'rate', 'mA-eq/s', (0.00003, 0.0001, 0.002),
                     lambda x: {'effects.offset_drift.enabled': True,
                                'effects.offset_drift.position_per_s': x}),
    'saturation': ('position', 'stop below the top of travel', 'mA-eq', (0.01, 0.03, 0.12),
                   lambda x: {**TOP_LINE_ACTUATOR, 'effects.end_stops.enabled': True,
                              'effects.end_stops.min_position': 0.0,
                              'effects.end_stops.max_position': 9.71 - x}),
    'stiction': ('position', 'static band', 'mA-eq', (0.02, 0.06, 0.15),
                 lambda x: {'effects.stick_slip.enabled': True,
                            'effects.stick_slip.static_band': x,
                            'effects.stick_slip.dynamic_band': x / 3.0}),
    'static_nonlinearity': ('pressure', 'rangeability', '1', (2.0, 5.0, 20.0),
                            lambda x: {**PRESSURE, 'effects.valve_characteristic.enabled': True,
                                       'effects.valve_characteristic.rangeability': x}),
    'rate_dependence': ('position', 'width_per_rate_s', 's', (0.02, 0.08, 0.3),
                        lambda x: {'effects.rate_hysteresis.enabled': True,
                                   'effects.rate_hysteresis.width_per_rate_s': x}),
}
AMPLITUDE_MA = {'position': 1.8, 'pressure': 1.0}


def run_one(job: tuple) -> dict:
    """Simulate one case and diagnose it blind."""
    truth, channel, level, magnitude, values, seed = job
    t = np.arange(0.0, DURATION_S, DT_S)
    v = multisine(t, amplitude_ma=AMPLITUDE_MA[channel])
    run = simulate_rig(RigParams().with_values(values), t, v, seed=100 + seed)
    t0 = time.time()
    d = diagnose(run.recording(channel), settings=DiagnoseSettings(workers=1))
    return {'truth': truth, 'channel': channel, 'level': level, 'magnitude': magnitude,
            'seed': seed, 'verdict': d.verdict, 'final': list(d.final.ids),
            'alternatives': [a['mechanism'] for a in d.findings[0].alternatives
                             if a.get('kind', 'tied') == 'tied']
            if d.findings else [],
            'er_holdout_before': d.baseline.er_holdout_percent,
            'er_holdout_after': d.final.er_holdout_percent,
            'noise_floor': d.noise_floor_percent, 'seconds': time.time() - t0}


def jobs(mechs, seeds) -> list[tuple]:
    """All runs: three magnitudes per mechanism, and clean runs on both channels."""
    out = []
    for seed in range(seeds):
        for ch in ('position', 'pressure'):
            out.append(('none', ch, 0, 0.0, dict(PRESSURE) if ch == 'pressure' else {}, seed))
        for m in mechs:
            ch, _, _, mags, make = SWEEP[m]
            for level, x in enumerate(mags, start=1):
                out.append((m, ch, level, x, make(x), seed))
    return out


def summarise(results: list[dict]) -> str:
    """Confusion matrix, detection per magnitude and thresholds, as markdown."""
    labels = ['none'] + list(MECHANISM_IDS)
    truths = ['none'] + [m for m in MECHANISM_IDS if any(r['truth'] == m for r in results)]
    short = {m: m.replace('_', ' ')[:9] for m in labels}
    lines = ['### Confusion matrix (rows: effect switched on; columns: verdict)', '',
             '| effect \\ verdict | ' + ' | '.join(short[m] for m in labels) + ' |',
             '|---' * (len(labels) + 1) + '|']
    for tr in truths:
        row = [sum(r['truth'] == tr and r['verdict'] == m for r in results) for m in labels]
        lines.append(f'| {tr} | ' + ' | '.join(str(c) if c else '.' for c in row) + ' |')
    lines += ['', '### Detection per magnitude (correct verdict / runs; held-out %e_r '
              'before -> after, noise floor)', '',
              '| effect | magnitude | level 1 | level 2 | level 3 |', '|---|---|---|---|---|']
    for m in truths[1:]:
        ch, name, unit, mags, _ = SWEEP[m]
        cells = []
        for level in (1, 2, 3):
            rs = [r for r in results if r['truth'] == m and r['level'] == level]
            if not rs:
                cells.append('-')
                continue
            ok = sum(r['verdict'] == m for r in rs)
            b = np.mean([r['er_holdout_before'] for r in rs])
            a = np.mean([r['er_holdout_after'] for r in rs])
            f = np.mean([r['noise_floor'] for r in rs])
            cells.append(f'{mags[level - 1]:g}: {ok}/{len(rs)} ({b:.3g} -> {a:.3g}, {f:.3g})')
        lines.append(f'| {m} ({ch}) | {name} [{unit}] | ' + ' | '.join(cells) + ' |')
    lines += ['', '### Detection threshold (smallest magnitude named in every seed)', '',
              '| effect | threshold | baseline held-out %e_r / noise floor there |',
              '|---|---|---|']
    for m in truths[1:]:
        _, name, unit, mags, _ = SWEEP[m]
        found = '> largest tested'
        ratio = ''
        for level in (1, 2, 3):
            rs = [r for r in results if r['truth'] == m and r['level'] == level]
            if rs and all(r['verdict'] == m for r in rs):
                found = f'{name} = {mags[level - 1]:g} {unit}'
                ratio = f'{np.mean([r["er_holdout_before"] / r["noise_floor"] for r in rs]):.2f}'
                break
        lines.append(f'| {m} | {found} | {ratio} |')
    clean = [r for r in results if r['truth'] == 'none']
    if clean:
        lines += ['', 'Clean runs: ' + ', '.join(f'{r["channel"]} seed {r["seed"]}: '
                                                 f'{r["verdict"]}' for r in clean)]
    return '\n'.join(lines)


def main(argv=None) -> int:
    """Run the sweep and write the results."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--seeds', type=int, default=3)
    ap.add_argument('--only', default=None, help='comma-separated mechanism ids')
    ap.add_argument('--out', default=str(ROOT / 'docs' / 'diagnosis_sweep'))
    args = ap.parse_args(argv)
    mechs = args.only.split(',') if args.only else list(SWEEP)
    todo = jobs(mechs, args.seeds)
    print(f'{len(todo)} runs on {args.workers} workers', flush=True)
    results = []
    t0 = time.time()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for r in pool.map(run_one, todo):
            results.append(r)
            print(f'[{len(results)}/{len(todo)} {time.time() - t0:.0f} s] {r["truth"]} '
                  f'level {r["level"]} seed {r["seed"]}: {r["verdict"]} {r["final"]} '
                  f'{r["er_holdout_before"]:.3g} -> {r["er_holdout_after"]:.3g} '
                  f'(floor {r["noise_floor"]:.3g})', flush=True)
    text = summarise(results)
    print(text)
    Path(args.out + '.json').write_text(json.dumps(results, indent=1) + '\n')
    Path(args.out + '.md').write_text(text + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
