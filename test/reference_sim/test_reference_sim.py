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

"""The reference simulator against first principles (never against hyst_id)."""

from __future__ import annotations

import numpy as np
import pytest

from reference_sim import (
    backlash,
    first_order_sensor,
    hysteresis,
    loop_corners,
    paper_constraints_ok,
    second_order_sensor,
    simulate,
)

#: The paper's induced hysteresis (section 4); m_b > m_t.
PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0}
#: A loop with m_t > m_b.
SKEW = {'m_l': 1.0, 'm_r': 1.0, 'm_t': 0.3, 'm_b': 0.1, 'c_l': -1.0, 'c_r': 1.0,
        'c_t': 6.0, 'c_b': 0.0}
#: A loop with m_t == m_b (no capping by the top / bottom line inside the loop).
EVEN = {'m_l': 1.2, 'm_r': 0.9, 'm_t': 0.2, 'm_b': 0.2, 'c_l': -0.5, 'c_r': 0.5,
        'c_t': 6.0, 'c_b': 1.0}
#: Table 1's position backlash.
BACKLASH = {'m_bl': 1.09, 'c_bl': 0.48, 'c_br': 1.02}


def _lines(p):
    return {'top': lambda v: p['m_t'] * v + p['c_t'],
            'bottom': lambda v: p['m_b'] * v + p['c_b'],
            'left': lambda v: p['m_l'] * (v - p['c_l']),
            'right': lambda v: p['m_r'] * (v - p['c_r'])}


def _rising_boundary(p, v):
    ln = _lines(p)
    return np.minimum(np.maximum(ln['bottom'](v), ln['right'](v)), ln['top'](v))


def _falling_boundary(p, v):
    ln = _lines(p)
    return np.maximum(np.minimum(ln['top'](v), ln['left'](v)), ln['bottom'](v))


def _slopes(v, u):
    return np.diff(u) / np.diff(v)


def _random_walk(seed, n, lo, hi, step):
    rng = np.random.default_rng(seed)
    v = np.empty(n)
    v[0] = 0.5 * (lo + hi)
    for j in range(1, n):
        v[j] = np.clip(v[j - 1] + rng.normal(0.0, step), lo, hi)
    return v


# --- corners and constraints --------------------------------------------------------------


@pytest.mark.parametrize('p', [PAPER, SKEW, EVEN])
def test_loop_corners_are_the_line_intersections(p):
    ln = _lines(p)
    c = loop_corners(p)
    assert np.isclose(ln['right'](c['v1']), ln['top'](c['v1']))
    assert np.isclose(ln['left'](c['v2']), ln['bottom'](c['v2']))
    assert np.isclose(ln['right'](c['v3']), ln['bottom'](c['v3']))
    assert np.isclose(ln['left'](c['v4']), ln['top'](c['v4']))
    assert c['v2'] < c['v3'] < c['v1'] and c['v2'] < c['v4'] < c['v1']


def test_paper_constraints():
    good = {**PAPER, **BACKLASH}
    assert paper_constraints_ok(good) and paper_constraints_ok(good, proper_loop=True)
    assert paper_constraints_ok(PAPER)                    # H alone
    assert paper_constraints_ok({**SKEW, **BACKLASH}, proper_loop=True)
    for key, value in [('m_l', 0.0), ('m_r', -1.0), ('m_t', 0.0), ('m_t', 1.02),
                       ('m_b', 0.0), ('m_b', 1.05), ('c_l', 0.6), ('c_t', 6.0),
                       ('m_bl', 0.0), ('c_bl', 1.02), ('c_bl', 2.0)]:
        assert not paper_constraints_ok({**good, key: value}), key
    # the paper's inequalities hold but the bottom line reaches the top before the right
    # line does: no proper loop
    flat = {**PAPER, 'm_t': 0.1, 'm_b': 0.9}
    assert paper_constraints_ok(flat) and not paper_constraints_ok(flat, proper_loop=True)
    with pytest.raises(KeyError):
        paper_constraints_ok({**PAPER, 'm_bl': 1.0})


# --- hysteresis ---------------------------------------------------------------------------


