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

"""Genetic Algorithm with Adaptive Search Space (GAASS), paper section 3.3.

A steppable real-coded GA shaped like :func:`scipy.optimize.differential_evolution`:
:class:`GaassSolver` advances one generation per :meth:`GaassSolver.step`
(so a ROS node can drive it from a timer and read :attr:`GaassSolver.result`),
and :func:`minimize` runs it to the end.  The cost function is vectorised
population-major: ``fun(pop) -> (n,)`` costs to minimise for ``pop`` of shape
``(n, m)``.  Operator details and the choices made where the paper is silent
are in ``docs/gaass.md``; the operators themselves are in
:mod:`hyst_id.solvers.gaass_ops`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
import math
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from hyst_id.errors import ConfigError, InfeasibleBoundsError
from hyst_id.solvers import gaass_ops as ops

__all__ = [
    'GaassHistory',
    'GaassResult',
    'GaassSolver',
    'check_rates',
    'minimize',
    'parse_bounds',
    'vectorize_scalar',
]


@dataclass
class GaassHistory:
    """Per-generation record of a run (row ``z - 1`` is generation ``z``).

    ``best_fun`` is the best cost so far (with elitism this is also the best
    of the generation), ``mean_fun`` the mean finite cost of the generation,
    ``nfev`` the cumulative number of cost evaluations.  ``nfd``, ``s``,
    ``gamma`` (half-widths of Omega, shape ``(nit, m)``), ``p_c`` and ``p_m``
    are the values computed from the parent generation and used to breed it.
    """

    best_fun: np.ndarray
    mean_fun: np.ndarray
    nfd: np.ndarray
    s: np.ndarray
    gamma: np.ndarray
    p_c: np.ndarray
    p_m: np.ndarray
    best_x: np.ndarray
    nfev: np.ndarray

    def __len__(self) -> int:
        """Return the number of generations recorded."""
        return int(self.best_fun.shape[0])

    @classmethod
    def empty(cls, n_rows: int, m: int) -> GaassHistory:
        """Allocate a history with ``n_rows`` rows for ``m`` parameters."""
        return cls(best_fun=np.full(n_rows, np.nan), mean_fun=np.full(n_rows, np.nan),
                   nfd=np.full(n_rows, np.nan), s=np.zeros(n_rows, dtype=np.int64),
                   gamma=np.full((n_rows, m), np.nan), p_c=np.full(n_rows, np.nan),
                   p_m=np.full(n_rows, np.nan), best_x=np.full((n_rows, m), np.nan),
                   nfev=np.zeros(n_rows, dtype=np.int64))

    def head(self, n_rows: int) -> GaassHistory:
        """Return a copy of the first ``n_rows`` rows."""
        return GaassHistory(**{f.name: getattr(self, f.name)[:n_rows].copy()
                               for f in fields(self)})


@dataclass
class GaassResult:
    """Outcome of a run; attribute access like :class:`scipy.optimize.OptimizeResult`.

    ``x`` is the best parameter vector, ``fun`` its cost, ``nit`` the number of
    generations bred (initialisation excluded), ``nfev`` the number of cost
    evaluations (``2 pop_size`` for initialisation, then ``pop_size`` per
    generation), ``population`` / ``population_fun`` the last generation.
    ``res['x']`` and ``res.keys()`` work as on an ``OptimizeResult``.
    """

    x: np.ndarray
    fun: float
    nfev: int
    nit: int
    success: bool
    message: str
    history: GaassHistory
    population: np.ndarray
    population_fun: np.ndarray
    extra: dict = field(default_factory=dict, repr=False)

    def __getitem__(self, key: str) -> Any:
        """Return attribute ``key`` (``OptimizeResult`` style)."""
        if key in self.keys():
            return getattr(self, key)
        raise KeyError(key)

    def keys(self) -> list[str]:
        """Return the attribute names."""
        return [f.name for f in fields(self)]


def vectorize_scalar(fun: Callable[..., float]) -> Callable[..., np.ndarray]:
    """Wrap ``fun(x, *args) -> float`` into a population function ``(n, m) -> (n,)``.

    Parameters
    ----------
    fun : callable
        Scalar function of one parameter vector.

    Returns
    -------
    callable
        ``f(pop, *args)`` returning ``np.array([fun(x, *args) for x in pop])``.
    """
    def population_fun(pop: np.ndarray, *args: Any) -> np.ndarray:
        return np.array([fun(np.array(x), *args) for x in pop], dtype=float)
    return population_fun


def parse_bounds(bounds: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate bounds given as ``[(low, high), ...]`` or :class:`scipy.optimize.Bounds`.

    Parameters
    ----------
    bounds : sequence of (float, float) or scipy.optimize.Bounds
        Search domain of each parameter.

    Returns
    -------
    tuple of numpy.ndarray
        ``low`` and ``high``, shape ``(m,)`` each.

    Raises
    ------
    ConfigError
        If bounds are empty, not finite, or ``low >= high`` somewhere.
    """
    if hasattr(bounds, 'lb') and hasattr(bounds, 'ub'):
        low = np.atleast_1d(np.asarray(bounds.lb, dtype=float))
        high = np.atleast_1d(np.asarray(bounds.ub, dtype=float))
        low, high = np.broadcast_arrays(low, high)
    else:
        try:
            arr = np.asarray(bounds, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f'bounds must be a sequence of (low, high) pairs: {exc}') from None
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
            raise ConfigError(f'bounds must have shape (m, 2), got {arr.shape}')
        low, high = arr[:, 0], arr[:, 1]
    if low.size == 0:
        raise ConfigError('bounds are empty')
    if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
        raise ConfigError('bounds must be finite')
    bad = np.flatnonzero(~(low < high))
    if bad.size:
        i = int(bad[0])
        raise ConfigError(f'bounds[{i}] = ({low[i]:g}, {high[i]:g}): low must be < high')
    return low.astype(float).copy(), high.astype(float).copy()


