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

"""Tests of the GAASS solver, its operators and the F1 benchmark."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import Bounds

from hyst_id.errors import ConfigError, HystIdError, InfeasibleBoundsError
from hyst_id.solvers import gaass_ops as ops
from hyst_id.solvers import simple_ga as bm
from hyst_id.solvers.gaass import GaassResult, GaassSolver, minimize
from hyst_id.solvers.simple_ga import shubert_2d, simple_ga, sphere

SPHERE_BOUNDS = [(-5.0, 5.0)] * 5


def _same_result(a: GaassResult, b: GaassResult) -> bool:
    hist = all(np.array_equal(getattr(a.history, k), getattr(b.history, k), equal_nan=True)
               for k in ('best_fun', 'mean_fun', 'nfd', 's', 'gamma', 'p_c', 'p_m', 'best_x'))
    return (hist and np.array_equal(a.x, b.x) and a.fun == b.fun and a.nfev == b.nfev
            and np.array_equal(a.population, b.population))


def test_seeded_runs_are_bit_identical():
    a = minimize(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=6, maxiter=40, rng=3)
    b = minimize(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=6, maxiter=40,
                 rng=np.random.default_rng(3))
    c = minimize(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=6, maxiter=40, rng=4)
    assert _same_result(a, b)
    assert not _same_result(a, c)


@pytest.mark.parametrize('bounds', [
    [(1.0, 0.0)], [(0.0, 0.0)], [(0.0, np.inf)], [(np.nan, 1.0)], [], [(0.0, 1.0, 2.0)],
    'abc', Bounds([0.0, 1.0], [1.0, 1.0]),
])
def test_bad_bounds_raise_config_error(bounds):
    with pytest.raises(ConfigError):
        GaassSolver(sphere, bounds)


def test_scipy_bounds_accepted():
    res = minimize(sphere, Bounds([-1.0, -1.0], [1.0, 2.0]), maxiter=5, rng=0)
    assert res.x.shape == (2,)
    assert np.all(res.population >= [-1.0, -1.0]) and np.all(res.population <= [1.0, 2.0])


@pytest.mark.parametrize('kwargs', [
    {'pop_size': 1}, {'maxiter': 0}, {'c': 0.0}, {'xi': 0.0}, {'p_c': (0.9, 0.5)},
    {'p_m': (0.0, 1.5)}, {'max_reject_tries': 0}, {'fitness': 'nope'}, {'target': np.nan},
    {'x0': [10.0, 0.0]}, {'x0': [0.0]},
])
def test_bad_options_raise_config_error(kwargs):
    with pytest.raises(ConfigError):
        GaassSolver(sphere, [(-1.0, 1.0)] * 2, **kwargs)


def test_infeasible_bounds_raise_one_line_error():
    solver = GaassSolver(sphere, [(0.0, 1.0)] * 3, max_reject_tries=20,
                         feasible=lambda pop: np.zeros(pop.shape[0], dtype=bool))
    with pytest.raises(InfeasibleBoundsError) as info:
        solver.step()
    assert isinstance(info.value, HystIdError)
    assert '\n' not in str(info.value)


def test_callback_returning_true_stops_early():
    seen = []

    def callback(res):
        seen.append(res.nit)
        return res.nit >= 7

    res = minimize(sphere, SPHERE_BOUNDS, maxiter=100, callback=callback, rng=1)
    assert res.nit == 7 and seen == list(range(1, 8))
    assert res.success and res.message == 'callback requested stop'
    assert len(res.history) == 7


def test_callback_raising_stop_iteration_stops_early():
    def callback(res):
        if res.nit == 3:
            raise StopIteration

    res = minimize(sphere, SPHERE_BOUNDS, maxiter=100, callback=callback, rng=1)
    assert res.nit == 3 and res.success and res.message == 'callback requested stop'


def test_target_stops_early():
    res = minimize(sphere, SPHERE_BOUNDS, maxiter=500, target=1.0, rng=2)
    assert res.fun <= 1.0 and res.nit < 500
    assert res.success and res.message.startswith('target reached')


def test_maxiter_stop_messages():
    res = minimize(sphere, SPHERE_BOUNDS, maxiter=5, rng=0)
    assert res.success and 'maxiter=5' in res.message
    res = minimize(sphere, SPHERE_BOUNDS, maxiter=5, rng=0, target=-1.0)
    assert not res.success and 'not reached' in res.message


def test_history_lengths_match_nit_and_nfev():
    n, m = 8, 5
    res = minimize(sphere, SPHERE_BOUNDS, pop_size=n, maxiter=30, rng=0)
    h = res.history
    assert res.nit == 30 == len(h)
    for name in ('best_fun', 'mean_fun', 'nfd', 's', 'p_c', 'p_m', 'nfev'):
        assert getattr(h, name).shape == (res.nit,)
    assert h.gamma.shape == h.best_x.shape == (res.nit, m)
    assert res.nfev == 2 * n + n * res.nit == h.nfev[-1]
    assert np.all(np.diff(h.best_fun) <= 0.0)  # elitism
    assert np.all(np.diff(h.s) >= 0) and h.s[0] == 1
    assert np.all(np.diff(h.gamma, axis=0) <= 0.0)
    assert np.allclose(h.gamma[0], 5.0 * np.exp(-0.007))
    assert set(h.p_c) <= {0.5, 0.9} and set(h.p_m) <= {0.01, 0.3}
    assert res.population.shape == (n, m) and res.population_fun.shape == (n,)
    assert res['fun'] == res.fun and 'history' in res.keys()


def test_steppable_api_and_iteration():
    solver = GaassSolver(sphere, SPHERE_BOUNDS, maxiter=4, rng=0)
    assert solver.result.nit == 0 and not solver.result.success
    solver.init_population()
    first = solver.result.population.copy()
    solver.init_population()  # idempotent
    assert np.array_equal(first, solver.result.population)
    assert solver.result.nfev == 20
    assert solver.step() is False and solver.result.nit == 1
    steps = list(solver)
    assert len(steps) == 3 and solver.finished and solver.step() is True
    assert solver.result.nit == 4
    assert steps[-1][1] == solver.result.fun


def test_f1_shubert_median_within_one_percent():
    best = [-minimize(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=6, maxiter=100, rng=seed).fun
            for seed in range(10)]
    assert np.median(best) >= 0.99 * bm.F1_OPTIMUM
    assert max(best) <= bm.F1_OPTIMUM + 1e-9


def test_sphere_5d_converges_near_zero():
    res = minimize(sphere, SPHERE_BOUNDS, pop_size=10, maxiter=500, rng=0)
    assert res.fun < 1e-3 and np.all(np.abs(res.x) < 0.05)


def _constraint(pop):
    """Hysteresis-like constraints: c_l < c_r and min(m_l, m_r) > m_t, plus a thin band."""
    m_l, m_r, m_t, c_l, c_r = pop.T
    return (c_l < c_r) & (np.minimum(m_l, m_r) > m_t) & (np.abs(c_r - c_l - 1.0) < 0.3)


def test_constraints_never_violated():
    bounds = [(0.0, 5.0)] * 3 + [(-5.0, 5.0)] * 2
    evaluated = []

    def cost(pop):
        evaluated.append(_constraint(pop).all())
        target = np.array([1.0, 1.05, 0.1, -0.25, 0.5])
        return np.sum((pop - target) ** 2, axis=1)

    populations = []
    res = minimize(cost, bounds, feasible=_constraint, pop_size=10, maxiter=150, rng=5,
                   callback=lambda r: populations.append(r.population.copy()))
    assert len(populations) == res.nit == 150
    assert all(evaluated) and all(_constraint(p).all() for p in populations)
    assert res.fun < 0.05


def test_constraint_fallback_keeps_parents():
    # A feasible set so thin that redraws nearly always fail: fallbacks must keep it feasible.
    def thin(pop):
        return np.abs(pop[:, 0] - pop[:, 1]) < 1e-3

    populations = []
    solver = GaassSolver(sphere, [(-1.0, 1.0)] * 2, feasible=thin, max_reject_tries=3,
                         maxiter=30, rng=0, callback=lambda r: populations.append(r.population))
    with pytest.raises(InfeasibleBoundsError):
        solver.step()
    res = minimize(sphere, [(-1.0, 1.0)] * 2, feasible=thin, max_reject_tries=2000, maxiter=30,
                   rng=0, callback=lambda r: populations.append(r.population))
    assert all(thin(p).all() for p in populations)
    assert res.extra['n_fallbacks'] > 0


def test_nan_costs_are_worst():
    def cost(pop):
        out = sphere(pop)
        out[pop[:, 0] < 0.0] = np.nan
        out[pop[:, 1] < -2.0] = np.inf
        return out

    res = minimize(cost, [(-5.0, 5.0)] * 2, maxiter=60, rng=0)
    assert np.isfinite(res.fun) and res.x[0] >= 0.0
    assert np.all(np.isfinite(res.history.best_fun))


def test_all_nan_costs_report_failure():
    res = minimize(lambda pop: np.full(pop.shape[0], np.nan), [(0.0, 1.0)], maxiter=3, rng=0)
    assert not res.success and 'no finite cost' in res.message and res.fun == np.inf


def test_scalar_function_and_x0():
    res = minimize(lambda x, a: float(np.sum((x - a) ** 2)), [(-3.0, 3.0)] * 2,
                   vectorized=False, args=(1.0,), x0=[1.0, 1.0], maxiter=3, rng=0)
    assert res.fun == 0.0 and np.array_equal(res.x, [1.0, 1.0])


def test_wrong_cost_shape_raises():
    with pytest.raises(ConfigError):
        minimize(lambda pop: np.zeros(3), [(0.0, 1.0)], maxiter=2)


def test_operators():
    rng = np.random.default_rng(0)
    assert ops.normalized_fitness_distance(np.array([1.0, 1.0, 4.0])) == pytest.approx(2 / 3)
    assert ops.normalized_fitness_distance(np.array([2.0, 2.0])) == 0.0
    assert np.isnan(ops.normalized_fitness_distance(np.array([np.inf])))
    fit = ops.selection_fitness(np.array([0.0, 1.0, 2.0, np.inf]))
    assert np.allclose(fit, [2.2, 1.2, 0.2, 0.0])
    assert np.allclose(ops.selection_fitness(np.array([3.0, 1.0, 2.0]), 'rank'), [1, 3, 2])
    chosen = ops.remainder_stochastic_sampling(np.array([3.0, 1.0, 0.0, 0.0]), 4, rng)
    assert sorted(chosen) == [0, 0, 0, 1]
    keep = ops.pairwise_tournament(np.arange(10.0)[::-1], 5, rng)
    assert 9 in keep and len(set(keep)) == 5
    a, b = rng.random((50, 4)), rng.random((50, 4))
    c1, c2 = ops.schema_arithmetic_crossover(a, b, rng)
    assert np.all(c1 >= np.minimum(a, b) - 1e-12) and np.all(c1 <= np.maximum(a, b) + 1e-12)
    assert np.allclose(c1 + c2, a + b)
    lo, hi = ops.mutation_window(np.array([0.0, 5.0]), np.array([-1.0, -1.0]),
                                 np.array([1.0, 1.0]), 0.1)
    assert np.allclose(lo, [-0.1, 0.9]) and np.allclose(hi, [0.1, 1.0])
    rows, cols = ops.mutation_positions(6, 2, 4, rng)
    assert len(set(zip(rows, cols, strict=True))) == 4
    assert [ops.round_half_up(v) for v in (5.4, 3.0, 0.12, 3.6, 2.5)] == [5, 3, 0, 4, 3]


def test_shubert_and_simple_ga():
    x_min = np.array([-7.0835, 4.8580])
    assert shubert_2d(x_min) == pytest.approx(bm.SHUBERT_2D_MIN, abs=1e-2)
    assert bm.SHUBERT_2D_MAX > bm.F1_OPTIMUM == -bm.SHUBERT_2D_MIN
    assert shubert_2d(np.zeros((3, 2))).shape == (3,)
    res = simple_ga(shubert_2d, bm.SHUBERT_2D_BOUNDS, maxiter=20, rng=0)
    assert isinstance(res, GaassResult) and len(res.history) == res.nit == 20
    assert res.nfev == 6 * 21 and np.all(np.diff(res.history.best_fun) <= 0.0)