@pytest.mark.parametrize('p', [PAPER, SKEW])
def test_monotone_rise_is_the_rising_boundary_with_its_slopes(p):
    c = loop_corners(p)
    v = np.linspace(c['v2'] - 5.0, c['v1'] + 5.0, 4001)
    u = hysteresis(v, **p)
    assert np.allclose(u, _rising_boundary(p, v), rtol=0, atol=1e-12)
    s, a, b = _slopes(v, u), v[:-1], v[1:]
    assert np.allclose(s[b < c['v3']], p['m_b'])
    assert np.allclose(s[(a > c['v3']) & (b < c['v1'])], p['m_r'])
    assert np.allclose(s[a > c['v1']], p['m_t'])


@pytest.mark.parametrize('p', [PAPER, SKEW])
def test_monotone_fall_from_falling_start_is_the_falling_boundary(p):
    c = loop_corners(p)
    v = np.linspace(c['v1'] + 5.0, c['v2'] - 5.0, 4001)
    u = hysteresis(v, **p, initial='falling')
    assert np.allclose(u, _falling_boundary(p, v), rtol=0, atol=1e-12)
    s, a, b = _slopes(v, u), v[:-1], v[1:]            # a > b: falling
    assert np.allclose(s[b > c['v4']], p['m_t'])
    assert np.allclose(s[(a < c['v4']) & (b > c['v2'])], p['m_l'])
    assert np.allclose(s[a < c['v2']], p['m_b'])


@pytest.mark.parametrize('p', [PAPER, SKEW, EVEN])
def test_slow_triangle_traces_the_major_loop_and_closes(p):
    c = loop_corners(p)
    lo, hi = c['v2'] - 3.0, c['v1'] + 3.0
    leg = np.linspace(lo, hi, 3001)
    v = np.concatenate([leg, leg[::-1][1:], leg[1:], leg[::-1][1:]])
    u = hysteresis(v, **p)
    n = leg.size
    up1, down1 = u[:n], u[n - 1:2 * n - 1]
    up2, down2 = u[2 * n - 2:3 * n - 2], u[3 * n - 3:]
    assert np.allclose(up1, _rising_boundary(p, leg), atol=1e-12)
    assert np.allclose(down1, _falling_boundary(p, leg[::-1]), atol=1e-12)
    assert np.allclose(up2, up1, atol=1e-12) and np.allclose(down2, down1, atol=1e-12)
    # the loop has width: inside (v2, v1) the falling branch lies above the rising one
    inside = (leg > c['v2'] + 0.1) & (leg < c['v1'] - 0.1)
    assert np.all(down1[::-1][inside] > up1[inside])
    # every step of the loop lies on one of the four lines (or crosses a corner)
    s = _slopes(v, u)
    slopes = np.array([p['m_l'], p['m_r'], p['m_t'], p['m_b']])
    on_line = np.min(np.abs(s[:, None] - slopes[None, :]), axis=1) < 1e-6
    assert np.count_nonzero(~on_line) <= 4 * 4          # at most the corner steps


def test_reversal_on_the_right_line_moves_parallel_to_the_top_until_the_left_line():
    p = PAPER
    c = loop_corners(p)
    v_peak = 12.0                                       # on the right line: v3 < 12 < v1
    assert c['v3'] < v_peak < c['v1']
    v = np.concatenate([np.linspace(6.0, v_peak, 601), np.linspace(v_peak, 5.0, 2801)[1:]])
    u = hysteresis(v, **p)
    k = 600
    u_p = u[k]
    assert np.isclose(u_p, p['m_r'] * (v_peak - p['c_r']))
    c_d = u_p - p['m_t'] * v_peak                       # Eq. 3
    v_d = (p['m_l'] * p['c_l'] + c_d) / (p['m_l'] - p['m_t'])
    assert c['v2'] < v_d < v_peak
    vf, uf = v[k:], u[k:]
    inner, left, bottom = vf > v_d, (vf <= v_d) & (vf >= c['v2']), vf < c['v2']
    assert np.allclose(uf[inner], p['m_t'] * vf[inner] + c_d)
    assert np.allclose(uf[left], p['m_l'] * (vf[left] - p['c_l']))
    assert np.allclose(uf[bottom], p['m_b'] * vf[bottom] + p['c_b'])
    # the reversal is a genuine hysteresis: the falling inner line is above the rising path
    assert np.all(uf[inner][1:] > _rising_boundary(p, vf[inner][1:]))


