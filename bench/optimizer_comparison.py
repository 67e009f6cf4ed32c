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

"""Compare optimisers on the paper's experiment (issue 2).

GAASS, GAASS + refinement, scipy's differential evolution and CMA-ES.

Data: the paper's Eq. 24 run (``v = 9 + 2 exp(-0.01 t) sin(2 pi t / 10)`` mA,
100 s at 20 Hz) through the test suite's chain (the paper's induced
hysteresis, a 0.3 mA unit-slope backlash, a 0.5 s pressure lag, pressure
calibration 50 kPa/mA + 1000 kPa) with 0.5 % Gaussian noise: the recordings
of ``test/conftest.py``. Position and pressure channels.

Every method minimises the same cost J (Eq. 6, affine calibration profiled,
infeasible candidates cost ``inf``) over the same search domains (the
paper's by default), ten seeds each, with the same evaluation budget: by
default the largest number of evaluations GAASS + refinement used on any
seed of that channel (it stops once it reaches the noise floor), or
``--budget N``.

* ``GAASS``: the paper's settings, generations raised to spend the budget.
* ``GAASS (paper)``: the paper's 500 generations, for reference.
* ``GAASS + refine``: :func:`hyst_id.identification.run_seed`, restarts allowed
  within the budget.
* ``DE``: :func:`scipy.optimize.differential_evolution`, default strategy
  and population (15 per parameter), vectorised, no polish, ``tol = 0`` so
  it spends the budget.
* ``CMA-ES``: the ``cmaes`` package in the box normalised to [0, 1],
  ``sigma0 = 0.25``, IPOP restarts; infeasible samples are redrawn (up to
  100 times, not counted as evaluations) and penalised if still infeasible.

Reported: %e_r / noise floor, median and worst over the seeds, and the
evaluations used. The table is printed and written to ``docs/benchmarks.md``.

Usage: ``python bench/optimizer_comparison.py [--budget N] [--seeds 10]
[--channels position,pressure] [--domains paper|auto] [--workers 2] [--no-write]``
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import os
from pathlib import Path
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))

from hyst_id.identification import IdentifySettings, run_seed  # noqa: E402
from hyst_id.identification.chains import chain_spec, ChainSpec, er_percent  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.signals.noise import noise_floor_percent  # noqa: E402

__all__ = ['simulate', 'run_method', 'main']

ROOT = Path(__file__).resolve().parents[1]
#: As in test/conftest.py: the paper's induced hysteresis, backlash, sensors.
TRUE_PARAMS = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0,
                        1.0, -0.15, 0.15, 0.5, 0.6])
CALIBRATION = {'position': (1.0, 0.0), 'pressure': (50.0, 1000.0), 'flow': (4.0, 2.0)}
METHODS = ('GAASS (paper)', 'GAASS', 'GAASS + refine', 'DE', 'CMA-ES')
GAASS_EVALS_PER_GENERATION = 10.0   # pop_size 10: one new population per generation


def simulate(channel: str, *, noise_percent: float = 0.5, seed: int = 1) -> Recording:
    """Simulate the Eq. 24 run of ``channel`` with 0.5 % noise (test/conftest.py's data)."""
    spec = chain_spec(channel)
    t = np.arange(0.0, 100.0, 0.05)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    y0 = spec.simulate(TRUE_PARAMS[:spec.n_params], t, v, CALIBRATION[channel])
    sigma = noise_percent / 100.0 * np.sqrt(np.mean(y0 ** 2))
    y = y0 + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    return Recording(t, v, y, channel, 'mA', '', f'simulated {channel}')


def _spec(channel: str, domains: str, rec: Recording) -> ChainSpec:
    if domains == 'auto':
        from hyst_id.identification.domains import domains_from_data
        return domains_from_data(rec)
    return chain_spec(channel)


def _gaass(spec: ChainSpec, rec: Recording, seed: int, budget: int | None,
           refine: bool) -> tuple[float, int]:
    if refine:
        rounds = 5 if budget is None else max(1, budget // 11000)
        settings = IdentifySettings(seeds=(seed,), restarts=rounds - 1)
    else:
        gens = 500 if budget is None else int(budget / GAASS_EVALS_PER_GENERATION)
        settings = IdentifySettings(seeds=(seed,), refine=False, maxiter=max(1, gens))
    floor = noise_floor_percent(rec.measurement)
    run = run_seed(spec, rec.t_s, rec.command, rec.measurement, settings, seed, floor)
    return run.fun, run.nfev


def _de(spec: ChainSpec, rec: Recording, seed: int, budget: int) -> tuple[float, int]:
    from scipy.optimize import differential_evolution

    cost = spec.cost_function(rec.t_s, rec.command, rec.measurement)
    popsize = 15
    n_pop = popsize * spec.n_params
    maxiter = max(1, budget // n_pop - 1)
    nfev = 0

    def population_cost(x: np.ndarray) -> np.ndarray:
        nonlocal nfev
        nfev += x.shape[1]          # scipy's nfev counts calls when vectorised
        return cost(np.ascontiguousarray(x.T))

    res = differential_evolution(population_cost, spec.bounds, maxiter=maxiter,
                                 popsize=popsize, tol=0.0, atol=0.0, polish=False, seed=seed,
                                 vectorized=True, updating='deferred')
    return float(res.fun), nfev


def _cmaes(spec: ChainSpec, rec: Recording, seed: int, budget: int) -> tuple[float, int]:
    from cmaes import CMA

    cost = spec.cost_function(rec.t_s, rec.command, rec.measurement)
    lo, width = spec.bounds[:, 0], spec.bounds[:, 1] - spec.bounds[:, 0]
    m = spec.n_params
    rng = np.random.default_rng(seed)
    penalty = 10.0 * float(np.sum((rec.measurement - rec.measurement.mean()) ** 2))
    best, nfev, pop_size, restart = np.inf, 0, None, 0
    while nfev < budget:
        opt = CMA(mean=rng.uniform(0.25, 0.75, m), sigma=0.25,
                  bounds=np.tile([0.0, 1.0], (m, 1)), seed=int(rng.integers(2 ** 31)),
                  population_size=pop_size)
        while nfev < budget and not opt.should_stop():
            zs = []
            for _ in range(opt.population_size):
                z = opt.ask()
                for _ in range(100):
                    if spec.feasible((lo + z * width)[None, :])[0]:
                        break
                    z = opt.ask()
                zs.append(z)
            xs = lo + np.array(zs) * width
            ok = spec.feasible(xs)
            values = np.full(len(zs), np.inf)
            if ok.any():
                values[ok] = cost(xs[ok])
                nfev += int(ok.sum())
            best = min(best, float(values.min()))
            told = np.where(np.isfinite(values), values, penalty)
            opt.tell(list(zip(zs, told)))
        restart += 1
        pop_size = opt.population_size * 2          # IPOP
    return best, nfev


def run_method(method: str, channel: str, seed: int, budget: int | None,
               domains: str = 'paper') -> tuple[str, str, int, float, int, float]:
    """Run one method on one channel with one seed.

    Returns
    -------
    tuple
        ``(method, channel, seed, %e_r / noise floor, evaluations, seconds)``.
    """
    with threadpool_limits(limits=1):
        rec = simulate(channel)
        spec = _spec(channel, domains, rec)
        start = time.perf_counter()
        if method == 'GAASS (paper)':
            fun, nfev = _gaass(spec, rec, seed, None, refine=False)
        elif method == 'GAASS':
            fun, nfev = _gaass(spec, rec, seed, budget, refine=False)
        elif method == 'GAASS + refine':
            fun, nfev = _gaass(spec, rec, seed, budget, refine=True)
        elif method == 'DE':
            fun, nfev = _de(spec, rec, seed, budget)
        else:
            fun, nfev = _cmaes(spec, rec, seed, budget)
        ratio = float(er_percent(fun, rec.measurement)) / noise_floor_percent(rec.measurement)
        return method, channel, seed, ratio, nfev, time.perf_counter() - start


def _table(results: dict, budgets: dict, channels: list[str]) -> str:
    cells = [f'{c}: median | {c}: worst | {c}: evals (median)' for c in channels]
    head = '| method | ' + ' | '.join(cells) + ' |'
    lines = [head, '|' + '---|' * (1 + 3 * len(channels))]
    for method in METHODS:
        row = [method]
        for c in channels:
            runs = results.get((method, c), [])
            if not runs:
                row += ['-', '-', '-']
                continue
            ratios = np.array([r[0] for r in runs])
            evals = np.array([r[1] for r in runs])
            row += [f'{np.median(ratios):.3f}', f'{ratios.max():.3f}',
                    f'{int(np.median(evals))}']
        lines.append('| ' + ' | '.join(row) + ' |')
    lines.append('')
    lines.append('Budget per seed: ' + ', '.join(f'{c} {budgets[c]}' for c in channels)
                 + ' evaluations.')
    return '\n'.join(lines)


def _write(text: str, command: str, path: Path, key: str) -> None:
    """Replace this run's section of ``path`` (one section per budget), or append it."""
    start = f'<!-- optimizer-comparison {key}:start -->'
    end = f'<!-- optimizer-comparison {key}:end -->'
    section = (f'{start}\n## Optimiser comparison (issue 2), budget: {key}\n\n'
               f'Produced by `{command}` (setup in the docstring of the script):\n'
               f'%e_r over the noise floor, ten seeds per method, equal evaluation budgets.\n'
               f'GAASS + refine stops once within 1.05 x the floor (it restarts otherwise), so '
               f"it may use\nless than the budget; GAASS (paper) runs the paper's 500 "
               f'generations whatever the budget.\n\n'
               f'{text}\n{end}')
    old = path.read_text() if path.exists() else '# Benchmarks\n'
    if start in old and end in old:
        new = old[:old.index(start)] + section + old[old.index(end) + len(end):]
    else:
        new = old.rstrip('\n') + '\n\n' + section + '\n'
    path.write_text(new)


def main(argv: list[str] | None = None) -> int:
    """Run the comparison, print the table and write it to docs/benchmarks.md."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--budget', type=int, default=None,
                        help='evaluations per seed (default: what GAASS + refine used)')
    parser.add_argument('--seeds', type=int, default=10)
    parser.add_argument('--channels', default='position,pressure')
    parser.add_argument('--domains', choices=('paper', 'auto'), default='paper')
    parser.add_argument('--workers', type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument('--no-write', action='store_true', help='do not write docs')
    args = parser.parse_args(argv)
    channels = [c.strip() for c in args.channels.split(',') if c.strip()]
    seeds = range(args.seeds)
    results: dict = {}
    budgets: dict = {}
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        def collect(jobs):
            for fut in [pool.submit(run_method, *job) for job in jobs]:
                method, channel, seed, ratio, nfev, secs = fut.result()
                results.setdefault((method, channel), []).append((ratio, nfev, secs))
                print(f'{method:15s} {channel:9s} seed {seed}: {ratio:7.3f} x floor, '
                      f'{nfev:7d} evals, {secs:6.1f} s', file=sys.stderr)

        collect([('GAASS + refine', c, s, args.budget, args.domains)
                 for c in channels for s in seeds])
        for c in channels:
            budgets[c] = args.budget or max(r[1] for r in results[('GAASS + refine', c)])
        collect([(m, c, s, budgets[c], args.domains) for m in METHODS if m != 'GAASS + refine'
                 for c in channels for s in seeds])
    table = _table(results, budgets, channels)
    print(table)
    print(f'total {time.perf_counter() - start:.0f} s', file=sys.stderr)
    if not args.no_write:
        command = 'python bench/optimizer_comparison.py ' + ' '.join(argv or sys.argv[1:])
        key = f'{args.budget} evaluations' if args.budget else 'what GAASS + refine used'
        _write(table + f'\n\nDomains: {args.domains}. Seeds 0-{args.seeds - 1}.\n',
               command.strip(), ROOT / 'docs' / 'benchmarks.md', key)
    return 0


if __name__ == '__main__':
    sys.exit(main())
