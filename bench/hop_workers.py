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

"""Basin hopping in one process and in two: wall time, and where a polish's time goes.

For blind-family recordings (``bench/blind_family.py``'s draw), the chain is
identified on the first 70 % without hopping (two seeds, one process, the
command scaled to about 7-11), then 100 jumps are made from that fit towards
a floor they cannot reach (the fit's %e_r / 3.9, so every jump is made), with
one worker and with two (:func:`hyst_id.identification.hop.hop_with_cost`).
Printed: both wall times, whether the two give the same evaluations and
answer, and how the jumps' polishes spread in length (one process): the
median, and the share of the time the five longest take. Times are this
machine's; run it with nothing else running.

Usage: ``python bench/hop_workers.py [--indices 84]`` (about two minutes per recording,
most of it the fit).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from blind_family import draw  # noqa: E402, I100

from hyst_id.identification.domains import domains_from_data  # noqa: E402
from hyst_id.identification.driver import identify  # noqa: E402
from hyst_id.identification.hop import HOP_NFEV, HOP_SCALE, hop_with_cost  # noqa: E402
from hyst_id.identification.refine import refine  # noqa: E402
from hyst_id.identification.result import IdentifySettings  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402


def one(index: int) -> None:
    """Print the comparison for one recording."""
    case = draw(index)
    n = int(0.7 * case['t'].size)
    v = case['command'][:n]
    v = 9.0 + 2.0 * (v - v.mean()) / v.std()
    rec = Recording(case['t'][:n], v, case['measurement'][:n], case['channel'], source='b')
    ident = identify(rec, settings=IdentifySettings(seeds=(0, 1), hops=0, workers=1))
    best = min(ident.runs, key=lambda r: r.fun)
    spec = replace(domains_from_data(rec), initial=best.initial, hold=best.hold)
    settings, floor = IdentifySettings(hops=100), best.er_percent / 3.9
    out = {}
    for workers in (1, 2):
        t0 = time.perf_counter()
        run, nfev = hop_with_cost(spec, rec, best, settings, floor, n_workers=workers)
        out[workers] = (time.perf_counter() - t0, nfev, None if run is None else run.fun)
    same = out[1][1:] == out[2][1:]
    lo, hi = spec.bounds[:, 0], spec.bounds[:, 1]
    steps = np.random.default_rng([settings.seeds[0], 11, 100]).normal(
        0.0, HOP_SCALE, (100, best.x_raw.size))
    lengths = []
    for step in steps:
        start = np.clip(best.x_raw + step * (hi - lo), lo, hi)
        if spec.feasible(start[None, :])[0]:
            t0 = time.perf_counter()
            refine(spec, start, rec.t_s, rec.command, rec.measurement, max_nfev=HOP_NFEV)
            lengths.append(time.perf_counter() - t0)
    lengths = np.sort(lengths)
    print(f'#{index}: 100 jumps, one worker {out[1][0]:.2f} s, two {out[2][0]:.2f} s '
          f'({out[1][0] / out[2][0]:.1f} x), same evaluations and answer: {same}; '
          f'{lengths.size} polishes, median {1e3 * np.median(lengths):.0f} ms, the five '
          f'longest {100 * lengths[-5:].sum() / lengths.sum():.0f} % of their time')


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--indices', type=int, nargs='+', default=[84])
    for index in ap.parse_args().indices:
        one(index)


if __name__ == '__main__':
    main()