def test_reversal_on_the_left_line_moves_parallel_to_the_bottom_until_the_right_line():
    p = PAPER
    c = loop_corners(p)
    v_trough = 11.0                                     # on the left line: v2 < 11 < v4
    v = np.concatenate([np.linspace(18.0, v_trough, 701),
                        np.linspace(v_trough, 19.0, 3201)[1:]])
    u = hysteresis(v, **p, initial='falling')
    k = 700
    u_t = u[k]
    assert np.isclose(u_t, p['m_l'] * (v_trough - p['c_l']))
    c_u = u_t - p['m_b'] * v_trough                     # Eq. 3
    v_u = (p['m_r'] * p['c_r'] + c_u) / (p['m_r'] - p['m_b'])
    assert v_trough < v_u < c['v1']
    vr, ur = v[k:], u[k:]
    inner, right, top = vr < v_u, (vr >= v_u) & (vr <= c['v1']), vr > c['v1']
    assert np.allclose(ur[inner], p['m_b'] * vr[inner] + c_u)
    assert np.allclose(ur[right], p['m_r'] * (vr[right] - p['c_r']))
    assert np.allclose(ur[top], p['m_t'] * vr[top] + p['c_t'])


def test_rising_from_the_top_line_stays_on_it_only_if_m_t_below_m_b():
    # paper (m_t < m_b): Eq. 1's second case keeps u on the top line
    v = np.array([15.2, 15.22, 15.25, 15.28])           # v4 < v < v1
    u = hysteresis(v, **PAPER, initial='falling')
    assert np.allclose(u, PAPER['m_t'] * v + PAPER['c_t'])
    # m_t > m_b: u leaves the top line, parallel to the bottom line
    v = np.array([8.5, 9.0, 9.5])                       # SKEW: v4 = 7.14 < v < v1 = 10
    u = hysteresis(v, **SKEW, initial='falling')
    assert np.isclose(u[0], SKEW['m_t'] * 8.5 + SKEW['c_t'])
    assert np.allclose(u, u[0] + SKEW['m_b'] * (v - 8.5))
    assert np.all(u[1:] < SKEW['m_t'] * v[1:] + SKEW['c_t'])


def test_falling_from_the_bottom_line_stays_on_it_only_if_m_t_above_m_b():
    # m_t > m_b: Eq. 1's fourth case keeps u on the bottom line
    v = np.array([0.0, -0.5, -1.0])                     # SKEW: v2 = -1.11 < v < v3 = 1.11
    u = hysteresis(v, **SKEW)
    assert np.allclose(u, SKEW['m_b'] * v + SKEW['c_b'])
    # paper (m_t < m_b): u leaves the bottom line, parallel to the top line
    v = np.array([8.2, 8.1, 8.0])                       # v2 = 7.85 < v < v3 = 8.36
    u = hysteresis(v, **PAPER)
    assert np.isclose(u[0], PAPER['m_b'] * 8.2 + PAPER['c_b'])
    assert np.allclose(u, u[0] + PAPER['m_t'] * (v - 8.2))
    assert np.all(u[1:] > PAPER['m_b'] * v[1:] + PAPER['c_b'])


def _eq1_literal(v, p):
    """Eq. 1-3 case by case (typos corrected as in the notes), valid for m_t == m_b."""
    m_l, m_r, m_t, m_b = p['m_l'], p['m_r'], p['m_t'], p['m_b']
    c_l, c_r, c_t, c_b = p['c_l'], p['c_r'], p['c_t'], p['c_b']
    v1 = (c_t + m_r * c_r) / (m_r - m_t)
    v2 = (c_b + m_l * c_l) / (m_l - m_b)
    u = [float(_rising_boundary(p, v[0]))]
    for j in range(1, v.size):
        x, xp, up = v[j], v[j - 1], u[-1]
        c_u, c_d = up - m_b * xp, up - m_t * xp
        v_u = (m_r * c_r + c_u) / (m_r - m_b)
        v_d = (m_l * c_l + c_d) / (m_l - m_t)
        if x == xp:
            u.append(up)
        elif x >= v1:
            u.append(m_t * x + c_t)
        elif x <= v2:
            u.append(m_b * x + c_b)
        elif xp < x < v_u:
            u.append(m_b * x + c_u)
        elif v_d < x < xp:
            u.append(m_t * x + c_d)
        elif x < xp:                                    # v2 <= x <= v_d
            u.append(m_l * (x - c_l))
        else:                                           # v_u <= x <= v1
            u.append(m_r * (x - c_r))
    return np.array(u)


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_the_min_max_rule_equals_eq1_case_by_case(seed):
    c = loop_corners(EVEN)
    v = _random_walk(seed, 3000, c['v2'] - 2.0, c['v1'] + 2.0, 0.4)
    v[100:110] = v[100]                                 # a held command too
    assert np.allclose(hysteresis(v, **EVEN), _eq1_literal(v, EVEN), atol=1e-10)


