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

"""The compensator node's tracking link: measurement in, corrected commands out, events logged."""

from __future__ import annotations

import json

from conftest import make_node, spin_nodes_until
import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')

from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402

from hyst_id.errors import ConfigError  # noqa: E402
from hyst_id.nodes.actuator_driver import PAPER_HYSTERESIS, SimulatedActuator  # noqa: E402
from hyst_id.nodes.compensator import Compensator  # noqa: E402
from hyst_id.nodes.support import LATCHED_QOS  # noqa: E402

pytestmark = pytest.mark.ros

BACKLASH = {'m_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}
PAPER = {**PAPER_HYSTERESIS, **BACKLASH}
GAIN, OFFSET = 0.8, 0.5          # the plant reads 0.8 x the model's output + 0.5


def _tracking_node(ctx, **extra):
    overrides = [Parameter(k, value=v) for k, v in {**PAPER, 'tracking.enabled': True,
                                                    **extra}.items()]
    return make_node(ctx, Compensator, parameter_overrides=overrides)


def _joint(value: float) -> JointState:
    return JointState(name=['valve'], position=[value])


def _closed_loop(comp: Compensator, desired: np.ndarray, observe: bool) -> np.ndarray:
    """Desired -> node -> plant (paper's H and B, then the gain and offset) -> node."""
    plant = SimulatedActuator(PAPER_HYSTERESIS, BACKLASH)
    out = []
    for d in desired:
        comp._on_desired(Float64(data=float(d)))
        y = GAIN * plant.apply(comp._comp.state[0]) + OFFSET
        if observe:
            comp._tracking._on_measurement(_joint(y))
        out.append(y)
    return np.array(out)


def test_tracking_corrects_a_plant_gain_and_offset(ctx):
    desired = 9.0 + np.sin(2 * np.pi * np.arange(600) / 40.0)
    fixed = _closed_loop(make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()]), desired, observe=False)
    comp = _tracking_node(ctx)
    tracked = _closed_loop(comp, desired, observe=True)
    late = slice(400, None)
    e_fixed = np.sqrt(np.mean((fixed - desired)[late] ** 2))
    e_tracked = np.sqrt(np.mean((tracked - desired)[late] ** 2))
    assert e_fixed > 1.0 and e_tracked < 0.01 * e_fixed, (e_fixed, e_tracked)
    status = comp._tracking.status()
    assert status['tracking'] == 'tracking'
    assert status['tracking_gain'] == pytest.approx(GAIN, rel=0.01)


def test_the_measurement_topic_reaches_the_tracker(ctx):
    comp = _tracking_node(ctx)
    talker = make_node(ctx, Node, 'talker')
    pub = talker.create_publisher(JointState, '/hyst_id/position', 10)
    comp._on_desired(Float64(data=9.0))

    def observed():
        pub.publish(_joint(8.0))
        return comp._tracking.adaptive.tracker.centre is not None

    assert spin_nodes_until(ctx[0], [comp, talker], observed, timeout=10.0)


def test_unreadable_or_non_finite_measurements_are_an_error_on_diagnostics(ctx):
    """A NaN reading or an empty JointState while tracking: the next status is an ERROR.

    A review saw the NaN stream leave the status at OK ``compensating`` (only a WARN logged).
    """
    comp = _tracking_node(ctx)
    sent: list[tuple[int, str]] = []
    comp.publish_diagnostics = lambda level, msg, values=None, **kw: sent.append((level, msg))
    comp._on_desired(Float64(data=9.0))
    comp._tracking._on_measurement(_joint(float('nan')))
    comp._publish_status()
    assert sent[-1][0] == 2 and 'non-finite' in sent[-1][1], sent[-1]
    comp._tracking._on_measurement(JointState(position=[]))
    comp._publish_status()
    assert sent[-1][0] == 2 and 'not collected: tracking: cannot read' in sent[-1][1], sent[-1]
    comp._tracking._on_measurement(_joint(8.0))
    comp._publish_status()
    assert sent[-1][0] == 0, sent[-1]


def test_sensor_parameters_come_with_the_identified_set(ctx):
    comp = _tracking_node(ctx, channel='pressure', **{'tracking.tau_s': 1.0})
    talker = make_node(ctx, Node, 'talker')
    pub = talker.create_publisher(String, '/hyst_id/identified_params', LATCHED_QOS)
    pub.publish(String(data=json.dumps({'channel': 'pressure', 'compensator_params': PAPER,
                                        'params': {**PAPER, 'tau_s': 2.5}})))
    assert spin_nodes_until(ctx[0], [comp, talker], lambda: comp.p('tracking.tau_s') == 2.5)
    assert comp._tracking.adaptive.sensor.params == (2.5,)


def test_tracking_without_its_sensor_parameters_is_refused(ctx):
    with pytest.raises(ConfigError, match='tracking.tau_s'):
        _tracking_node(ctx, channel='pressure')
    comp = make_node(ctx, Compensator)
    result = comp.set_parameters_atomically([Parameter('channel', value='flow'),
                                             Parameter('tracking.enabled', value=True)])
    assert not result.successful and 'tracking.zeta' in result.reason


def test_a_refused_identified_set_is_a_warning_on_diagnostics_until_one_is_accepted(ctx):
    """Not JSON, an incomplete set, an invalid loop: counted, a WARN with the reason.

    The set before stays. A review saw OK throughout and only the invalid loop counted.
    """
    comp = make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()])
    sent: list[tuple[int, str]] = []
    comp.publish_diagnostics = lambda level, msg, values=None, **kw: sent.append((level, msg))
    bad = ['{not json', json.dumps({'channel': 'position', 'params': {'m_l': 1.0}}),
           json.dumps({'channel': 'position', 'params': {**PAPER, 'm_t': -3.0}})]
    for k, text in enumerate(bad, start=1):
        comp._on_identified(String(data=text))
        assert comp.rejected_updates == k
        comp._publish_status()
        assert sent[-1][0] == 1 and 'identified parameters refused' in sent[-1][1], sent[-1]
        assert 'the set before it stays' in sent[-1][1]
    assert comp.p('m_l') == PAPER['m_l'] and comp.model is not None
    comp._on_identified(String(data=json.dumps({'channel': 'position',
                                                'params': {**PAPER, 'm_l': 1.02}})))
    comp._publish_status()
    assert sent[-1][0] == 0 and comp.p('m_l') == 1.02, sent[-1]
