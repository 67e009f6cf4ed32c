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

"""Hysteresis, backlash and sensor models: round trips, exactness, kernel agreement."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from hyst_id.errors import InvalidParametersError
from hyst_id.identification.chains import chain_spec, er_percent
from hyst_id.identification.gauge import canonical_gauge
from hyst_id.models.backlash import invert_backlash, simulate_backlash
from hyst_id.models.sensors import simulate_first_order, simulate_second_order
from hyst_id.models.tk import (
    check_hysteresis,
    hysteresis_feasible,
    invert_hysteresis,
    simulate_hysteresis,
)

PAPER_H = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0])


def random_hysteresis(rng: np.random.Generator) -> np.ndarray:
    """Draw a feasible (proper-loop) hysteresis parameter set."""
    while True:
        m_l, m_r = rng.uniform(0.5, 3.0, 2)
        m_t, m_b = rng.uniform(0.01, 0.95 * min(m_l, m_r), 2)
        c_l = rng.uniform(-3.0, 1.0)
        c_r = c_l + rng.uniform(0.1, 3.0)
        c_b = rng.uniform(0.0, 10.0)
        c_t = c_b + rng.uniform(0.5, 10.0)
        p = np.array([m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b])
        if hysteresis_feasible(*p):
            return check_hysteresis(p)


def test_paper_loop_follows_the_right_line_when_rising():
    v = np.linspace(8.5, 11.0, 50)       # between corners B (8.36) and C (15.3)
    u = simulate_hysteresis(PAPER_H, v)
    np.testing.assert_allclose(u, 1.05 * (v - 0.5), rtol=1e-12)
    v_low = np.linspace(7.0, 8.3, 20)    # left of B the bottom line caps the loop
    np.testing.assert_allclose(simulate_hysteresis(PAPER_H, v_low), 0.15 * v_low + 7.0)


def test_loop_is_closed_and_wider_than_zero():
    t = np.arange(0, 30.005, 0.01)
    v = 9 + 2 * np.sin(2 * np.pi * t / 10)
    u = simulate_hysteresis(PAPER_H, v)
    rising, falling = u[1000], u[1500]      # both at v = 9, second period
    assert rising == pytest.approx(1.05 * (9 - 0.5))     # right line
    assert falling == pytest.approx(1.01 * (9 + 0.25))   # left line
    np.testing.assert_allclose(u[1000:2000], u[2000:3000], atol=1e-9)


@pytest.mark.parametrize('seed', range(20))
def test_hysteresis_inverse_round_trip(seed):
    rng = np.random.default_rng(seed)
    p = random_hysteresis(rng)
    v0 = rng.uniform(-2, 2)
    u0 = simulate_hysteresis(p, [v0])[0]
    desired = u0 + np.cumsum(rng.normal(0, 0.3, 400))
    desired[50:60] = desired[49]  # holds
    v = invert_hysteresis(p, desired, v0=v0)
    u = simulate_hysteresis(p, np.concatenate([[v0], v]), u0=u0)[1:]
    np.testing.assert_allclose(u, desired, atol=1e-9)


@pytest.mark.parametrize('seed', range(10))
def test_backlash_inverse_round_trip(seed):
    rng = np.random.default_rng(seed)
    p = np.array([rng.uniform(0.3, 3.0), -rng.uniform(0, 1), rng.uniform(0, 1)])
    u0 = 1.0
    desired = p[0] * (u0 - p[2]) + np.cumsum(rng.normal(0, 0.2, 300))
    u = invert_backlash(p, desired, u0=u0)
    y = simulate_backlash(p, np.concatenate([[u0], u]))[1:]
    np.testing.assert_allclose(y, desired, atol=1e-9)


def test_backlash_holds_inside_the_dead_band():
    p = [1.0, -0.5, 0.5]
    u = np.array([0.0, -0.2, -0.6, -0.9, -1.2, -0.8, 0.3, 0.8])
    y = simulate_backlash(p, u)
    # starts on the rising edge (y = u - c_br), holds while reversing through
    # the dead band of width c_br - c_bl, then follows the falling edge
    np.testing.assert_allclose(y, [-0.5, -0.5, -0.5, -0.5, -0.7, -0.7, -0.2, 0.3])


@pytest.mark.parametrize('bad, rule', [
    ([1.0, 1.0, 1.2, 0.1, 0, 1, 10, 5], 'm_t'),
    ([1.0, 1.0, 0.1, 0.1, 1, 0, 10, 5], 'left line must stay left'),
    # top line below the bottom line over the loop: the corners say so (not c_t > c_b)
    ([1.0, 1.0, 0.1, 0.1, 0, 1, 5, 10], 'not proper'),
    ([-1.0, 1.0, 0.1, 0.1, 0, 1, 10, 5], 'm_l'),
    ([0.714, 1.092, 0.546, 0.399, -2.623, -1.267, 6.808, 4.79], 'not proper'),
])
def test_infeasible_hysteresis_is_rejected_with_the_rule(bad, rule):
    with pytest.raises(InvalidParametersError, match=rule.split()[-1]):
        check_hysteresis(bad)


def test_canonical_sets_may_have_c_l_above_c_r_when_the_loop_is_proper():
    """c_l < c_r is not gauge invariant; a shifted output can swap the zero crossings."""
    from hyst_id.identification.gauge import affine_map_output
    raw = np.concatenate([PAPER_H, [1.0, -0.15, 0.15]])
    shifted = affine_map_output(raw, 1.0, -400.0)
    assert shifted[4] > shifted[5]
    check_hysteresis(shifted[:8])


def test_a_loop_stays_valid_in_any_command_frame():
    """The paper's loop commanded as u = 0.5 v - 100: same output, c_t < c_b at u = 0.

    ``c_t > c_b`` compares the lines at command 0, which moves with the
    command's offset; validation and the search over data-derived domains do
    not require it, the paper's own domains keep it (its frame).
    """
    a, b = 0.5, -100.0
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = PAPER_H
    moved = np.array([m_l / a, m_r / a, m_t / a, m_b / a, b + a * c_l, b + a * c_r,
                      c_t - m_t * b / a, c_b - m_b * b / a])
    assert moved[6] < moved[7]
    check_hysteresis(moved)
    t = np.arange(0.0, 200.0, 0.1)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10)
    np.testing.assert_allclose(simulate_hysteresis(moved, a * v + b),
                               simulate_hysteresis(PAPER_H, v), rtol=1e-9, atol=1e-9)
    x = np.concatenate([moved, [1.0, -0.15, 0.15]])[None, :]
    domains = {'c_l': (-200.0, 0.0), 'c_r': (-200.0, 0.0), 'c_t': (-50.0, 50.0),
               'c_b': (-50.0, 50.0)}
    assert chain_spec('position', domains=domains).feasible(x)[0]
    assert not chain_spec('position').feasible(x)[0]       # the paper's domains: its frame


def nonuniform_times(n=400, seed=0):
    steps = np.random.default_rng(seed).uniform(0.01, 0.1, n - 1)
    return np.concatenate([[0.0], np.cumsum(steps)])


@pytest.mark.parametrize('zeta', [0.2, 0.7, 1.0, 1.8])
def test_second_order_is_exact_on_nonuniform_samples(zeta):
    t = nonuniform_times()
    u = np.ones_like(t)
    u[0] = 0.0
    x = simulate_second_order(u, t, zeta, 2.5)
    fine = np.linspace(0, t[-1], 200001)
    _, y_ref = signal.step(([6.25], [1, 2 * zeta * 2.5, 6.25]), T=fine)
    np.testing.assert_allclose(x, np.interp(t, fine, y_ref), atol=1e-6)


def test_first_order_is_exact_and_zero_tau_passes_through():
    t = nonuniform_times()
    u = np.ones_like(t)
    u[0] = 0.0
    np.testing.assert_allclose(simulate_first_order(u, t, 0.7), 1 - np.exp(-t / 0.7),
                               atol=1e-12)
    np.testing.assert_array_equal(simulate_first_order(u, t, 0.0), u)


TRUE = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15, 0.5, 0.6])


@pytest.mark.parametrize('channel', ['position', 'pressure', 'flow'])
def test_population_kernel_matches_single_simulation(channel):
    spec = chain_spec(channel)
    t = nonuniform_times(600, seed=3)
    v = 9 + 2 * np.sin(2 * np.pi * t / 10)
    p = TRUE[:spec.n_params]
    y = 3.0 * spec.simulate(p, t, v) + 100.0
    rng = np.random.default_rng(0)
    pop = np.vstack([p, p * rng.uniform(0.9, 1.1, (20, p.size))])
    costs = spec.cost_function(t, v, y)(pop)
    assert costs[0] < 1e-12 * np.sum(y ** 2)
    for row, cost in zip(pop, costs):
        if not spec.feasible(row[None])[0]:
            assert np.isinf(cost)
            continue
        k, b = spec.fit_calibration(row, t, v, y)
        sse = np.sum((y - spec.simulate(row, t, v, (k, b))) ** 2)
        assert cost == pytest.approx(sse, rel=1e-8, abs=1e-9)


def test_kernel_marks_infeasible_and_nonfinite_rows_inf():
    t = np.arange(100) * 0.1
    v = np.sin(t)
    pop = np.array([TRUE[:11], TRUE[:11]])
    pop[1, 2] = np.nan
    costs = chain_spec('position').cost_function(t, v, v)(pop)
    assert np.isfinite(costs[0]) and np.isinf(costs[1])
    assert er_percent(0.0, v) == 0.0


@pytest.mark.parametrize('channel', ['position', 'pressure', 'flow'])
def test_canonical_gauge_leaves_the_output_unchanged(channel):
    spec = chain_spec(channel)
    raw = TRUE[:spec.n_params].copy()
    raw[8:11] = [1.7, 0.4, 1.3]
    t = np.arange(0, 50, 0.05)
    v = 9 + 2 * np.sin(2 * np.pi * t / 10)
    y = spec.simulate(raw, t, v, (2.5, -40.0))
    canon = canonical_gauge(raw, (2.5, -40.0))
    assert canon[8] == 1.0 and canon[9] == pytest.approx(-canon[10])
    np.testing.assert_allclose(spec.simulate(canon, t, v, (1.0, 0.0)), y, atol=1e-9)


def test_a_corner_far_beyond_the_commands_is_not_a_level_to_drive_to():
    """A dropout record's fit put the top-right corner at 744942 for commands within +-1.

    The warning had said 'drive the command above 744942.6327'; a corner more than
    ten command spans and ten times the largest command away says the recording does
    not place it. A corner within reach keeps the advice.
    """
    from hyst_id.models.registry import FAMILIES
    from hyst_id.models.tk import loop_corners
    from hyst_id.models.tk_lines import unexcited_lines

    p = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0])
    t = np.arange(0.0, 60.0, 0.05)
    v = 9.0 + 0.9 * np.sin(2 * np.pi * t / 10.0)
    u = FAMILIES['tk'].simulate(p, v)
    corners = loop_corners(p)
    near = unexcited_lines(p, v, u, corners)[0]
    assert any('drive the command above 15.289' in w for w in near), near
    far = dict(corners, C=(744942.6327, corners['C'][1]))
    words = [w for w in unexcited_lines(p, v, u, far)[0] if w.startswith('the top line')]
    assert len(words) == 1 and 'no level to drive to' in words[0], words
    assert 'drive the command' not in words[0]