@pytest.mark.parametrize('p', [PAPER, SKEW, EVEN])
def test_random_command_stays_inside_the_major_loop(p):
    c = loop_corners(p)
    v = _random_walk(3, 3000, c['v2'] - 1.0, c['v1'] + 1.0, 0.3)
    for initial in ('rising', 'falling'):
        u = hysteresis(v, **p, initial=initial)
        assert np.all(u >= _rising_boundary(p, v) - 1e-9)
        assert np.all(u <= _falling_boundary(p, v) + 1e-9)


@pytest.mark.parametrize('p', [PAPER, SKEW])
def test_hysteresis_and_backlash_are_rate_independent(p):
    c = loop_corners(p)
    v = _random_walk(4, 400, c['v2'] - 1.0, c['v1'] + 1.0, 0.5)
    fine = np.interp(np.arange(0, v.size - 1 + 1e-9, 0.1), np.arange(v.size), v)
    u, u_fine = hysteresis(v, **p), hysteresis(fine, **p)
    assert np.allclose(u_fine[::10], u, atol=1e-9)
    assert np.allclose(backlash(u_fine, **BACKLASH)[::10], backlash(u, **BACKLASH), atol=1e-9)


def test_held_command_holds_the_output():
    v = np.array([9.0, 10.0, 10.0, 10.0, 9.5, 9.5, 9.5])
    u = hysteresis(v, **PAPER)
    assert u[1] == u[2] == u[3] and u[4] == u[5] == u[6]


def test_initial_state_is_on_the_named_boundary():
    for v0 in (5.0, 10.0, 14.0, 20.0):
        assert hysteresis([v0], **PAPER)[0] == pytest.approx(_rising_boundary(PAPER, v0))
        assert hysteresis([v0], **PAPER, initial='falling')[0] == pytest.approx(
            _falling_boundary(PAPER, v0))
    with pytest.raises(ValueError):
        hysteresis([1.0], **PAPER, initial='middle')


# --- backlash -----------------------------------------------------------------------------


def test_backlash_dead_band_equals_the_crossing_gap_on_a_reversal():
    m, c_bl, c_br = 2.0, -0.3, 0.4
    up = np.linspace(0.0, 5.0, 5001)                     # step 1e-3
    u = np.concatenate([up, up[::-1][1:], up[1:]])
    y = backlash(u, m, c_bl, c_br)
    n = up.size
    assert np.allclose(y[:n], m * (up - c_br))          # rising edge from the start
    expected_down = np.minimum(m * (5.0 - c_br), m * (up[::-1] - c_bl))
    assert np.allclose(y[n - 1:2 * n - 1], expected_down)
    # width (in input) of the flat part after the peak and after the trough
    down = y[n - 1:2 * n - 1]
    held = np.count_nonzero(np.isclose(down, down[0], rtol=0, atol=1e-12)) - 1
    assert held * 1e-3 == pytest.approx(c_br - c_bl, abs=1.5e-3)
    rise = y[2 * n - 2:]
    held = np.count_nonzero(np.isclose(rise, rise[0], rtol=0, atol=1e-12)) - 1
    assert held * 1e-3 == pytest.approx(c_br - c_bl, abs=1.5e-3)
    assert np.allclose(rise[-100:], m * (up[-100:] - c_br))
    # the edges have slope m
    assert np.allclose(_slopes(up[:-1], y[:n - 1]), m)


def _eq10_literal(u, m, c_l, c_r):
    y = [m * (u[0] - c_r)]
    for j in range(1, u.size):
        v_l, v_r = y[-1] / m + c_l, y[-1] / m + c_r
        if u[j] <= v_l:
            y.append(m * (u[j] - c_l))
        elif u[j] >= v_r:
            y.append(m * (u[j] - c_r))
        else:
            y.append(y[-1])
    return np.array(y)


