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

"""The smooth family (Prandtl-Ishlinskii behind a tanh map): kernel, inverse, gauge, identify.

The kernel is checked against a plain-Python play sum written from the
formula in the module docstring; recordings for identification are made with
that plain sum and ``reference_sim``'s backlash and sensor (written apart from
hyst_id), over random parameter sets.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference_sim import backlash, first_order_sensor

from hyst_id.compensation import Compensator, InverseModel
from hyst_id.errors import InvalidParametersError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.domains import domains_from_data
from hyst_id.io.recording import Recording
from hyst_id.models.registry import get_family
from hyst_id.models.smooth import N_PLAYS, SMOOTH_NAMES

__all__: list[str] = []

FAMILY = get_family('smooth')


def plain_play_sum(p, v):
    """The smooth family's H from its formula, one sample and one play at a time."""
    w = [float(x) for x in p[:N_PLAYS]]
    r_max, v_s, v_c, c_o = (float(x) for x in p[N_PLAYS:])
    r = [r_max * k / (N_PLAYS - 1) for k in range(N_PLAYS)]
    g = v_s * math.tanh((float(v[0]) - v_c) / v_s)
    z = [g - rk for rk in r]
    out = []
    for x in v:
        g = v_s * math.tanh((float(x) - v_c) / v_s)
        z = [max(g - rk, min(g + rk, zk)) for zk, rk in zip(z, r)]
        out.append(c_o + sum(wk * zk for wk, zk in zip(w, z)))
    return np.array(out)


def random_params(rng):
    """A valid set: some weights zero, wide and narrow thresholds, weak and strong saturation."""
    w = rng.uniform(0.0, 2.0, N_PLAYS) * (rng.uniform(size=N_PLAYS) < 0.7)
    w[0] = rng.uniform(0.05, 2.0)
    return np.concatenate([w, [rng.uniform(0.0, 3.0), math.exp(rng.uniform(-1.0, 3.0)),
                               rng.uniform(-1.0, 1.0), rng.uniform(-5.0, 5.0)]])


@pytest.mark.parametrize('seed', range(40))
def test_kernel_equals_the_plain_play_sum(seed):
    rng = np.random.default_rng([5, seed])
    p = random_params(rng)
    v = np.cumsum(rng.normal(0.0, 0.4, 400))
    ours = FAMILY.simulate(p, v)
    assert np.max(np.abs(ours - plain_play_sum(p, v))) <= 1e-12 * max(1.0, np.ptp(ours))


@pytest.mark.parametrize('seed', range(40))
def test_inverse_round_trip(seed):
    """H(H^-1(u)) = u to 1e-9 for reachable targets, over random sets.

    Targets come from a command path that starts where the inverse's state
    starts: plays wider than the saturated travel never move, so what is
    reachable depends on the start.
    """
    rng = np.random.default_rng([6, seed])
    p = random_params(rng)
    path = np.cumsum(rng.normal(0.0, 0.4, 300))
    targets = FAMILY.simulate(p, path)
    inv = FAMILY.inverse(p)
    inv.reset(float(path[0]))
    worst = 0.0
    for u in targets:
        inv.advance(inv.command_for(float(u)))
        worst = max(worst, abs(inv.output - u))
    assert worst <= 1e-9 * max(1.0, np.ptp(targets))


def test_inverse_beyond_saturation_goes_to_the_nearest_reachable():
    p = np.array([1.0, 0, 0, 0, 0, 0, 0.0, 1.0, 0.0, 0.0])       # u = tanh(v)
    inv = FAMILY.inverse(p)
    v = inv.command_for(5.0)
    assert math.isfinite(v) and v > 10.0
    assert inv.advance(v) == pytest.approx(1.0, abs=1e-9)
    assert math.isfinite(inv.command_for(float('nan')))


@pytest.mark.parametrize('seed', range(10))
def test_output_map_is_the_gauge(seed):
    rng = np.random.default_rng([7, seed])
    p = random_params(rng)
    v = np.cumsum(rng.normal(0.0, 0.4, 200))
    alpha, delta = math.exp(rng.uniform(-2, 2)), rng.uniform(-10, 10)
    np.testing.assert_allclose(FAMILY.simulate(FAMILY.map_output(p, alpha, delta), v),
                               alpha * FAMILY.simulate(p, v) + delta, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize('bad, rule', [
    ({'w_0': 0.0}, 'w_0'), ({'w_3': -0.1}, 'w_k'), ({'r_max': -1.0}, 'r_max'),
    ({'v_s': 0.0}, 'v_s'), ({'c_o': float('nan')}, 'finite')])
def test_invalid_sets_are_refused_by_name(bad, rule):
    p = dict(zip(SMOOTH_NAMES, [1.0, 0.5, 0.0, 0.2, 0.0, 0.1, 1.0, 2.0, 0.0, 0.0]))
    p.update(bad)
    with pytest.raises(InvalidParametersError, match=rule):
        FAMILY.check(np.array(list(p.values())))
    assert not FAMILY.feasible_rows(np.array([list(p.values())]))[0]
    with pytest.raises(InvalidParametersError):
        FAMILY.check(np.ones(3))


def test_compensator_runs_the_smooth_inverse_in_line():
    values = dict(zip(SMOOTH_NAMES, [0.8, 0.4, 0.0, 0.3, 0.2, 0.1, 0.6, 3.0, 0.2, 1.0]))
    model = InverseModel.from_mapping({'family': 'smooth', **values,
                                       'm_bl': 1.0, 'c_bl': -0.05, 'c_br': 0.05})
    comp = Compensator(model, v0=0.0)
    desired = 1.0 + 0.8 * np.sin(np.linspace(0.0, 12.0, 400))
    v = comp.run(desired)
    act = FAMILY.inverse(np.array(list(values.values())))
    act.reset(0.0)
    y, out = act.output - 0.05, []
    for vj in v:
        u = act.advance(vj)
        y = min(max(y, u - 0.05), u + 0.05)
        out.append(y)
    np.testing.assert_allclose(out[1:], desired[1:], atol=1e-9)


def _smooth_recording(seed: int):
    """A pressure recording of a random smooth loop, backlash and lag; its true noise floor."""
    rng = np.random.default_rng([8, seed])
    p = random_params(rng)
    p[N_PLAYS + 2] = 0.0
    t = np.arange(3000) * 0.02
    v = 2.0 * np.sin(2 * np.pi * t / 12.0) * (0.4 + 0.6 * np.exp(-t / 25.0))
    v += 0.3 * np.sin(2 * np.pi * t / 2.7)
    u = plain_play_sum(p, v)
    span = np.ptp(u)
    band = rng.uniform(0.0, 0.15) * span
    y0 = first_order_sensor(t, backlash(u, 1.0, -0.5 * band, 0.5 * band), 0.3)
    sigma = 0.005 * np.ptp(y0)
    y = 40.0 * y0 + 3.0 + 40.0 * rng.normal(0.0, sigma, t.size)
    floor = float(np.sqrt(t.size * (40.0 * sigma) ** 2 / (y @ y)) * 100.0)
    return Recording(t, v, y, 'pressure', 'V', 'kPa', f'smooth #{seed}'), floor


@pytest.mark.slow
@pytest.mark.parametrize('seed', range(3))
def test_identify_reaches_the_true_floor_on_smooth_loops(seed):
    rec, floor = _smooth_recording(seed)
    spec = domains_from_data(rec, family='smooth')
    ident = identify(rec, spec=spec, settings=IdentifySettings(workers=1))
    assert ident.family == 'smooth'
    assert ident.er_percent <= 1.1 * floor, (ident.er_percent / floor, ident.params)
