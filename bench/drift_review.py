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

"""Slow drifts read through actuators outside the paper's chain (docs/reliability.md section 8).

The recordings of the third independent review, written apart from the package
in plain numpy (no ``hyst_id`` import in the generator): a play and a cubic map
(``play``), a narrower play and a quadratic map (``play2``) or a
Prandtl-Ishlinskii sum of four plays (``pi``), driven by a multisine, a
periodic multisine, random steps, a triangle or a decaying sine (2,000 samples,
10-50 Hz, noise 0.3-1 % of the span), read through a clean sensor (kind ``a``),
an offset drift (``b``), a gain growing about a zero 1-8 spans from the travel
(``c``), a gain growing about the travel's bottom (``d``) or a falling gain
(``e``). Each is diagnosed with the defaults (one worker) and a line printed:
the truth, the findings, the fitted drift, the final held-out error over the
floor; then the right verdicts per kind (``a`` right with ``none``, ``b`` with
``offset_drift``, ``c``/``d`` with ``gain_drift``, ``e`` with a falling gain).

Run from the repository root (about a minute per recording)::

    python bench/drift_review.py                    # all 37
    python bench/drift_review.py --names b4 c4      # some
    python bench/drift_review.py --csv DIR          # only write DIR/rec_<name>.csv
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: name, kind, excitation, actuator, rate (Hz), seed, drift parameters
SPECS = [
    ('a1', 'a', 'multisine', 'play', 20, 101, {}),
    ('a2', 'a', 'steps', 'pi', 10, 102, {}),
    ('a3', 'a', 'triangle', 'play', 40, 103, {}),
    ('a4', 'a', 'decay', 'pi', 25, 104, {}),
    ('b1', 'b', 'steps', 'play', 20, 201, {'r': 0.05}),
    ('b2', 'b', 'multisine', 'pi', 10, 202, {'r': 0.02}),
    ('b3', 'b', 'triangle', 'pi', 50, 203, {'r': -0.08}),
    ('b4', 'b', 'decay', 'play', 20, 204, {'r': 0.10}),
    ('c1', 'c', 'multisine', 'play', 20, 301, {'g': 0.08, 'zspans': -3}),
    ('c2', 'c', 'steps', 'pi', 10, 302, {'g': 0.05, 'zspans': 5}),
    ('c3', 'c', 'triangle', 'play', 40, 303, {'g': 0.12, 'zspans': -1}),
    ('c4', 'c', 'decay', 'pi', 20, 304, {'g': 0.03, 'zspans': -8}),
    ('c5', 'c', 'steps', 'play', 25, 305, {'g': 0.15, 'zspans': -2}),
    ('d1', 'd', 'multisine', 'pi', 20, 401, {'g': 0.10}),
    ('d2', 'd', 'steps', 'play', 10, 402, {'g': 0.05}),
    ('d3', 'd', 'triangle', 'pi', 30, 403, {'g': 0.15}),
    ('e1', 'e', 'multisine', 'play', 20, 501, {'g': -0.10}),
    ('e2', 'e', 'steps', 'pi', 10, 502, {'g': -0.05}),
    ('e3', 'e', 'triangle', 'play', 40, 503, {'g': -0.15, 'zspans': -3}),
    ('e4', 'e', 'decay', 'pi', 20, 504, {'g': -0.03}),
    ('a5', 'a', 'multisine', 'play2', 20, 601, {}),
    ('a6', 'a', 'steps', 'play2', 20, 606, {}),
    ('b5', 'b', 'multisine', 'play2', 20, 602, {'r': 0.05}),
    ('b6', 'b', 'steps', 'play2', 20, 603, {'r': 0.03}),
    ('c6', 'c', 'multisine', 'play2', 20, 604, {'g': 0.08, 'zspans': -3}),
    ('c7', 'c', 'triangle', 'play2', 25, 605, {'g': 0.10, 'zspans': 2}),
    ('d4', 'd', 'steps', 'play2', 20, 607, {'g': 0.08}),
    ('e5', 'e', 'multisine', 'play2', 20, 608, {'g': -0.10}),
    ('e6', 'e', 'triangle', 'play2', 25, 609, {'g': -0.08}),
    ('a7', 'a', 'pmultisine', 'play2', 20, 701, {}),
    ('a8', 'a', 'triangle', 'play2', 25, 708, {}),
    ('b7', 'b', 'pmultisine', 'play2', 20, 702, {'r': 0.05}),
    ('b8', 'b', 'triangle', 'play2', 25, 703, {'r': 0.04}),
    ('c8', 'c', 'pmultisine', 'play2', 20, 704, {'g': 0.08, 'zspans': -3}),
    ('c9', 'c', 'triangle', 'pi', 25, 705, {'g': 0.06, 'zspans': -5}),
    ('d5', 'd', 'pmultisine', 'play2', 20, 706, {'g': 0.10}),
    ('e7', 'e', 'pmultisine', 'play2', 20, 707, {'g': -0.10}),
]

#: the verdicts that are right for each kind
RIGHT = {'a': {'none'}, 'b': {'offset_drift'}, 'c': {'gain_drift'}, 'd': {'gain_drift'},
         'e': {'gain_loss', 'supply_decay'}}


def play(u: np.ndarray, r: float) -> np.ndarray:
    """A play (backlash) operator of half-width ``r``, starting at ``u[0]``."""
    y, p = np.empty_like(u), u[0]
    for i, v in enumerate(u):
        p = min(max(p, v - r), v + r)
        y[i] = p
    return y


def actuator(u: np.ndarray, kind: str) -> np.ndarray:
    """The position of actuator ``kind`` (``play``, ``play2``, ``pi``) under command ``u``."""
    span = u.max() - u.min()
    if kind == 'play':
        p = play(u, 0.10 * span)
        s = (p - p.mean()) / span
        return 20.0 + 30.0 * (s + 0.15 * s**2 - 0.1 * s**3)
    if kind == 'play2':
        p = play(u, 0.08 * span)
        s = (p - p.mean()) / span
        return 20.0 + 30.0 * (s + 0.05 * s**2)
    widths, weights = np.array([0.0, 0.04, 0.08, 0.13]) * span, [0.5, 0.25, 0.15, 0.10]
    p = sum(w * play(u, r) for w, r in zip(weights, widths))
    s = (p - p.mean()) / span
    return 20.0 + 30.0 * (s + 0.1 * s**2)


def command(exc: str, n: int, fs: float, rng: np.random.Generator) -> tuple:
    """Time (s) and command (%) of excitation ``exc``."""
    t = np.arange(n) / fs
    end = t[-1]
    if exc == 'multisine':
        f = np.array([0.013, 0.031, 0.057, 0.089]) * (200.0 / end) * 0.5
        ph = rng.uniform(0, 2 * np.pi, 4)
        u = sum(a * np.sin(2 * np.pi * fi * t + p) for a, fi, p in zip([1, .6, .4, .3], f, ph))
    elif exc == 'pmultisine':   # period a quarter of the record: the held-out part comes back
        period = (end + t[1]) / 4
        ph = rng.uniform(0, 2 * np.pi, 4)
        u = sum(a * np.sin(2 * np.pi * h * t / period + p)
                for a, h, p in zip([1, .5, .35, .25], [1, 2, 3, 5], ph))
        u = u / np.abs(u).max()
    elif exc == 'steps':
        u, i = np.empty(n), 0
        while i < n:
            h = int(rng.uniform(1, 3) * fs)
            u[i:i + h] = rng.uniform(-1, 1)
            i += h
        k = max(1, int(0.2 * fs))       # a mild slew
        u = np.convolve(np.pad(u, (k, 0), 'edge'), np.ones(k) / k, 'valid')[:n]
    elif exc == 'triangle':
        phase = (t / (end / 8)) % 1.0
        amplitude = 0.4 + 0.6 * np.abs(np.sin(np.pi * t / end * 3 + 0.3))
        u = amplitude * (2 * np.abs(2 * phase - 1) - 1)
    else:                               # decaying sine
        per = end / 10
        u = np.exp(-2.0 * t / end) * np.sin(2 * np.pi * t / per) + 0.1 * np.sin(
            2 * np.pi * t / (3.1 * per))
    return t, 50.0 + 40.0 * u


def make(spec: tuple, n: int = 2000) -> tuple:
    """Time, command, measurement and the truth of one recording."""
    name, kind, exc, act, fs, seed, p = spec
    rng = np.random.default_rng(seed)
    t, u = command(exc, n, fs, rng)
    x = actuator(u, act)
    span, end = x.max() - x.min(), t[-1]
    noise = rng.uniform(0.003, 0.01)
    truth = {'name': name, 'kind': kind, 'excitation': exc, 'actuator': act, 'fs': fs}
    y = x.copy()
    if kind == 'b':
        y = x + p['r'] * span * t / end
        truth['drift'] = f'offset {100 * p["r"]:+.0f} % of the span'
    elif kind in ('c', 'd', 'e'):
        spans = 0 if kind == 'd' else p.get('zspans', 0)
        z0 = (x.min() + spans * span if spans <= 0 else x.max() + spans * span)
        y = (x - z0) * (1 + p['g'] * t / end) + z0
        truth['drift'] = f'gain {100 * p["g"]:+.0f} % about {z0:.4g}'
    y = y + rng.normal(0, noise * span, n)
    # the digits of the review's CSV files, so that a run here and `hyst-id diagnose` on them agree
    return np.round(t, 6), np.round(u, 6), np.round(y, 6), truth


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--names', nargs='+', metavar='NAME')
    ap.add_argument('--csv', metavar='DIR', help='only write the recordings as CSV files')
    args = ap.parse_args()
    specs = [s for s in SPECS if not args.names or s[0] in args.names]
    if args.csv:
        Path(args.csv).mkdir(parents=True, exist_ok=True)
        for s in specs:
            t, u, y, _ = make(s)
            np.savetxt(Path(args.csv) / f'rec_{s[0]}.csv', np.column_stack([t, u, y]),
                       delimiter=',', header='t,command,measurement', comments='', fmt='%.6f')
        print(f'{len(specs)} recordings in {args.csv}: hyst-id diagnose FILE --channel position')
        return 0
    from hyst_id.diagnosis import diagnose, DiagnoseSettings
    from hyst_id.io.recording import Recording
    right: dict[str, list[int]] = {}
    for s in specs:
        t, u, y, truth = make(s)
        t0 = time.time()
        d = diagnose(Recording(t, u, y, 'position', source=s[0]),
                     settings=DiagnoseSettings(workers=1))
        drift = ', '.join(f'{f.mechanism} ' + ', '.join(
            f'{k} {q.value:.4g} {q.unit}' for k, q in f.params.items())
            for f in d.findings if f.mechanism in ('offset_drift', 'gain_drift', 'gain_loss'))
        final = d.final.er_holdout_percent / d.noise_floor_percent
        ok = d.verdict in RIGHT[truth['kind']]
        right.setdefault(truth['kind'], []).append(int(ok))
        print(f'{s[0]} {truth["excitation"]}/{truth["actuator"]}/{truth["fs"]} Hz '
              f'{truth.get("drift", "clean")}: {d.verdict} '
              f'[{", ".join(f.mechanism for f in d.findings)}] {drift} final {final:.2f} x '
              f'{"right" if ok else "wrong"} ({time.time() - t0:.0f} s)', flush=True)
    print('right per kind: '
          + ', '.join(f'{k} {sum(v)}/{len(v)}' for k, v in sorted(right.items())))
    return 0


if __name__ == '__main__':
    sys.exit(main())
