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

"""The in-line compensator: exact inversion, limits, atomic swaps, pass-through."""

from __future__ import annotations

import re

import numpy as np
import pytest

from hyst_id.compensation import CommandLimits, Compensator, InverseModel
from hyst_id.errors import InvalidParametersError
from hyst_id.identification.chains import chain_spec

CANON = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
T = np.arange(0.0, 60.0, 0.5)
DESIRED = 9.0 + np.sin(2 * np.pi * T / 12.0)       # Eq. 25
PAPER_SET = dict(zip(chain_spec('position').names, (float(x) for x in CANON)))


def plant(commands: np.ndarray, v0: float = 9.0, sign: float = 1.0) -> np.ndarray:
    """The true actuator (H then B) driven from the same state as the compensator."""
    spec = chain_spec('position', calibration=(sign, 0.0))
    return spec.simulate(CANON, np.arange(len(commands) + 1.0), np.r_[v0, commands])[1:]


@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_compensated_actuator_tracks_exactly(sign):
    comp = Compensator(InverseModel.from_vector(CANON, output_sign=sign), v0=9.0)
    out = plant(comp.run(sign * DESIRED), sign=sign)
    np.testing.assert_allclose(out, sign * DESIRED, atol=1e-9)
    uncompensated = plant(DESIRED)
    assert np.max(np.abs(uncompensated - DESIRED)) > 0.3


def test_limits_are_never_exceeded_and_state_follows_what_was_sent():
    limits = CommandLimits(min_command=8.5, max_command=10.0, max_rate_per_s=1.0)
    comp = Compensator(InverseModel.from_vector(CANON), limits, v0=9.0)
    commands = comp.run(DESIRED + 1.0, T)
    assert commands.min() >= 8.5 and commands.max() <= 10.0
    assert np.max(np.abs(np.diff(commands))) <= 1.0 * 0.5 + 1e-12
    assert comp.state[0] == commands[-1]


def test_the_rate_limit_starts_from_the_held_command():
    """The first command after a reset is the held one: no time has passed to move."""
    comp = Compensator(None, CommandLimits(4.0, 20.0, max_rate_per_s=1.0), v0=9.0)
    assert comp.step(15.0, 100.0) == 9.0
    assert comp.step(15.0, 100.5) == pytest.approx(9.5)
    comp.reset(12.0)
    assert comp.step(4.0, 200.0) == 12.0
    assert comp.step(4.0, 201.0) == pytest.approx(11.0)


@pytest.mark.parametrize('sign', [1.0, -1.0])
@pytest.mark.parametrize('rate', [np.inf, 1.0])
def test_a_desired_value_beyond_any_reach_goes_to_the_limit_on_its_side(sign, rate):
    """1e308 overflowed the inverse and held the last command; 1e6 went to the limit.

    A non-finite desired value is still held (never sent); with no limit on a
    side, an overflow toward it holds too.
    """
    def after(desired, limits):
        comp = Compensator(InverseModel.from_vector(CANON, output_sign=sign), limits, v0=9.0)
        comp.step(sign * 9.0, 0.0)
        held = comp.state[0]
        return comp.step(desired, 1.0), held

    limits = CommandLimits(4.0, 20.0, max_rate_per_s=rate)
    for big in (1e6, 1e308, np.finfo(float).max):
        assert after(sign * big, limits)[0] == after(sign * 1e6, limits)[0] > 9.0
        assert after(-sign * big, limits)[0] == after(-sign * 1e6, limits)[0] < 9.0
    for bad in (np.inf, -np.inf, np.nan):
        got, held = after(bad, limits)
        assert got == held
    got, held = after(sign * 1e308, CommandLimits())
    assert got == held


def test_no_model_passes_through():
    comp = Compensator(None, CommandLimits(0.0, 20.0), v0=9.0)
    np.testing.assert_array_equal(comp.run(DESIRED), DESIRED)


def test_bypass_passes_through_and_resumes_from_the_real_state():
    comp = Compensator(InverseModel.from_vector(CANON), v0=9.0)
    half = len(DESIRED) // 2
    comp.bypass = True
    first = comp.run(DESIRED[:half])
    np.testing.assert_array_equal(first, DESIRED[:half])          # passed through
    comp.bypass = False
    second = comp.run(DESIRED[half:])
    # the plant driven by everything sent tracks exactly once the bypass ends: the
    # model state followed the passed-through commands
    out = plant(np.r_[first, second])
    np.testing.assert_allclose(out[half:], DESIRED[half:], atol=1e-9)
    assert np.max(np.abs(out[:half] - DESIRED[:half])) > 0.3


def test_swap_keeps_state_inside_the_new_loop():
    comp = Compensator(InverseModel.from_vector(CANON), v0=9.0)
    comp.run(DESIRED[:30])
    wider = CANON.copy()
    wider[4] -= 0.5
    new = InverseModel.from_vector(wider)
    comp.set_model(new)
    v, u, _ = comp.state
    lower, upper = new.inverse().output_range(v)
    assert lower <= u <= upper
    assert np.all(np.isfinite(comp.run(DESIRED[30:])))


@pytest.mark.parametrize('values, reason', [
    ({'m_l': 1.0}, 'missing'),
    ({**dict(zip(('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl',
                  'c_br'), CANON)), 'c_l': 2.0}, 'not proper'),
    ({**dict(zip(('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl',
                  'c_br'), CANON)), 'output_sign': 0.5}, 'output_sign'),
])
def test_invalid_sets_are_rejected_with_the_reason(values, reason):
    with pytest.raises(InvalidParametersError, match=reason):
        InverseModel.from_mapping(values)


@pytest.mark.parametrize('doc, words', [
    ([1, 2], 'a JSON object was expected, got list'),
    ({'channel': 'position'}, 'm_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b, m_bl, c_bl, c_br missing'),
    ({'params': {'family': 'preisach'}}, "unknown family 'preisach' (known: "),
    ({'params': 'm_l=1'}, 'its parameters must be an object, got str'),
    ({'params': {**PAPER_SET, 'm_l': 'one'}}, "m_l is 'one', not a number"),
])
def test_a_malformed_set_document_is_named(doc, words):
    """What an identified-parameters document lacks is said (was a bare ``KeyError('m_l')``)."""
    from hyst_id.compensation.params_file import read_set_document
    with pytest.raises(ValueError, match=re.escape(words)):
        read_set_document(doc)


def test_a_set_document_is_read_with_its_sensor_values():
    from hyst_id.compensation.params_file import read_set_document
    doc = {'channel': 'pressure', 'params': {**PAPER_SET, 'tau_s': 0.5}, 'er_percent': 0.7,
           'output_sign': -1}
    channel, values, er = read_set_document(doc, ('tau_s', 'zeta'))
    assert (channel, er, values['output_sign'], values['family']) == ('pressure', 0.7, -1.0, 'tk')
    assert values['tracking.tau_s'] == 0.5 and 'tracking.zeta' not in values
    assert {k: values[k] for k in PAPER_SET} == PAPER_SET
