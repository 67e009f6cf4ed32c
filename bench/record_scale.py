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

"""Identify and diagnose wall time against record length, the growth exponent, stage profile.

First, identify with its search on a subset of a long record (the default
``search_samples``) against every sample (``search_samples=0``), on position
and on pressure (a 0.8 s first-order sensor): wall time and the ratio of the
two %e_r. Then clean position recordings at 1 kHz from the independent
reference simulator (``test/reference_sim``: the paper's loop, backlash
0.25, Eq. 24's 10 s sine with its decaying amplitude repeated, 0.4 % of the
span of noise), of ``--lengths`` samples (at least 20,000: a shorter 1 kHz record has fewer
than two of the 10 s sine's reversals). For each: ``identify`` with default
settings (as ``hyst-id identify``) and ``diagnose`` with default settings
(both compiled on a short record first), wall time and
%e_r over the true noise floor. Then the growth exponent (least squares of
log time on log length) and, for the longest record, where identify's time
goes (cProfile, one worker so that everything runs in this process).

Usage: ``PYTHONPATH=.:test python bench/record_scale.py [--lengths 20000 60000 120000]
[--no-diagnose] [--no-profile] [--no-full-rate]``. Run on an otherwise idle machine: it
measures time (about 8 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import cProfile
from dataclasses import replace
from pathlib import Path
import pstats
import sys
import time

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

from reference_sim import backlash, first_order_sensor, hysteresis  # noqa: E402, I100

PAPER_H = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)
#: Functions whose cumulative time makes identify's stages (cProfile names).
STAGES = {'validate_recording': 'validate', 'roundoff_probe': 'round-off probe',
          'noise_floor_percent': 'noise floor', 'data_incumbent': 'data-built starts',
          'rank_conventions': 'initial state / hold', '_run_seed': 'GAASS seeds + refinement',
          'global_phase': 'global phase', 'summarise': 'summary',
          'assess': 'warnings / uncertainty'}


def make_recording(n: int, dt_s: float = 0.001, seed: int = 0, channel: str = 'position'):
    """A clean recording of ``n`` samples at ``1/dt_s`` Hz (reference simulator).

    ``channel`` ``pressure``: the position through a first-order sensor of 0.8 s.
    """
    from hyst_id.io.recording import Recording
    t = np.arange(n) * dt_s
    phase = t % 100.0            # Eq. 24 over 100 s, repeated
    v = 9.0 + (2.0 * np.exp(-0.01 * phase)) * np.sin(2 * np.pi * phase / 10.0)
    y = backlash(hysteresis(v, *PAPER_H), 1.0, -0.25, 0.25)
    if channel == 'pressure':
        y = first_order_sensor(t, y, 0.8)
    sigma = 0.004 * float(np.ptp(y))
    y = y + np.random.default_rng(seed).normal(0.0, sigma, n)
    return Recording(t, v, y, channel, 'mA', 'mA-eq', f'reference, {n} samples'), sigma


def _floor(rec, sigma: float) -> float:
    from hyst_id.signals.noise import floor_percent
    return floor_percent(rec.measurement, sigma)


def growth_exponent(lengths: list[int], seconds: list[float]) -> float:
    """Slope of log(time) on log(length)."""
    return float(np.polyfit(np.log(lengths), np.log(seconds), 1)[0])


def profile_identify(rec) -> list[tuple[str, float]]:
    """Cumulative seconds per stage of one identify run with one worker."""
    from hyst_id.identification import identify, IdentifySettings
    prof = cProfile.Profile()
    prof.enable()
    identify(rec, settings=replace(IdentifySettings(), workers=1))
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = {}
    for (_, _, name), (_, _, _, cum, _) in stats.items():
        if name in STAGES:
            total[STAGES[name]] = total.get(STAGES[name], 0.0) + cum
    whole = sum(v[3] for k, v in stats.items() if k[2] == 'identify')
    return [('identify (total)', whole)] + sorted(total.items(), key=lambda kv: -kv[1])


def full_rate_table(lengths: list[int]) -> None:
    """Identify with the search on a subset (default) and on every sample, side by side."""
    from hyst_id.identification import identify, IdentifySettings
    print('search on a subset (default search_samples) against every sample (0):\n')
    print('| channel | samples | subset: s | full rate: s | %e_r subset / full rate |')
    print('|---|---|---|---|---|')
    for channel in ('position', 'pressure'):
        for n in lengths:
            rec = make_recording(n, channel=channel)[0]
            out = []
            for samples in (IdentifySettings().search_samples, 0):
                t0 = time.perf_counter()
                ident = identify(rec, settings=replace(IdentifySettings(),
                                                       search_samples=samples))
                out.append((time.perf_counter() - t0, ident.er_percent))
            print(f'| {channel} | {n} | {out[0][0]:.1f} | {out[1][0]:.1f} | '
                  f'{out[0][1] / out[1][1]:.4f} |', flush=True)
    print()


def main(argv: list[str] | None = None) -> int:
    """Print the table, the exponents and the profile."""
    from hyst_id.diagnosis import diagnose
    from hyst_id.identification import identify
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--lengths', type=int, nargs='+', default=[20_000, 60_000, 120_000])
    ap.add_argument('--no-diagnose', action='store_true')
    ap.add_argument('--no-profile', action='store_true')
    ap.add_argument('--no-full-rate', action='store_true',
                    help='skip the full-rate comparison (search_samples=0)')
    args = ap.parse_args(argv)
    warm = make_recording(2000, dt_s=0.05)[0]      # compile the kernels first
    identify(warm)
    if not args.no_diagnose:
        diagnose(warm)
    if not args.no_full_rate:
        full_rate_table(args.lengths)
    rows = []
    print('| samples | identify [s] | %e_r / true floor | diagnose [s] | verdict |')
    print('|---|---|---|---|---|')
    for n in args.lengths:
        rec, sigma = make_recording(n)
        t0 = time.perf_counter()
        ident = identify(rec)
        t_id = time.perf_counter() - t0
        t_dg, verdict = float('nan'), '-'
        if not args.no_diagnose:
            t0 = time.perf_counter()
            d = diagnose(rec)
            t_dg, verdict = time.perf_counter() - t0, d.verdict
        rows.append((n, t_id, t_dg))
        print(f'| {n} | {t_id:.1f} | {ident.er_percent / _floor(rec, sigma):.3f} | '
              f'{t_dg:.1f} | {verdict} |', flush=True)
    if len(rows) > 1:
        ns = [r[0] for r in rows]
        print(f'\ngrowth exponent (time ~ n^k): identify k = '
              f'{growth_exponent(ns, [r[1] for r in rows]):.2f}'
              + ('' if args.no_diagnose else
                 f', diagnose k = {growth_exponent(ns, [r[2] for r in rows]):.2f}'))
    if not args.no_profile:
        print(f"\nwhere identify's time goes, {args.lengths[-1]} samples, one worker "
              '(cumulative; stages overlap where one calls another):')
        for name, sec in profile_identify(make_recording(args.lengths[-1])[0]):
            print(f'  {name:28s} {sec:7.1f} s')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