@pytest.mark.parametrize('seed', [5, 6])
def test_backlash_equals_eq10_case_by_case(seed):
    u = _random_walk(seed, 3000, -5.0, 5.0, 0.3)
    assert np.allclose(backlash(u, 1.3, -0.4, 0.7), _eq10_literal(u, 1.3, -0.4, 0.7))


def test_backlash_initial_edges():
    assert backlash([1.0], 2.0, -0.5, 0.5)[0] == pytest.approx(1.0)
    assert backlash([1.0], 2.0, -0.5, 0.5, initial='falling')[0] == pytest.approx(3.0)
    y = backlash([1.0, 1.2, 1.4], 2.0, -0.5, 0.5, initial='falling')
    assert np.allclose(y, 3.0)                            # inside the dead band


# --- sensors ------------------------------------------------------------------------------


def _times(uniform, n, t_end, seed):
    if uniform:
        return np.linspace(0.0, t_end, n)
    t = np.sort(np.random.default_rng(seed).uniform(0.0, t_end, n))
    t[0] = 0.0
    return t


@pytest.mark.parametrize('uniform', [True, False])
def test_first_order_step_response(uniform):
    t = _times(uniform, 301, 10.0, 0) + 3.0              # need not start at 0
    s = first_order_sensor(t, np.ones(t.size), 1.5, x0=0.0)
    assert np.allclose(s, 1.0 - np.exp(-(t - 3.0) / 1.5), rtol=0, atol=1e-13)


@pytest.mark.parametrize('uniform', [True, False])
def test_first_order_matches_superposed_step_responses(uniform):
    tau = 0.7
    t = _times(uniform, 200, 8.0, 1)
    x = np.random.default_rng(2).normal(0.0, 1.0, t.size)
    s = first_order_sensor(t, x, tau)
    # x(k) is applied from t(k) on: s = x(0) + sum_k (x(k) - x(k-1)) step(t - t(k))
    exact = np.full(t.size, x[0])
    for k in range(1, t.size):
        after = t > t[k]
        exact[after] += (x[k] - x[k - 1]) * (1.0 - np.exp(-(t[after] - t[k]) / tau))
    assert np.allclose(s, exact, rtol=0, atol=1e-12)


def test_first_order_dc_gain_steady_start_and_odd_times():
    t = np.array([0.0, 0.5, 0.5, 1.0, 4.0, 40.0])
    assert np.allclose(first_order_sensor(t, np.full(t.size, 2.5), 0.8), 2.5)
    s = first_order_sensor(t, np.array([0.0, 1.0, 5.0, 1.0, 1.0, 1.0]), 0.8)
    assert s[0] == 0.0 and s[2] == s[1]                  # repeated time: no change
    assert s[-1] == pytest.approx(1.0)                   # DC gain 1
    # tau_s = 0 is the limit: the held input is reached at once, s(j) = x(j-1)
    assert np.allclose(first_order_sensor(t, np.arange(6.0), 0.0), [0, 0, 0, 2, 3, 4])
    with pytest.raises(ValueError):
        first_order_sensor(np.array([0.0, 1.0, 0.5]), np.zeros(3), 1.0)


def _second_order_step(t, zeta, wn):
    if zeta < 1.0:
        wd = wn * np.sqrt(1.0 - zeta ** 2)
        return 1.0 - np.exp(-zeta * wn * t) * (np.cos(wd * t)
                                               + zeta / np.sqrt(1.0 - zeta ** 2)
                                               * np.sin(wd * t))
    if zeta == 1.0:
        return 1.0 - (1.0 + wn * t) * np.exp(-wn * t)
    r = np.sqrt(zeta ** 2 - 1.0)
    p1, p2 = -wn * (zeta - r), -wn * (zeta + r)
    return 1.0 + (p2 * np.exp(p1 * t) - p1 * np.exp(p2 * t)) / (p1 - p2)


@pytest.mark.parametrize('uniform', [True, False])
@pytest.mark.parametrize('zeta, wn', [(0.4, 3.0), (0.51, 0.22), (0.0, 2.0), (1.0, 1.5),
                                      (2.0, 1.0)])
