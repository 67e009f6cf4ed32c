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
from smooth_reference import plain_play_sum, random_params, smooth_recording

from hyst_id.compensation import Compensator, InverseModel
from hyst_id.errors import InvalidParametersError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.domains import domains_from_data
from hyst_id.models.registry import get_family
from hyst_id.models.smooth import N_PLAYS, SMOOTH_NAMES

__all__: list[str] = []

FAMILY = get_family('smooth')


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


@pytest.mark.parametrize('seed', range(20))
def test_inverse_reaches_any_target_with_a_slope_past_saturation(seed):
    """With ``w_l > 0`` every output is reachable: random targets far past the knee."""
    rng = np.random.default_rng([9, seed])
    p = random_params(rng)
    p[SMOOTH_NAMES.index('w_l')] = math.exp(rng.uniform(-4.0, 0.0))
    inv = FAMILY.inverse(p)
    inv.reset(0.0)
    span = 10.0 * float(p[:N_PLAYS + 1].sum() * p[SMOOTH_NAMES.index('v_s')] + 1.0)
    worst = 0.0
    for u in np.cumsum(rng.normal(0.0, 0.05 * span, 300)):
        inv.advance(inv.command_for(float(u)))
        worst = max(worst, abs(inv.output - u) / max(1.0, abs(u)))
    assert worst <= 1e-9


def test_inverse_beyond_saturation_goes_to_the_nearest_reachable():
    p = np.array([1.0, 0, 0, 0, 0, 0, 0.0, 0.0, 1.0, 0.0, 0.0])       # u = tanh(v)
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
    ({'v_s': 0.0}, 'v_s'), ({'c_o': float('nan')}, 'finite'), ({'w_l': -0.1}, 'w_l')])
def test_invalid_sets_are_refused_by_name(bad, rule):
    p = dict(zip(SMOOTH_NAMES, [1.0, 0.5, 0.0, 0.2, 0.0, 0.1, 0.0, 1.0, 2.0, 0.0, 0.0]))
    p.update(bad)
    with pytest.raises(InvalidParametersError, match=rule):
        FAMILY.check(np.array(list(p.values())))
    assert not FAMILY.feasible_rows(np.array([list(p.values())]))[0]
    with pytest.raises(InvalidParametersError):
        FAMILY.check(np.ones(3))


def test_compensator_runs_the_smooth_inverse_in_line():
    values = dict(zip(SMOOTH_NAMES, [0.8, 0.4, 0.0, 0.3, 0.2, 0.1, 0.2, 0.6, 3.0, 0.2, 1.0]))
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


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0] + [pytest.param(s, marks=pytest.mark.thorough)
                                        for s in (1, 2)])
def test_identify_reaches_the_true_floor_on_smooth_loops(seed):
    rec, floor = smooth_recording(seed)
    spec = domains_from_data(rec, family='smooth')
    ident = identify(rec, spec=spec, settings=IdentifySettings(workers=1))
    assert ident.family == 'smooth'
    assert ident.er_percent <= 1.1 * floor, (ident.er_percent / floor, ident.params)
