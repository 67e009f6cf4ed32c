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

"""Genetic operators of GAASS (paper section 3.3), as pure numpy functions.

Every function takes its random generator explicitly and never touches the
cost function, so the solver in :mod:`hyst_id.solvers.gaass` decides when costs are
evaluated.  Costs are *minimised*; non-finite costs are expected to have been
replaced by ``+inf`` (worst) before they reach these functions.  The choices
made where the paper is silent are described in ``docs/gaass.md``.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = [
    'normalized_fitness_distance',
    'selection_fitness',
    'remainder_stochastic_sampling',
    'pairwise_tournament',
    'schema_arithmetic_crossover',
    'uniform_in_box',
    'mutation_positions',
    'mutation_window',
    'redraw_until_feasible',
    'round_half_up',
    'crossover',
    'regenerate',
    'mutate',
]

Feasible = Callable[[np.ndarray], np.ndarray]

FITNESS_TRANSFORMS = ('window', 'rank')


def round_half_up(value: float) -> int:
    """Round a non-negative count to the nearest integer, halves upwards.

    Parameters
    ----------
    value : float
        Non-negative real count, e.g. ``N_pop * p_c``.

    Returns
    -------
    int
        ``floor(value + 0.5)`` (Python's ``round`` would round halves to even).
    """
    return int(np.floor(value + 0.5 + 1e-9))


def normalized_fitness_distance(costs: np.ndarray, eps_rel: float = 1e-12) -> float:
    """Compute the Normalized Fitness Distance, Eq. 13, minimisation form, on costs.

    ``NFD = (f_max - f_mean) / (f_max - f_min + eps)`` over the finite costs,
    with ``eps = eps_rel * (1 + max|f|)`` so that the guard against a zero
    division scales with the cost.

    Parameters
    ----------
    costs : numpy.ndarray
        Costs of the population, shape ``(n,)``; ``inf`` marks a failed cost.
    eps_rel : float, optional
        Relative size of the zero-division guard.

    Returns
    -------
    float
        NFD in ``[0, 1)``, or ``nan`` when no cost is finite.
    """
    finite = costs[np.isfinite(costs)]
    if finite.size == 0:
        return float('nan')
    f_max = float(finite.max())
    f_min = float(finite.min())
    eps = eps_rel * (1.0 + max(abs(f_max), abs(f_min)))
    return (f_max - float(finite.mean())) / (f_max - f_min + eps)


def selection_fitness(costs: np.ndarray, transform: str = 'window') -> np.ndarray:
    """Turn costs to minimise into non-negative fitness values for Eq. 11.

    ``'window'`` (default) is linear windowing against the worst finite cost
    of the generation, ``f_k = (J_worst - J_k) + 0.1 (J_worst - J_best)``, so
    the worst chromosome keeps a small chance.  ``'rank'`` gives
    ``f_k = n - rank_k`` (best gets ``n``, worst ``1``).  Non-finite costs get
    fitness 0.  If all finite costs are equal every finite one gets 1.

    Parameters
    ----------
    costs : numpy.ndarray
        Costs, shape ``(n,)``, ``inf`` for failed evaluations.
    transform : {'window', 'rank'}
        Which transform to use.

    Returns
    -------
    numpy.ndarray
        Fitness, shape ``(n,)``, all ``>= 0``.
    """
    finite = np.isfinite(costs)
    fitness = np.zeros(costs.shape, dtype=float)
    if not finite.any():
        return np.ones(costs.shape, dtype=float)
    good = costs[finite]
    if transform == 'rank':
        order = np.argsort(good, kind='stable')
        ranks = np.empty(good.size, dtype=float)
        ranks[order] = np.arange(good.size, dtype=float)
        fitness[finite] = good.size - ranks
        return fitness
    if transform != 'window':
        raise ValueError(f'unknown fitness transform {transform!r}')
    spread = float(good.max() - good.min())
    if not spread > 0.0:
        fitness[finite] = 1.0
        return fitness
    fitness[finite] = (good.max() - good) + 0.1 * spread
    return fitness


def remainder_stochastic_sampling(fitness: np.ndarray, n: int,
                                  rng: np.random.Generator) -> np.ndarray:
    """Remainder stochastic sampling with replacement, Eq. 11-12.

    ``p_k = f_k / sum f`` and ``e_k = n p_k``; chromosome ``k`` first gets
    ``floor(e_k)`` copies (deterministic part), then the remaining slots are
    drawn by roulette on the fractional parts ``e_k - floor(e_k)``.

    Parameters
    ----------
    fitness : numpy.ndarray
        Non-negative fitness, shape ``(N_pop,)``.
    n : int
        Number of chromosomes to select.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    numpy.ndarray
        Selected indices, shape ``(n,)``, in random order.
    """
    total = float(fitness.sum())
    if not total > 0.0:
        p = np.full(fitness.size, 1.0 / fitness.size)
    else:
        p = fitness / total
    expected = n * p
    counts = np.floor(expected + 1e-12).astype(np.int64)
    counts = np.minimum(counts, n)
    chosen = np.repeat(np.arange(fitness.size), counts)[:n]
    remaining = n - chosen.size
    if remaining > 0:
        frac = np.clip(expected - counts, 0.0, None)
        frac_sum = float(frac.sum())
        probs = frac / frac_sum if frac_sum > 0.0 else p
        extra = rng.choice(fitness.size, size=remaining, replace=True, p=probs)
        chosen = np.concatenate([chosen, extra])
    return rng.permutation(chosen)


def pairwise_tournament(costs: np.ndarray, n_keep: int,
                        rng: np.random.Generator) -> np.ndarray:
    """Binary tournament without replacement (initial ``2 N_pop -> N_pop``).

    The ``2 n_keep`` chromosomes are shuffled into ``n_keep`` disjoint pairs
    and the lower cost of each pair survives (first of the pair on a tie), so
    no chromosome is duplicated and the best one always survives.

    Parameters
    ----------
    costs : numpy.ndarray
        Costs, shape ``(2 n_keep,)``.
    n_keep : int
        Number of survivors.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    numpy.ndarray
        Indices of the survivors, shape ``(n_keep,)``.
    """
    perm = rng.permutation(costs.size)[:2 * n_keep].reshape(n_keep, 2)
    first_wins = ~(costs[perm[:, 1]] < costs[perm[:, 0]])
    return np.where(first_wins, perm[:, 0], perm[:, 1])


def schema_arithmetic_crossover(xa: np.ndarray, xb: np.ndarray,
                                rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Two-parent arithmetic crossover combined with schema processing.

    For each pair a weight ``lam ~ U(0, 1)`` (arithmetic part) and a
    per-gene fair coin ``M_i`` (schema part, as a binary uniform crossover)
    are drawn; then ``c1_i = lam a_i + (1 - lam) b_i`` where ``M_i`` is set
    and ``c1_i = (1 - lam) a_i + lam b_i`` elsewhere, and ``c2 = a + b - c1``.
    With ``lam`` near 0 or 1 this is a gene exchange as in a binary GA, with
    ``lam`` near 0.5 a blend; each child gene stays between its parents' genes.

    Parameters
    ----------
    xa, xb : numpy.ndarray
        Parents, shape ``(k, m)`` each.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    tuple of numpy.ndarray
        The two children, shape ``(k, m)`` each.
    """
    lam = rng.random((xa.shape[0], 1))
    mask = rng.random(xa.shape) < 0.5
    weight = np.where(mask, lam, 1.0 - lam)
    c1 = weight * xa + (1.0 - weight) * xb
    c2 = (1.0 - weight) * xa + weight * xb
    return c1, c2


def uniform_in_box(low: np.ndarray, high: np.ndarray, n: int,
                   rng: np.random.Generator) -> np.ndarray:
    """Draw ``n`` points uniformly in the box ``[low, high]``.

    Parameters
    ----------
    low, high : numpy.ndarray
        Box corners, shape ``(m,)`` or ``(n, m)``.
    n : int
        Number of points.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    numpy.ndarray
        Points, shape ``(n, m)``.
    """
    m = np.shape(low)[-1]
    return low + rng.random((n, m)) * (high - low)


def mutation_positions(n: int, m: int, n_mut: int,
                       rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Choose ``n_mut`` distinct (chromosome, gene) positions, Eq. 21.

    Parameters
    ----------
    n, m : int
        Population size and number of genes.
    n_mut : int
        Number of genes to mutate (capped at ``n m``).
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    tuple of numpy.ndarray
        Row and column indices, shape ``(n_mut,)`` each.
    """
    n_mut = min(max(n_mut, 0), n * m)
    flat = rng.choice(n * m, size=n_mut, replace=False)
    return flat // m, flat % m


def mutation_window(genes: np.ndarray, omega_low: np.ndarray, omega_high: np.ndarray,
                    xi: float) -> tuple[np.ndarray, np.ndarray]:
    """Sub-space ``omega = xi * Omega`` centred on each gene, clipped to Omega (Eq. 22).

    A gene lying outside Omega is first moved to Omega's nearest edge.

    Parameters
    ----------
    genes : numpy.ndarray
        Current gene values, shape ``(k,)``.
    omega_low, omega_high : numpy.ndarray
        Omega bounds for the same genes, shape ``(k,)``.
    xi : float
        Relative size of omega.

    Returns
    -------
    tuple of numpy.ndarray
        Lower and upper ends of the window for each gene.
    """
    centre = np.clip(genes, omega_low, omega_high)
    half = 0.5 * xi * (omega_high - omega_low)
    return np.maximum(omega_low, centre - half), np.minimum(omega_high, centre + half)


def redraw_until_feasible(candidates: np.ndarray, feasible: Callable[[np.ndarray], np.ndarray],
                          draw: Callable[[np.ndarray], np.ndarray], fallback: np.ndarray,
                          max_tries: int) -> tuple[np.ndarray, int]:
    """Rejecting strategy: redraw infeasible rows, then fall back.

    Parameters
    ----------
    candidates : numpy.ndarray
        Proposed chromosomes, shape ``(k, m)``; modified in place.
    feasible : callable
        ``feasible(pop) -> bool (n,)``, including the box check.
    draw : callable
        ``draw(rows) -> (len(rows), m)`` new proposals for the given row indices.
    fallback : numpy.ndarray
        Feasible replacement rows, shape ``(k, m)``, used for rows still
        infeasible after ``max_tries`` redraws.
    max_tries : int
        Maximum number of redraw rounds.

    Returns
    -------
    tuple
        The feasible chromosomes and the number of rows that fell back.
    """
    ok = feasible(candidates)
    tries = 0
    while not ok.all() and tries < max_tries:
        rows = np.flatnonzero(~ok)
        candidates[rows] = draw(rows)
        ok[rows] = feasible(candidates[rows])
        tries += 1
    bad = np.flatnonzero(~ok)
    if bad.size:
        candidates[bad] = fallback[bad]
    return candidates, int(bad.size)


def crossover(pool: np.ndarray, n_c: int, low: np.ndarray, high: np.ndarray,
              feasible: Feasible, max_tries: int,
              rng: np.random.Generator) -> tuple[np.ndarray, int]:
    """Breed ``n_c`` offspring (Eq. 18) from the mating pool, rejecting infeasible ones.

    The pool is shuffled and consecutive chromosomes are paired (cyclically
    if ``n_c`` needs more pairs than the pool holds); each pair gives two
    children by :func:`schema_arithmetic_crossover`, the last one is dropped
    when ``n_c`` is odd.  An infeasible child is redrawn from the same pair;
    after ``max_tries`` rounds it is replaced by its own parent.

    Parameters
    ----------
    pool : numpy.ndarray
        Mating pool, shape ``(n, m)``, all feasible.
    n_c : int
        Number of offspring, ``0 <= n_c``.
    low, high : numpy.ndarray
        Parameter bounds (children are clipped to them against round-off).
    feasible : callable
        Feasibility mask of a population, box check included.
    max_tries : int
        Redraw rounds of the rejecting strategy.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    tuple
        Offspring ``(n_c, m)`` and the number of fallbacks to a parent.
    """
    n, m = pool.shape
    if n_c <= 0:
        return np.empty((0, m)), 0
    n_pairs = (n_c + 1) // 2
    perm = rng.permutation(n)
    xa = pool[perm[(2 * np.arange(n_pairs)) % n]]
    xb = pool[perm[(2 * np.arange(n_pairs) + 1) % n]]

    def draw(rows: np.ndarray) -> np.ndarray:
        c1, c2 = schema_arithmetic_crossover(xa[rows // 2], xb[rows // 2], rng)
        return np.clip(np.where((rows % 2 == 0)[:, None], c1, c2), low, high)

    rows = np.arange(n_c)
    parents = np.where((rows % 2 == 0)[:, None], xa[rows // 2], xb[rows // 2])
    return redraw_until_feasible(draw(rows), feasible, draw, parents, max_tries)


def regenerate(pool_rest: np.ndarray, omega_low: np.ndarray, omega_high: np.ndarray,
               feasible: Feasible, max_tries: int,
               rng: np.random.Generator) -> tuple[np.ndarray, int]:
    """Fill the vacancies left by crossover with chromosomes drawn in Omega (Eq. 19).

    ``x = x_mean + r gamma`` with ``r ~ U[-1, 1]`` per gene, restricted to the
    bounds, is a uniform draw in Omega (Eq. 14), which is how it is drawn.
    A regenerated chromosome still infeasible after ``max_tries`` rounds is
    replaced by the mating-pool chromosome of the same slot.

    Parameters
    ----------
    pool_rest : numpy.ndarray
        Mating-pool chromosomes of the vacant slots, shape ``(k, m)`` (fallbacks).
    omega_low, omega_high : numpy.ndarray
        Omega, shape ``(m,)``.
    feasible : callable
        Feasibility mask of a population, box check included.
    max_tries : int
        Redraw rounds of the rejecting strategy.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    tuple
        Regenerated chromosomes ``(k, m)`` and the number of fallbacks.
    """
    def draw(rows: np.ndarray) -> np.ndarray:
        return uniform_in_box(omega_low, omega_high, rows.size, rng)

    if pool_rest.shape[0] == 0:
        return pool_rest.copy(), 0
    return redraw_until_feasible(draw(np.arange(pool_rest.shape[0])), feasible, draw,
                                 pool_rest.copy(), max_tries)


def mutate(pop: np.ndarray, n_mut: int, omega_low: np.ndarray, omega_high: np.ndarray,
           xi: float, feasible: Feasible, max_tries: int,
           rng: np.random.Generator) -> tuple[np.ndarray, int]:
    """Mutate ``n_mut`` distinct genes of the population (Eq. 20-22).

    Each chosen gene is redrawn uniformly in its :func:`mutation_window`.  A
    chromosome made infeasible gets all its mutated genes redrawn; after
    ``max_tries`` rounds it keeps its pre-mutation genes.

    Parameters
    ----------
    pop : numpy.ndarray
        Population, shape ``(n, m)``, all feasible (not modified).
    n_mut : int
        Number of genes to mutate, ``N_m``.
    omega_low, omega_high : numpy.ndarray
        Omega, shape ``(m,)``.
    xi : float
        Relative size of omega, Eq. 22.
    feasible : callable
        Feasibility mask of a population, box check included.
    max_tries : int
        Redraw rounds of the rejecting strategy.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    tuple
        Mutated population and the number of chromosomes that fell back.
    """
    n, m = pop.shape
    rows, cols = mutation_positions(n, m, n_mut, rng)
    if rows.size == 0:
        return pop, 0
    w_lo, w_hi = mutation_window(pop[rows, cols], omega_low[cols], omega_high[cols], xi)
    touched = np.unique(rows)
    local = np.searchsorted(touched, rows)
    original = pop[touched].copy()

    def draw(sel: np.ndarray) -> np.ndarray:
        inv = np.full(touched.size, -1)
        inv[sel] = np.arange(sel.size)
        hit = inv[local] >= 0
        block = original[sel].copy()
        vals = w_lo[hit] + rng.random(int(hit.sum())) * (w_hi[hit] - w_lo[hit])
        block[inv[local[hit]], cols[hit]] = vals
        return block

    block, n_fb = redraw_until_feasible(draw(np.arange(touched.size)), feasible, draw,
                                        original, max_tries)
    out = pop.copy()
    out[touched] = block
    return out, n_fb
