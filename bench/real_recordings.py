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

"""Real recordings: fit on the first 70 %, held-out %e_r, ``identify`` against CMA-ES.

Every recording in ``../shared/data`` (or ``--data``):

* ``pneumatic-cylinder-friction/Circle_{1,3,7}bar.csv``: command = piston
  displacement (mm), measurement = force (N), time = column 0 in ms
  (non-uniform sampling, gaps up to 2.66 s), channel ``position``;
* ``magnetic-bh-loops/*.csv``: command = field H (A/m), measurement = flux
  density B (T), the loops of increasing amplitude one after another, the
  sample index as time (quasi-static), channel ``position``. The first 70 %
  holds the smaller loops, so the held-out part asks for a loop at an
  amplitude the fit did not see.

For each: :func:`hyst_id.identify` (default settings) on the first 70 %;
then CMA-ES (``cmaes``, IPOP) on the same chain (box, initial state, sensor
hold) at the evaluations ``identify`` used. Both parameter sets simulate the
whole recording (the state runs on through the split); the calibration of
the CMA-ES set is fitted on the training part only. Printed per recording:
training and held-out %e_r of both, the estimated noise floor, and whether
the chain can make the loop at all (training %e_r over 3 x the floor and the
residual structured by command level: "the chain cannot make this loop").

Usage (from the repository root; about 2 minutes per recording)::

    python bench/real_recordings.py
    python bench/real_recordings.py --only Circle_1bar --seeds 4
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
sys.path.insert(0, str(ROOT))

from generalisation import cmaes_minimise  # noqa: E402, I100

__all__ = ['load_all', 'main', 'run_one']

#: Share of each recording used for fitting.
FIT_SHARE = 0.7
#: Training %e_r above this many noise floors: the chain cannot make the loop.
CANNOT_MAKE = 3.0


def _pneumatic(path: Path):
    from hyst_id.io.recording import Recording
    raw = np.loadtxt(path)
    return Recording(raw[:, 0] / 1000.0, raw[:, 4], raw[:, 6], 'position', 'mm', 'N',
                     f'{path.parent.name}/{path.name}')


def _bh_loops(path: Path):
    from hyst_id.io.recording import Recording
    raw = np.loadtxt(path, delimiter=',', skiprows=1)
    order = np.lexsort((raw[:, 1], raw[:, 0]))     # loop, then index within the loop
    h, b = raw[order, 2], raw[order, 3]
    return Recording(np.arange(h.size, dtype=float), h, b, 'position', 'A/m', 'T',
                     f'{path.parent.name}/{path.name}')


def load_all(data: Path) -> list:
    """Every real recording under ``data`` as a Recording (not validated)."""
    recs = [_pneumatic(p) for p in sorted((data / 'pneumatic-cylinder-friction').glob('*.csv'))]
    recs += [_bh_loops(p) for p in sorted((data / 'magnetic-bh-loops').glob('*.csv'))]
    return recs


def _split(rec, n_train: int):
    from hyst_id.io.recording import Recording
    return Recording(rec.t_s[:n_train], rec.command[:n_train], rec.measurement[:n_train],
                     rec.channel, rec.command_unit, rec.measurement_unit, rec.source)


def _er(y: np.ndarray, pred: np.ndarray) -> float:
    r = y - pred
    return float(np.sqrt((r @ r) / max(float(y @ y), 1e-300)) * 100.0)


def run_one(rec, seeds: int, seed: int = 0) -> dict:
    """Identify and CMA-ES on the first 70 % of ``rec``; held-out errors of both."""
    from threadpoolctl import threadpool_limits

    from hyst_id.identification import identify, IdentifySettings
    from hyst_id.identification.domains import domains_from_data
    from hyst_id.io.recording import validate_recording
    from hyst_id.signals.noise import floor_percent, estimate_noise_std
    n_train = int(FIT_SHARE * rec.t_s.size)
    train = validate_recording(_split(rec, n_train))
    y, yt, yh = rec.measurement, rec.measurement[:n_train], rec.measurement[n_train:]
    noise = estimate_noise_std(yt)
    out = {'source': rec.source, 'n': rec.t_s.size, 'n_train': n_train,
           'floor_train': floor_percent(yt, noise), 'floor_holdout': floor_percent(yh, noise)}
    with threadpool_limits(limits=1):
        t0 = time.perf_counter()
        ident = identify(train, settings=IdentifySettings(seeds=tuple(range(seeds)), workers=1))
        wall = time.perf_counter() - t0
        pred = ident.spec().simulate(ident.x, rec.t_s, rec.command)
        budget = ident.nfev
        out['identify'] = {'train': _er(yt, pred[:n_train]), 'holdout': _er(yh, pred[n_train:]),
                           'nfev': budget, 'wall_s': wall, 'proper': ident.proper}
        spec = replace(domains_from_data(train), initial=ident.initial, hold=ident.hold)
        t0 = time.perf_counter()
        _, x = cmaes_minimise(spec, train, seed, budget)
        wall = time.perf_counter() - t0
        if x is None:
            out['CMA-ES'] = {'train': np.nan, 'holdout': np.nan, 'nfev': budget, 'wall_s': wall}
        else:
            cal = spec.fit_calibration(x, train.t_s, train.command, train.measurement)
            pred = spec.simulate(x, rec.t_s, rec.command, calibration=cal)
            out['CMA-ES'] = {'train': _er(yt, pred[:n_train]),
                             'holdout': _er(yh, pred[n_train:]), 'nfev': budget,
                             'wall_s': wall}
    out['can_make'] = out['identify']['train'] <= CANNOT_MAKE * out['floor_train']
    del y
    return out


def _table(results: list[dict]) -> str:
    lines = ['| recording | samples (fit) | floor % (fit / held out) | identify % fit | '
             'identify % held out | CMA-ES % fit | CMA-ES % held out | evaluations | '
             'wall s (identify / CMA-ES) | verdict |',
             '|---|---|---|---|---|---|---|---|---|---|']
    for r in results:
        i, c = r['identify'], r['CMA-ES']
        better = 'identify at least as good' if i['holdout'] <= c['holdout'] * 1.0001 else \
            'CMA-ES better'
        verdict = better + ('' if r['can_make'] else '; the chain cannot make this loop')
        if not i.get('proper', True):
            verdict += '; identify kept a loop that is not proper'
        lines.append(f"| {r['source']} | {r['n']} ({r['n_train']}) | "
                     f"{r['floor_train']:.3f} / {r['floor_holdout']:.3f} | "
                     f"{i['train']:.3f} | {i['holdout']:.3f} | {c['train']:.3f} | "
                     f"{c['holdout']:.3f} | {i['nfev']} | {i['wall_s']:.0f} / "
                     f"{c['wall_s']:.0f} | {verdict} |")
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run every real recording and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--data', type=Path, default=ROOT.parent / 'shared' / 'data',
                    help='folder holding pneumatic-cylinder-friction/ and magnetic-bh-loops/')
    ap.add_argument('--seeds', type=int, default=10, help='identify seeds')
    ap.add_argument('--only', default='', help='substring of the recordings to run')
    args = ap.parse_args(argv)
    if not args.data.is_dir():
        print(f'error: no data folder {args.data}', file=sys.stderr)
        return 2
    recs = [r for r in load_all(args.data) if args.only in r.source]
    if not recs:
        print(f'error: no recordings under {args.data} match {args.only!r}', file=sys.stderr)
        return 2
    results = []
    for rec in recs:
        r = run_one(rec, args.seeds)
        results.append(r)
        print(f"# {r['source']}: identify held out {r['identify']['holdout']:.3f} %, "
              f"CMA-ES {r['CMA-ES']['holdout']:.3f} %", flush=True)
    print()
    print(f'Fit on the first {FIT_SHARE:.0%}, held-out %e_r on the rest; CMA-ES at the '
          f'evaluations identify used ({args.seeds} seeds).')
    print()
    print(_table(results))
    return 0


if __name__ == '__main__':
    sys.exit(main())
