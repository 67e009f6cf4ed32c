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

"""Spread of the diagnosis figures the tests assert on, over seeds and round-off.

A threshold in a test must sit well outside what the computation gives on
other noise seeds and on another CPU make. This script measures that spread
for the statistical claims of ``test/diagnose``: every mechanism's synthetic
record over ``--seeds`` noise seeds, each also under the round-off probe
(``HYST_ID_ROUNDOFF_PROBE``, imitating another CPU's last bits), and the
concealed bags under ``--probes`` probe seeds. It prints, per claim, how
often the verdict is right and the distribution of the figures the tests
bound (held-out gain, final held-out over the noise floor; for the bags also the
explained share of the mismatch beyond the floor).

Run from the repository root (about 40 minutes on 2 cores)::

    python bench/claim_spreads.py
    python bench/claim_spreads.py --only stiction --seeds 24
    python bench/claim_spreads.py --only loop_shape --seeds 12 --verbose
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from hyst_id.diagnosis import diagnose  # noqa: E402
from hyst_id.io.readers import read_recording  # noqa: E402


#: Print every run, not only the summary (``--verbose``).
VERBOSE = False


def _probe(seed: int | None) -> None:
    if seed is None:
        os.environ.pop('HYST_ID_ROUNDOFF_PROBE', None)
    else:
        os.environ['HYST_ID_ROUNDOFF_PROBE'] = f'{seed}:1e-12'


def _row(name: str, verdicts: list[bool], gains: list[float], ratios: list[float]) -> str:
    g, r = np.array(gains), np.array(ratios)
    return (f'{name:24s} named {sum(verdicts):2d}/{len(verdicts):2d}  '
            f'gain min {g.min():6.1%} med {np.median(g):6.1%} max {g.max():6.1%}  '
            f'final/floor min {r.min():5.2f} med {np.median(r):5.2f} max {r.max():5.2f}  '
            f'under 1.5x {int(np.sum(r < 1.5))}/{r.size}')


def synthetic_spreads(mechs: list[str], seeds: list[int], probes: list[int | None]) -> None:
    """Each mechanism's synthetic record over seeds and probes."""
    from test_diagnose import FAST, synthetic
    print('synthetic records (test/diagnosis/test_diagnose.py), '
          f'seeds {seeds[0]}..{seeds[-1]}, probes {probes}')
    for mech in mechs:
        verdicts, gains, ratios = [], [], []
        for seed in seeds:
            for probe in probes:
                _probe(probe)
                d = diagnose(synthetic(mech, seed=seed), settings=FAST)
                verdicts.append(d.verdict == mech)
                b, f = d.baseline.er_holdout_percent, d.final.er_holdout_percent
                gains.append(1.0 - f / b)
                ratios.append(f / d.noise_floor_percent)
                if VERBOSE:
                    print(f'  {mech} seed {seed} probe {probe}: {d.verdict}, held-out '
                          f'{b:.4g} -> {f:.4g}, floor {d.noise_floor_percent:.4g}', flush=True)
        print(_row(mech, verdicts, gains, ratios), flush=True)
    _probe(None)


def smooth_spreads(seeds: list[int], probes: list[int | None]) -> None:
    """``loop_shape`` on the smooth reference's curved loops (``test_curved_branches_...``).

    Prints how often it is named, the final held-out %e_r over the noise floor,
    and the share of the paper chain's held-out excess over the floor that the
    smooth chain removes.
    """
    from test_diagnose import FAST
    from smooth_reference import smooth_recording
    print(f'smooth loops (test/smooth_reference.py), seeds {seeds[0]}..{seeds[-1]}, '
          f'probes {probes}')
    verdicts, ratios, shares = [], [], []
    for seed in seeds:
        for probe in probes:
            _probe(probe)
            d = diagnose(smooth_recording(seed)[0], settings=FAST)
            verdicts.append(d.verdict == 'loop_shape')
            floor = d.noise_floor_percent
            b = d.baseline.er_holdout_percent
            a = d.findings[0].er_holdout_after_percent if d.findings else b
            ratios.append(a / floor)
            named = d.verdict == 'loop_shape'
            shares.append((b - a) / (b - floor) if named and b > floor else float('nan'))
            if VERBOSE:
                print(f'  seed {seed} probe {probe}: {d.verdict}, held-out {b:.4g} -> {a:.4g}, '
                      f'floor {floor:.4g}', flush=True)
    r, sh = np.array(ratios), np.array(shares)
    print(f'loop_shape named {sum(verdicts)}/{len(verdicts)}  final/floor min {r.min():.3f} '
          f'max {r.max():.3f}  excess share removed (named) min {np.nanmin(sh):.2f} '
          f'max {np.nanmax(sh):.2f}', flush=True)
    _probe(None)


def bag_spreads(probes: list[int | None], names: list[str]) -> None:
    """The concealed bags under round-off probes."""
    from test_concealed_bags import CASES, SETTINGS

    from hyst_id.diagnosis.select import explained_share
    print(f'concealed bags (test/diagnosis/test_concealed_bags.py), probes {probes}')
    for name in sorted(n for n in CASES if not names or n in names):
        channel, _, _, _, expected = CASES[name]
        verdicts, gains, ratios, shares = [], [], [], []
        for probe in probes:
            _probe(probe)
            d = diagnose(read_recording(ROOT / 'bags' / name, channel), settings=SETTINGS)
            verdicts.append(d.verdict == expected)
            b, f = d.baseline.er_holdout_percent, d.final.er_holdout_percent
            gains.append(1.0 - f / b)
            ratios.append(f / d.noise_floor_percent)
            shares.append(explained_share(b, f, d.noise_floor_percent))
            if VERBOSE:
                print(f'  {name} probe {probe}: {d.verdict}, held-out {b:.4g} -> {f:.4g}, '
                      f'floor {d.noise_floor_percent:.4g}', flush=True)
        print(_row(f'{name} ({expected})', verdicts, gains, ratios)
              + f'  explained share min {min(shares):.0%} max {max(shares):.0%}', flush=True)
    _probe(None)


def main() -> int:
    """Print the spreads."""
    from hyst_id.diagnosis.mechanisms import MECHANISM_IDS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=10, help='noise seeds per mechanism (from 5)')
    ap.add_argument('--probes', type=int, default=2, help='round-off probe seeds (plus none)')
    ap.add_argument('--only', default='', help='comma-separated mechanisms, or "bags"')
    ap.add_argument('--bags', default='', help='comma-separated bag names (default: all)')
    ap.add_argument('--verbose', action='store_true', help='print every run')
    args = ap.parse_args()
    global VERBOSE
    VERBOSE = args.verbose
    probes = [None] + list(range(1, args.probes + 1))
    only = [m for m in args.only.split(',') if m]
    from test_diagnose import CASES
    mechs = [m for m in MECHANISM_IDS if (not only or m in only) and m in CASES]
    if mechs and only != ['bags']:
        synthetic_spreads(mechs, list(range(5, 5 + args.seeds)), probes[:2])
    if not only or 'loop_shape' in only:
        smooth_spreads(list(range(args.seeds)), probes[:2])
    if not only or 'bags' in only:
        bag_spreads(probes, [b for b in args.bags.split(',') if b])
    return 0


if __name__ == '__main__':
    sys.exit(main())
