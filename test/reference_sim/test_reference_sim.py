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

"""The reference simulator against first principles (not against hyst_id)."""

from __future__ import annotations

import numpy as np
import pytest

from reference_sim import backlash, first_order_sensor, hysteresis, second_order_sensor

__all__: list[str] = []

PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0}
NARROW = {'m_l': 1.0, 'm_r': 1.0, 'm_t': 0.2, 'm_b': 0.2, 'c_l': -0.5, 'c_r': 0.5,
          'c_t': 8.0, 'c_b': 0.0}


def test_monotone_rise_follows_the_rising_boundary_and_its_lines():
    v = np.linspace(-20.0, 30.0, 5001)
    u = hysteresis(v, **NARROW)
    # bottom line while below the right line, right line, then capped by the top line
    boundary = np.minimum(np.maximum(0.2 * v + 0.0, 1.0 * (v - 0.5)), 0.2 * v + 8.0)
    assert np.allclose(u, boundary)
    # slopes on each piece: 0.2 at both ends, 1 in the middle
    du = np.diff(u) / np.diff(v)
    assert np.isclose(du[10], 0.2) and np.isclose(du[2500], 1.0) and np.isclose(du[-10], 0.2)


def test_a_reversal_moves_along_the_top_slope_until_the_left_line():
    v = np.concatenate([np.linspace(0.0, 5.0, 501), np.linspace(5.0, -5.0, 1001)[1:]])
    u = hysteresis(v, **NARROW)
    u_peak = u[500]
    assert np.isclose(u_peak, 4.5)                       # on the right line at v = 5
    fall = u[501:]
    v_fall = v[501:]
    inner = 0.2 * v_fall + (u_peak - 0.2 * 5.0)          # parallel to the top line
    left = 1.0 * (v_fall + 0.5)
    assert np.allclose(fall, np.maximum(np.minimum(inner, left), 0.2 * v_fall))
    # the left line is reached where inner == left: v = (3.5 - 0.5) / 0.8
    v_meet = (u_peak - 1.0 - 0.5) / 0.8
    k = np.argmin(np.abs(v_fall - v_meet))
    assert np.isclose(fall[k], left[k], atol=0.02)


def test_held_command_holds_the_output():
    v = np.array([9.0, 10.0, 10.0, 10.0, 9.5, 9.5])
    u = hysteresis(v, **PAPER)
    assert u[1] == u[2] == u[3] and u[4] == u[5]


def test_backlash_dead_band_on_a_reversal():
    u = np.concatenate([np.linspace(0.0, 5.0, 501), np.linspace(5.0, 0.0, 501)[1:]])
    y = backlash(u, 2.0, -0.3, 0.4)
    assert np.allclose(y[:501], 2.0 * (u[:501] - 0.4))   # rising edge from the start
    # after the peak the output holds until u has fallen by c_br - c_bl = 0.7
    held = np.isclose(y[501:], y[500])
    assert np.isclose(u[500] - u[501:][~held][0], 0.7, atol=0.011)
    assert np.allclose(y[-50:], 2.0 * (u[-50:] + 0.3))


@pytest.mark.parametrize('uniform', [True, False])
def test_first_order_step_response(uniform):
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 10.0, 201) if uniform else np.sort(rng.uniform(0.0, 10.0, 201))
    t[0] = 0.0
    s = first_order_sensor(t, np.ones(t.size), 1.5, x0=0.0)    # a unit step at t = 0
    assert np.allclose(s, 1.0 - np.exp(-t / 1.5))


@pytest.mark.parametrize('uniform', [True, False])
def test_second_order_step_response(uniform):
    rng = np.random.default_rng(1)
    t = np.linspace(0.0, 10.0, 301) if uniform else np.sort(rng.uniform(0.0, 10.0, 301))
    t[0] = 0.0
    zeta, wn = 0.4, 3.0
    s = second_order_sensor(t, np.ones(t.size), zeta, wn, x0=0.0)
    wd = wn * np.sqrt(1 - zeta ** 2)
    phi = np.arccos(zeta)
    exact = 1 - np.exp(-zeta * wn * t) * np.sin(wd * t + phi) / np.sqrt(1 - zeta ** 2)
    assert np.allclose(s, exact, atol=1e-9)
    assert np.isclose(second_order_sensor(t, np.full(t.size, 2.5), zeta, wn)[-1], 2.5)