def check_rates(c: float, xi: float, names: tuple[str, str] = ('c', 'xi')) -> None:
    """Refuse a contraction rate ``c`` that is not a finite number > 0, a ``xi`` outside (0, 1].

    ``names`` say them as the caller's user knows them (the CLI's flags).

    Raises
    ------
    ConfigError
        Either value out of its range.
    """
    if not (np.isfinite(c) and c > 0.0):
        raise ConfigError(f'{names[0]} must be a finite number > 0, got {c!r}')
    if not (np.isfinite(xi) and 0.0 < xi <= 1.0):
        raise ConfigError(f'{names[1]} must be in (0, 1], got {xi!r}')


def _pair(value: Sequence[float], name: str) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ConfigError(f'{name} must be a (low, high) pair of rates') from None
    if not (0.0 <= low <= high <= 1.0):
        raise ConfigError(f'{name} = ({low:g}, {high:g}) must satisfy 0 <= low <= high <= 1')
    return low, high


class GaassSolver:
    """Steppable GAASS minimiser.

    Parameters
    ----------
    fun : callable
        ``fun(pop, *args) -> (n,)`` costs to minimise for ``pop`` of shape
        ``(n, m)`` (or ``fun(x, *args) -> float`` with ``vectorized=False``).
        NaN or inf costs count as worst and are never selected as best.
    bounds : sequence of (float, float) or scipy.optimize.Bounds
        Parameter constraints ``C_lower, C_upper``; finite, ``low < high``.
    feasible : callable, optional
        ``feasible(pop) -> bool (n,)`` extra constraint mask (population-major,
        or per vector with ``vectorized=False``).  No infeasible chromosome is
        ever evaluated or kept (rejecting strategy).
    pop_size : int
        ``N_pop`` (>= 2); initialisation samples ``2 N_pop``.
    maxiter : int
        Maximum number of generations (>= 1).
    c : float
        Contraction coefficient of Eq. 15 (> 0).
    xi : float
        Relative size of the mutation sub-space, Eq. 22 (0 < xi <= 1).
    p_c, p_m : (float, float)
        ``(low, high)`` crossover rates (Eq. 17) and mutation rates (Eq. 20).
    target : float, optional
        Stop as soon as the best cost is ``<= target``.
    rng : None, int or numpy.random.Generator
        Random source; the same seed gives a bit-identical run.
    callback : callable, optional
        ``callback(intermediate_result: GaassResult)`` after each generation;
        returning True or raising StopIteration stops the run.
    max_reject_tries : int
        Maximum redraw rounds of the rejecting strategy.
    x0 : array_like, optional
        One ``(m,)`` or several ``(k, m)`` (``k <= 2 pop_size``) feasible
        starting vectors placed in the initial population.
    vectorized : bool
        False if ``fun`` and ``feasible`` take a single vector.
    args : tuple
        Extra arguments passed to ``fun``.
    fitness : {'window', 'rank'}
        Cost-to-fitness transform used by selection (Eq. 11).
    """

    def __init__(self, fun: Callable[..., Any], bounds: Any, *,
                 feasible: Callable[[np.ndarray], Any] | None = None, pop_size: int = 10,
                 maxiter: int = 500, c: float = 0.007, xi: float = 0.02,
                 p_c: Sequence[float] = (0.5, 0.9), p_m: Sequence[float] = (0.01, 0.3),
                 target: float | None = None, rng: Any = None,
                 callback: Callable[[GaassResult], Any] | None = None,
                 max_reject_tries: int = 1000, x0: Any = None, vectorized: bool = True,
                 args: tuple = (), fitness: str = 'window') -> None:
        self._low, self._high = parse_bounds(bounds)
        m = self._low.size
        if int(pop_size) != pop_size or pop_size < 2:
            raise ConfigError(f'pop_size must be an integer >= 2, got {pop_size!r}')
        if int(maxiter) != maxiter or maxiter < 1:
            raise ConfigError(f'maxiter must be an integer >= 1, got {maxiter!r}')
        if int(max_reject_tries) != max_reject_tries or max_reject_tries < 1:
            raise ConfigError('max_reject_tries must be an integer >= 1, '
                              f'got {max_reject_tries!r}')
        check_rates(c, xi)
        if fitness not in ops.FITNESS_TRANSFORMS:
            raise ConfigError(f'fitness must be one of {ops.FITNESS_TRANSFORMS}, got {fitness!r}')
        if target is not None and not np.isfinite(target):
            raise ConfigError(f'target must be a finite number, got {target!r}')
        self._fun = fun if vectorized else vectorize_scalar(fun)
        self._feasible = feasible if (vectorized or feasible is None) else \
            vectorize_scalar(feasible)
        self._args = tuple(args)
        self.pop_size = int(pop_size)
        self.maxiter = int(maxiter)
        self.c, self.xi = float(c), float(xi)
        self.p_c, self.p_m = _pair(p_c, 'p_c'), _pair(p_m, 'p_m')
        self.target = None if target is None else float(target)
        self.callback = callback
        self.max_reject_tries = int(max_reject_tries)
        self.fitness = fitness
        self._rng = np.random.default_rng(rng)
        self._x0 = self._check_x0(x0, m)
        self._gamma_init = 0.5 * (self._high - self._low)
        self._pop: np.ndarray | None = None
        self._cost: np.ndarray | None = None
        self._hist = GaassHistory.empty(self.maxiter, m)
        self.nit = 0
        self.nfev = 0
        self.n_fallbacks = 0
        self._s = 0
        self._prev_nfd: float | None = None
        self._finished = False
        self._success = False
        self._message = 'not started'

    # ------------------------------------------------------------------ helpers
    def _check_x0(self, x0: Any, m: int) -> np.ndarray | None:
        if x0 is None:
            return None
        arr = np.atleast_2d(np.asarray(x0, dtype=float))
        if arr.ndim != 2 or arr.shape[1] != m or arr.shape[0] > 2 * self.pop_size:
            raise ConfigError(f'x0 must have shape ({m},) or (k, {m}) with k <= '
                              f'{2 * self.pop_size}, got {np.shape(x0)}')
        if not np.all(np.isfinite(arr)):
            raise ConfigError('x0 must be finite')
        if np.any(arr < self._low) or np.any(arr > self._high):
            raise ConfigError('x0 lies outside the bounds')
        return arr.copy()

    def _is_feasible(self, pop: np.ndarray) -> np.ndarray:
        ok = np.all((pop >= self._low) & (pop <= self._high), axis=1)
        if self._feasible is not None and pop.shape[0]:
            mask = np.asarray(self._feasible(pop), dtype=bool).reshape(-1)
            if mask.shape != (pop.shape[0],):
                raise ConfigError(f'feasible() returned {mask.shape[0]} values for '
                                  f'{pop.shape[0]} chromosomes')
            ok &= mask
        return ok

    def _evaluate(self, pop: np.ndarray) -> np.ndarray:
        n = pop.shape[0]
        cost = np.asarray(self._fun(np.ascontiguousarray(pop), *self._args), dtype=float)
        if cost.size != n:
            raise ConfigError(f'cost function returned {cost.size} values for {n} chromosomes')
        cost = cost.reshape(n).copy()
        cost[~np.isfinite(cost)] = np.inf
        self.nfev += n
        return cost

    def _finish(self, success: bool, message: str) -> None:
        self._finished, self._success, self._message = True, success, message

    # -------------------------------------------------------------- operators
    def init_population(self) -> None:
        """Sample ``2 pop_size`` feasible chromosomes and keep ``pop_size`` by tournament.

        Idempotent.  Raises :class:`~hyst_id.errors.InfeasibleBoundsError` if
        ``max_reject_tries`` batches of uniform draws do not yield enough
        feasible chromosomes.
        """
        if self._pop is not None:
            return
        n_init = 2 * self.pop_size
        parts = []
        if self._x0 is not None:
            bad = np.flatnonzero(~self._is_feasible(self._x0))
            if bad.size:
                raise ConfigError(f'x0 row {int(bad[0])} violates the constraints')
            parts.append(self._x0)
        have = sum(p.shape[0] for p in parts)
        tries = 0
        while have < n_init and tries < self.max_reject_tries:
            draw = ops.uniform_in_box(self._low, self._high, n_init, self._rng)
            draw = draw[self._is_feasible(draw)][:n_init - have]
            parts.append(draw)
            have += draw.shape[0]
            tries += 1
        if have < n_init:
            raise InfeasibleBoundsError(
                f'only {have} of {n_init} feasible chromosomes found in {tries * n_init} '
                'uniform draws: the bounds admit (almost) no parameters satisfying the '
                'constraints')
        pop = np.concatenate(parts, axis=0)
        cost = self._evaluate(pop)
        keep = ops.pairwise_tournament(cost, self.pop_size, self._rng)
        self._pop, self._cost = pop[keep], cost[keep]
        self._message = 'initialised'

    # ------------------------------------------------------------- generation
    def step(self) -> bool:
        """Breed and evaluate exactly one generation.

        Returns
        -------
        bool
            True when a stop rule is met (target, callback, maxiter); further
            calls then do nothing and return True.
        """
        if self._finished:
            return True
        self.init_population()
        pop, cost = self._pop, self._cost
        n, m = pop.shape
        # Evaluation: NFD (Eq. 13) drives s (Eq. 16), p_c (Eq. 17), p_m (Eq. 20).
        nfd = ops.normalized_fitness_distance(cost)
        if self._prev_nfd is None:
            converging, self._s = True, 1
        else:
            converging = bool(nfd <= self._prev_nfd)
            self._s += int(converging)
        self._prev_nfd = nfd
        gamma = self._gamma_init * math.exp(-self.c * self._s)
        p_c = self.p_c[1] if converging else self.p_c[0]
        p_m = self.p_m[1] if converging else self.p_m[0]
        # Adaptive search space Omega (Eq. 14), centred on the population mean.
        centre = pop.mean(axis=0)
        om_lo = np.maximum(self._low, centre - gamma)
        om_hi = np.minimum(self._high, centre + gamma)
        elite = int(np.argmin(cost))
        elite_x, elite_f = pop[elite].copy(), float(cost[elite])
        # Selection (Eq. 11-12), crossover (Eq. 18), regeneration (Eq. 19), mutation (Eq. 21).
        pool = pop[ops.remainder_stochastic_sampling(
            ops.selection_fitness(cost, self.fitness), n, self._rng)]
        n_c = min(n, ops.round_half_up(n * p_c))
        tries, feas, rng = self.max_reject_tries, self._is_feasible, self._rng
        children, fb_c = ops.crossover(pool, n_c, self._low, self._high, feas, tries, rng)
        regen, fb_r = ops.regenerate(pool[n_c:], om_lo, om_hi, feas, tries, rng)
        new, fb_m = ops.mutate(np.concatenate([children, regen], axis=0),
                               ops.round_half_up(n * m * p_m), om_lo, om_hi, self.xi, feas,
                               tries, rng)
        self.n_fallbacks += fb_c + fb_r + fb_m
        new_cost = self._evaluate(new)
        # Elitism: the best chromosome so far always survives.
        if not new_cost.min() <= elite_f:
            worst = int(np.argmax(new_cost))
            new[worst], new_cost[worst] = elite_x, elite_f
        self._pop, self._cost = new, new_cost
        self._record(nfd, gamma, p_c, p_m)
        self.nit += 1
        return self._check_stop()

    def _record(self, nfd: float, gamma: np.ndarray, p_c: float, p_m: float) -> None:
        h, z = self._hist, self.nit
        best = int(np.argmin(self._cost))
        finite = self._cost[np.isfinite(self._cost)]
        h.best_fun[z] = self._cost[best]
        h.mean_fun[z] = finite.mean() if finite.size else np.nan
        h.nfd[z], h.s[z], h.gamma[z], h.p_c[z], h.p_m[z] = nfd, self._s, gamma, p_c, p_m
        h.best_x[z] = self._pop[best]
        h.nfev[z] = self.nfev

    def _check_stop(self) -> bool:
        stop_cb = False
        if self.callback is not None:
            self._message = f'in progress (generation {self.nit})'
            try:
                stop_cb = bool(self.callback(self.result))
            except StopIteration:
                stop_cb = True
        best = float(self._cost.min())
        if self.target is not None and best <= self.target:
            self._finish(True, f'target reached: best cost {best:.6g} <= {self.target:.6g}')
        elif stop_cb:
            self._finish(True, 'callback requested stop')
        elif self.nit >= self.maxiter:
            msg = f'maximum number of generations reached (maxiter={self.maxiter})'
            if self.target is not None:
                msg += f'; target {self.target:.6g} not reached'
            self._finish(self.target is None, msg)
        else:
            self._message = f'in progress (generation {self.nit})'
        if self._finished and not np.isfinite(best):
            self._finish(False, self._message + '; no finite cost was found')
        return self._finished

    def solve(self) -> GaassResult:
        """Run generations until a stop rule is met and return the result."""
        while not self.step():
            pass
        return self.result

    @property
    def finished(self) -> bool:
        """Tell whether a stop rule has been met."""
        return self._finished

    @property
    def result(self) -> GaassResult:
        """Snapshot of the current state (best so far, history, population)."""
        m = self._low.size
        if self._pop is None:
            return GaassResult(x=np.full(m, np.nan), fun=float('inf'), nfev=self.nfev, nit=0,
                               success=False, message=self._message,
                               history=self._hist.head(0), population=np.empty((0, m)),
                               population_fun=np.empty(0))
        best = int(np.argmin(self._cost))
        return GaassResult(x=self._pop[best].copy(), fun=float(self._cost[best]),
                           nfev=self.nfev, nit=self.nit, success=self._success,
                           message=self._message, history=self._hist.head(self.nit),
                           population=self._pop.copy(), population_fun=self._cost.copy(),
                           extra={'n_fallbacks': self.n_fallbacks})

    def __iter__(self) -> Iterator[tuple[np.ndarray, float]]:
        """Iterate generations, yielding ``(best_x, best_fun)`` like scipy's DE solver."""
        return self

    def __next__(self) -> tuple[np.ndarray, float]:
        """Advance one generation and return ``(best_x, best_fun)``."""
        if self._finished:
            raise StopIteration
        self.step()
        best = int(np.argmin(self._cost))
        return self._pop[best].copy(), float(self._cost[best])


def minimize(fun: Callable[..., Any], bounds: Any, **kwargs: Any) -> GaassResult:
    """Minimise ``fun`` over ``bounds`` with GAASS; see :class:`GaassSolver`.

    Parameters
    ----------
    fun : callable
        Population cost function ``(n, m) -> (n,)`` (see ``vectorized``).
    bounds : sequence of (float, float) or scipy.optimize.Bounds
        Search domain.
    **kwargs
        Keyword arguments of :class:`GaassSolver`.

    Returns
    -------
    GaassResult
        Best vector, cost, history and final population.
    """
    return GaassSolver(fun, bounds, **kwargs).solve()