def test_second_order_step_response(uniform, zeta, wn):
    t = _times(uniform, 301, 30.0, 3)
    s = second_order_sensor(t, np.ones(t.size), zeta, wn, x0=0.0)
    assert np.allclose(s, _second_order_step(t, zeta, wn), rtol=0, atol=1e-10)
    if zeta == 0.4:                                     # textbook form of the same
        phi = np.arccos(zeta)
        wd = wn * np.sqrt(1 - zeta ** 2)
        textbook = 1 - np.exp(-zeta * wn * t) * np.sin(wd * t + phi) / np.sqrt(1 - zeta ** 2)
        assert np.allclose(s, textbook, atol=1e-10)


def test_second_order_matches_superposed_step_responses():
    zeta, wn = 0.3, 2.0
    t = _times(False, 200, 10.0, 4)
    x = np.random.default_rng(5).normal(0.0, 1.0, t.size)
    s = second_order_sensor(t, x, zeta, wn)
    exact = np.full(t.size, x[0])
    for k in range(1, t.size):
        after = t > t[k]
        exact[after] += (x[k] - x[k - 1]) * _second_order_step(t[after] - t[k], zeta, wn)
    assert np.allclose(s, exact, rtol=0, atol=1e-10)


def test_second_order_dc_gain_and_steady_start():
    t = np.linspace(0.0, 60.0, 601)
    assert np.allclose(second_order_sensor(t, np.full(t.size, -3.2), 0.5, 1.0), -3.2)
    x = np.where(t < 1.0, 0.0, 2.5)
    s = second_order_sensor(t, x, 0.5, 1.0)
    assert s[0] == 0.0 and s[-1] == pytest.approx(2.5, abs=1e-9)
    # underdamped overshoot exp(-pi zeta / sqrt(1 - zeta^2))
    fine = np.linspace(0.0, 20.0, 20001)
    peak = second_order_sensor(fine, np.ones(fine.size), 0.5, 1.0, x0=0.0).max()
    assert peak - 1.0 == pytest.approx(np.exp(-np.pi * 0.5 / np.sqrt(0.75)), abs=1e-6)


# --- the chain ----------------------------------------------------------------------------


def test_simulate_composes_the_chain():
    t = np.arange(0.0, 60.0, 0.1)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)     # Eq. 24
    p = {**PAPER, **BACKLASH, 'tau_s': 1.79, 'zeta': 0.51, 'omega_n': 0.22}
    for initial in ('rising', 'falling'):
        pos = backlash(hysteresis(v, **PAPER, initial=initial), **BACKLASH, initial=initial)
        assert np.allclose(simulate('position', p, t, v, initial=initial), pos)
        assert np.allclose(simulate('pressure', p, t, v, 50.0, 1000.0, initial=initial),
                           50.0 * first_order_sensor(t, pos, 1.79) + 1000.0)
        assert np.allclose(simulate('flow', p, t, v, gain=4.0, offset=2.0, initial=initial),
                           4.0 * second_order_sensor(t, pos, 0.51, 0.22) + 2.0)
    aliases = {**PAPER, **BACKLASH, 'tau': 1.79, 'wn': 0.22, 'zeta': 0.51}
    assert np.allclose(simulate('pressure', aliases, t, v), simulate('pressure', p, t, v))
    assert np.allclose(simulate('flow', aliases, t, v), simulate('flow', p, t, v))
    with pytest.raises(ValueError):
        simulate('temperature', p, t, v)
    with pytest.raises(ValueError):
        simulate('position', p, t[:-1], v)


def test_simulate_with_the_paper_hysteresis_shows_a_loop():
    t = np.arange(0.0, 100.0, 0.05)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    p = {**PAPER, 'm_bl': 1.0, 'c_bl': -0.15, 'c_br': 0.15}
    y = simulate('position', p, t, v)
    # at the same command the output differs between rising and falling passes
    k_up = np.argmin(np.abs(t - 50.0))                   # sin rising through 0, v ~ 9
    k_down = np.argmin(np.abs(t - 55.0))                 # sin falling through 0, v ~ 9
    assert v[k_up] == pytest.approx(v[k_down], abs=1e-9)
    # rising boundary 8.93, falling 9.34 at v = 9, plus the 0.3 backlash band
    assert y[k_down] - y[k_up] > 0.5
