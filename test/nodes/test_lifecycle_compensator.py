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

"""The lifecycle compensator: commands only while active, through the standard services.

Driven the way a lifecycle manager drives it: ``lifecycle_msgs/ChangeState``
on ``/compensator/change_state`` and ``GetState`` on
``/compensator/get_state``, from another node.
"""

from __future__ import annotations

from conftest import make_node, spin_nodes_until
import pytest

rclpy = pytest.importorskip('rclpy')

from lifecycle_msgs.msg import Transition  # noqa: E402, I100
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402

from hyst_id.compensation import CommandLimits, InverseModel  # noqa: E402
from hyst_id.compensation import Compensator as CoreCompensator  # noqa: E402
from hyst_id.nodes.actuator_driver import PAPER_HYSTERESIS  # noqa: E402
from hyst_id.nodes.lifecycle_compensator import LifecycleCompensator  # noqa: E402
from hyst_id.nodes.support import COMMAND_QOS  # noqa: E402

pytestmark = pytest.mark.ros

PAPER = {**PAPER_HYSTERESIS, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}


class Manager:
    """A minimal lifecycle manager: the services, a desired publisher, a command listener."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.node = make_node(ctx, Node, 'manager')
        self.change = self.node.create_client(ChangeState, '/compensator/change_state')
        self.get = self.node.create_client(GetState, '/compensator/get_state')
        self.desired = self.node.create_publisher(Float64, '/hyst_id/desired', COMMAND_QOS)
        self.commands: list[float] = []
        self.node.create_subscription(Float64, '/hyst_id/command',
                                      lambda m: self.commands.append(m.data), COMMAND_QOS)

    def call(self, comp, client, request):
        assert client.wait_for_service(timeout_sec=10.0)
        future = client.call_async(request)
        assert spin_nodes_until(self.ctx[0], [comp, self.node], future.done, 10.0)
        return future.result()

    def transition(self, comp, transition_id: int) -> bool:
        req = ChangeState.Request()
        req.transition.id = transition_id
        return self.call(comp, self.change, req).success

    def state(self, comp) -> str:
        return self.call(comp, self.get, GetState.Request()).current_state.label

    def send(self, comp, values, expect_commands: int) -> None:
        """Publish desired values; spin until ``expect_commands`` commands are in (or 2 s)."""
        for v in values:
            self.desired.publish(Float64(data=v))
            spin_nodes_until(self.ctx[0], [comp, self.node], lambda: False, 0.01)
        spin_nodes_until(self.ctx[0], [comp, self.node],
                         lambda: len(self.commands) >= expect_commands, 2.0)


def _compensator(ctx, **params):
    return make_node(ctx, LifecycleCompensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in params.items()])


def test_commands_flow_only_while_active(ctx):
    comp = _compensator(ctx, **PAPER)
    mgr = Manager(ctx)
    assert mgr.state(comp) == 'unconfigured'
    mgr.send(comp, [9.0, 9.5, 10.0], 0)
    assert mgr.commands == [] and comp._dropped == 3     # unconfigured: nothing sent
    assert mgr.transition(comp, Transition.TRANSITION_CONFIGURE)
    assert mgr.state(comp) == 'inactive'
    mgr.send(comp, [9.0, 9.5], 0)
    assert mgr.commands == []                             # inactive: nothing sent
    assert mgr.transition(comp, Transition.TRANSITION_ACTIVATE)
    assert mgr.state(comp) == 'active'
    desired = [9.0, 9.5, 10.0, 10.5, 10.0, 9.5]
    mgr.send(comp, desired, len(desired))
    assert len(mgr.commands) == len(desired)
    # the commands of the set's inverse run on its own, from the command held at activation
    core = CoreCompensator(InverseModel.from_mapping({**PAPER, 'output_sign': 1.0,
                                                      'family': 'tk'}),
                           CommandLimits(4.0, 20.0), v0=comp.p('initial_command'))
    assert mgr.commands == pytest.approx([core.step(d) for d in desired], abs=1e-12)
    assert mgr.transition(comp, Transition.TRANSITION_DEACTIVATE)
    n = len(mgr.commands)
    mgr.send(comp, [11.0, 11.5], n + 1)
    assert len(mgr.commands) == n                         # deactivated: commands stop
    assert mgr.transition(comp, Transition.TRANSITION_CLEANUP)
    assert mgr.state(comp) == 'unconfigured'
    assert comp._comp.state[0] == comp.p('initial_command')


def test_configure_fails_without_a_set_under_require_model(ctx):
    comp = _compensator(ctx, require_model=True)
    mgr = Manager(ctx)
    assert not mgr.transition(comp, Transition.TRANSITION_CONFIGURE)
    assert mgr.state(comp) == 'unconfigured'
    # a set given afterwards (as the identifier pushes it) lets it configure
    assert comp.set_parameters_atomically(
        [Parameter(k, value=v) for k, v in PAPER.items()]).successful
    assert mgr.transition(comp, Transition.TRANSITION_CONFIGURE)
    assert mgr.state(comp) == 'inactive'
