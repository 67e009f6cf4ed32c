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

"""The zero-order-hold convention of the diagnosis's filters, against the reference simulator.

The reference simulator (written apart from the package) holds ``x(j-1)`` over
``[t(j-1), t(j))``, one sample later than the package's own filters. A composed
model in the ``after`` convention must reproduce it to round-off, in the ``before``
convention it must not; on a recording with a lag or a second order the diagnosis picks
the convention that fits (``extra['hold']``).
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import first_order_sensor, second_order_sensor

from hyst_id.diagnosis.mechanisms import Context, MECHANISMS
from hyst_id.diagnosis.model import ComposedModel, held
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.excitation import multisine

CHAIN = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15, 0.4])
T = np.arange(0.0, 60.0, 0.05)
V = multisine(T, amplitude_ma=1.8)


def _sensor_column(channel: str, mech: str | None, theta: list, hold: str):
    ctx = Context(channel, T, T.size)
    mechs = [MECHANISMS[mech]] if mech else []
    model = ComposedModel(channel, mechs, ctx, chain_spec(channel).bounds, hold=hold)
    n_chain = model.n_chain
    ev = model.evaluate(np.concatenate([CHAIN[:n_chain], theta]), T, V, T.size)
    return ev.columns[0], ev.travel_raw


def test_held_moves_the_input_one_sample_later():
    x = np.array([1.0, 2.0, 3.0])
    assert np.array_equal(held(x, 'after'), [1.0, 1.0, 2.0])
    assert np.array_equal(held(x, 'before'), x)
    with pytest.raises(ConfigError):
        ComposedModel('position', [], Context('position', T, T.size),
                      chain_spec('position').bounds, hold='late')


@pytest.mark.parametrize('mech, theta, ref', [
    ('sensor_lag', [0.4], lambda t, x: first_order_sensor(t, x, 0.4)),
    ('actuator_dynamics', [0.3, 2.5], lambda t, x: second_order_sensor(t, x, 0.3, 2.5)),
])
def test_a_filter_block_after_matches_the_reference_and_before_does_not(mech, theta, ref):
    after, travel = _sensor_column('position', mech, theta, 'after')
    before, _ = _sensor_column('position', mech, theta, 'before')
    expected = ref(T, travel)
    scale = np.ptp(expected)
    assert np.max(np.abs(after - expected)) < 1e-9 * scale
    assert np.max(np.abs(before - expected)) > 1e-2 * scale


def test_the_pressure_sensor_after_matches_the_reference():
    after, travel = _sensor_column('pressure', None, [], 'after')
    expected = first_order_sensor(T, travel, CHAIN[11])
    assert np.max(np.abs(after - expected)) < 1e-9 * np.ptp(expected)
