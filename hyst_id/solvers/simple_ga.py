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

"""Test functions and a simple-GA baseline for the GAASS benchmarks (paper Fig. 2).

F1 (Eq. 23) is the 2-D Shubert function.  As printed, Eq. 23 has its global
*minimum* ``-186.7309`` on ``[-10, 10]^2`` and its maximum ``+210.4823``; the
paper's "global optimum 186.7307" is the magnitude of the minimum, so Fig. 2 is
reproduced by minimising :func:`shubert_2d` and plotting ``-F1``
(see ``docs/gaass.md``).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from hyst_id.errors import ConfigError
from hyst_id.solvers import gaass_ops as ops
from hyst_id.solvers.gaass import GaassHistory, GaassResult, parse_bounds, vectorize_scalar

__all__ = [
    'SHUBERT_2D_BOUNDS',
    'SHUBERT_2D_MIN',
    'SHUBERT_2D_MAX',
    'F1_OPTIMUM',
    'shubert_2d',
    'sphere',
    'simple_ga',
]

SHUBERT_2D_BOUNDS = ((-10.0, 10.0), (-10.0, 10.0))
#: Global minimum of Eq. 23 on ``[-10, 10]^2`` (18 minimisers).
SHUBERT_2D_MIN = -186.73090883102248
#: Global maximum of Eq. 23 on ``[-10, 10]^2`` (not the paper's optimum).
SHUBERT_2D_MAX = 210.48229401555335
#: The paper's F1 optimum, ``-SHUBERT_2D_MIN`` (paper prints 186.7307).
F1_OPTIMUM = -SHUBERT_2D_MIN


def shubert_2d(x: np.ndarray) -> np.ndarray:
    """F1 of Eq. 23, ``sum_i i cos((i+1) x1 + i) * sum_i i cos((i+1) x2 + i)``.

    Parameters
    ----------
    x : numpy.ndarray
        A point ``(2,)`` or a population ``(n, 2)``.

    Returns
    -------
    numpy.ndarray
        ``(n,)`` values for a population, a 0-d array for a single point.
    """
    x = np.asarray(x, dtype=float)
    i = np.arange(1.0, 6.0)
    terms = i * np.cos((i + 1.0) * x[..., :, None] + i)
    sums = terms.sum(axis=-1)
    return sums[..., 0] * sums[..., 1]


def sphere(x: np.ndarray) -> np.ndarray:
    """Sphere function ``sum x_i^2`` over the last axis (minimum 0 at the origin).

    Parameters
    ----------
    x : numpy.ndarray
        A point ``(m,)`` or a population ``(n, m)``.

    Returns
    -------
    numpy.ndarray
        Values, shape ``x.shape[:-1]``.
    """
    x = np.asarray(x, dtype=float)
    return np.sum(x * x, axis=-1)


def simple_ga(fun: Callable[..., Any], bounds: Any, *, pop_size: int = 6, maxiter: int = 100,
              p_c: float = 0.9, p_m: float = 0.01, selection: str = 'roulette',
              elitism: bool = False, rng: Any = None, vectorized: bool = True) -> GaassResult:
    """Plain real-coded simple GA (SGA), the baseline of the paper's Fig. 2.

    Each generation: select ``pop_size`` parents (roulette on the same
    windowed fitness GAASS uses, or binary tournament with replacement), pair
    them in order and, with probability ``p_c`` per pair, replace the pair by
    ``lam a + (1 - lam) b`` and ``(1 - lam) a + lam b`` (``lam ~ U(0, 1)``,
    whole arithmetic crossover), otherwise copy the parents; then every gene
    is, with probability ``p_m``, redrawn uniformly over its whole bound.  No
    adaptive search space, no constraints.  With ``elitism=True`` the previous
    best replaces the worst child when it would otherwise be lost.  The
    initial population is ``pop_size`` uniform draws.

    Parameters
    ----------
    fun : callable
        Population cost ``(n, m) -> (n,)`` to minimise (see ``vectorized``).
    bounds : sequence of (float, float) or scipy.optimize.Bounds
        Search domain.
    pop_size, maxiter : int
        Population size and number of generations.
    p_c, p_m : float
        Crossover probability per pair, mutation probability per gene.
    selection : {'roulette', 'tournament'}
        Parent selection.
    elitism : bool
        Keep the best chromosome (default False: Goldberg's SGA).
    rng : None, int or numpy.random.Generator
        Random source.
    vectorized : bool
        False if ``fun`` takes one vector.

    Returns
    -------
    GaassResult
        ``x``/``fun`` are the best found over the whole run and
        ``history.best_fun`` is best-so-far (with or without elitism);
        ``s`` is 0 and ``gamma`` the constant half bound widths.
    """
    low, high = parse_bounds(bounds)
    if selection not in ('roulette', 'tournament'):
        raise ConfigError(f"selection must be 'roulette' or 'tournament', got {selection!r}")
    if pop_size < 2 or maxiter < 1:
        raise ConfigError('pop_size must be >= 2 and maxiter >= 1')
    fun = fun if vectorized else vectorize_scalar(fun)
    gen = np.random.default_rng(rng)
    n, m = int(pop_size), low.size
    hist = GaassHistory.empty(maxiter, m)

    def evaluate(pop: np.ndarray) -> np.ndarray:
        cost = np.asarray(fun(pop), dtype=float).reshape(pop.shape[0]).copy()
        cost[~np.isfinite(cost)] = np.inf
        return cost

    pop = ops.uniform_in_box(low, high, n, gen)
    cost = evaluate(pop)
    nfev = n
    best = int(np.argmin(cost))
    best_x, best_f = pop[best].copy(), float(cost[best])
    for z in range(maxiter):
        nfd = ops.normalized_fitness_distance(cost)
        if selection == 'roulette':
            fit = ops.selection_fitness(cost, 'window')
            parents = gen.choice(n, size=n, replace=True, p=fit / fit.sum())
        else:
            a, b = gen.integers(0, n, size=(2, n))
            parents = np.where(cost[b] < cost[a], b, a)
        mates = pop[parents]
        children = mates.copy()
        n_pairs = n // 2
        xa, xb = mates[0:2 * n_pairs:2], mates[1:2 * n_pairs:2]
        lam = gen.random((n_pairs, 1))
        do = gen.random(n_pairs) < p_c
        c1 = np.where(do[:, None], lam * xa + (1 - lam) * xb, xa)
        c2 = np.where(do[:, None], (1 - lam) * xa + lam * xb, xb)
        children[0:2 * n_pairs:2], children[1:2 * n_pairs:2] = c1, c2
        mutate = gen.random((n, m)) < p_m
        children = np.where(mutate, ops.uniform_in_box(low, high, n, gen), children)
        children = np.clip(children, low, high)
        new_cost = evaluate(children)
        nfev += n
        if elitism and not new_cost.min() <= best_f:
            worst = int(np.argmax(new_cost))
            children[worst], new_cost[worst] = best_x, best_f
        pop, cost = children, new_cost
        g_best = int(np.argmin(cost))
        if cost[g_best] < best_f:
            best_x, best_f = pop[g_best].copy(), float(cost[g_best])
        finite = cost[np.isfinite(cost)]
        hist.best_fun[z], hist.best_x[z] = best_f, best_x
        hist.mean_fun[z] = finite.mean() if finite.size else np.nan
        hist.nfd[z], hist.s[z], hist.gamma[z] = nfd, 0, 0.5 * (high - low)
        hist.p_c[z], hist.p_m[z], hist.nfev[z] = p_c, p_m, nfev
    return GaassResult(x=best_x, fun=best_f, nfev=nfev, nit=maxiter,
                       success=bool(np.isfinite(best_f)),
                       message=f'simple GA: maximum number of generations reached '
                               f'(maxiter={maxiter})',
                       history=hist, population=pop, population_fun=cost)
