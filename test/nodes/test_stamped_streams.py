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

"""Stamped streams and the typed result (issue 15: "time is right").

With ``params/stamped.yaml`` (``topics.*_type: hyst_id_interfaces/msg/StampedValue``)
commands, desired values and flow carry the time they stand for:

* the compensator's command carries the stamp of the desired value it answers;
* the actuator driver and the pipeline simulator stamp their readings with the
  command's stamp, not its arrival;
* the identifier times stamped commands and flow by their stamps, so samples
  that arrive in a burst (a replay at any rate, a queue that caught up) keep
  their sample period, and a replay at rate 4 without ``/clock`` still gives
  the sensor's time constant;
* the identifier publishes each result typed (``IdentifiedParams``) beside the JSON;
* a field the configured type does not have is refused at start, with the fields.

These tests need the interfaces package built and sourced (``./run`` does it).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

from conftest import make_node, other_participant, spin_nodes_until
import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')
interfaces = pytest.importorskip('hyst_id_interfaces.msg', reason='the interfaces package '
                                 'is not built (./run builds it; test_colcon checks the build)')
IdentifiedParams, StampedValue = interfaces.IdentifiedParams, interfaces.StampedValue

from builtin_interfaces.msg import Time  # noqa: E402, I100
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import FluidPressure, JointState  # noqa: E402
from std_msgs.msg import Float64, Header, String  # noqa: E402
from test_identifier_node import FAST, PAPER  # noqa: E402

from hyst_id.errors import ConfigError  # noqa: E402
from hyst_id.io.interface_types import STAMPED_VALUE_TYPE  # noqa: E402
from hyst_id.nodes.actuator_driver import ActuatorDriver  # noqa: E402
from hyst_id.nodes.compensator import Compensator  # noqa: E402
from hyst_id.nodes.excitation import Excitation  # noqa: E402
from hyst_id.nodes.identifier import Identifier  # noqa: E402
from hyst_id.nodes.pipeline_sim import PipelineSim  # noqa: E402
from hyst_id.nodes.recorder import Recorder  # noqa: E402
from hyst_id.nodes.support import COMMAND_QOS, LATCHED_QOS, SENSOR_QOS  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402

pytestmark = pytest.mark.ros

STAMPED = [Parameter('topics.command_type', value=STAMPED_VALUE_TYPE),
           Parameter('topics.command_field', value='value')]
T0_NS = 1_800_000_000 * 10**9


def _spin_until(ctx, predicate, timeout=10.0):
    return spin_nodes_until(ctx[0], ctx[1], predicate, timeout)


def _stamp(ns: int) -> Time:
    return Time(sec=ns // 10**9, nanosec=ns % 10**9)


def _ns(stamp: Time) -> int:
    return stamp.sec * 10**9 + stamp.nanosec


def test_compensator_command_carries_the_stamp_of_the_desired_value(ctx):
    comp = make_node(ctx, Compensator, parameter_overrides=STAMPED + [
        Parameter('topics.desired_type', value=STAMPED_VALUE_TYPE),
        Parameter('max_rate_per_s', value=4.0),
        *[Parameter(k, value=v) for k, v in PAPER.items()]])
    io = make_node(ctx, Node, 'io')
    got = []
    io.create_subscription(StampedValue, 'hyst_id/command', got.append, COMMAND_QOS)
    pub = io.create_publisher(StampedValue, 'hyst_id/desired', COMMAND_QOS)
    assert _spin_until(ctx, lambda: pub.get_subscription_count() > 0)
    twin = copy.deepcopy(comp._comp)   # the same compensator, stepped offline
    stamps = [T0_NS + k * 250_000_000 for k in range(5)]
    desired = [9.0, 12.0, 14.0, 10.0, 12.0]
    for ns, d in zip(stamps, desired):  # sent in a burst, stamped 0.25 s apart
        pub.publish(StampedValue(header=Header(stamp=_stamp(ns)), value=d))
    assert _spin_until(ctx, lambda: len(got) == 5), got
    assert [_ns(m.header.stamp) for m in got] == stamps
    # the rate limit (4 mA/s) allows 1 mA per 0.25 s of stamps; over the burst's
    # milliseconds it would allow almost nothing
    want = [twin.step(d, ns * 1e-9) for ns, d in zip(stamps, desired)]
    assert [m.value for m in got] == pytest.approx(want, abs=1e-9)
    steps = np.abs(np.diff([m.value for m in got]))
    assert steps == pytest.approx(1.0, abs=1e-5), steps     # float seconds since 1970


def test_a_float64_publisher_on_a_stamped_desired_topic_is_an_error(ctx):
    statuses = []
    listener = make_node(ctx, Node, 'diag_listener')
    listener.create_subscription(
        DiagnosticArray, '/diagnostics',
        lambda m: statuses.extend((s.name, s.level[0], s.message) for s in m.status), 50)
    make_node(ctx, Compensator, parameter_overrides=[
        Parameter('topics.desired_type', value=STAMPED_VALUE_TYPE),
        Parameter('diagnostics_period_s', value=0.2)])
    with other_participant() as io:   # a wrong type can only come from elsewhere
        io.create_publisher(Float64, 'hyst_id/desired', COMMAND_QOS)
        assert _spin_until(ctx, lambda: any(
            n == 'hyst_id: compensator' and lvl == 2 and 'std_msgs/msg/Float64' in m
            and STAMPED_VALUE_TYPE in m for n, lvl, m in statuses), timeout=10.0), statuses


def test_actuator_driver_stamps_the_position_with_the_command_stamp(ctx):
    make_node(ctx, ActuatorDriver, parameter_overrides=STAMPED)
    io = make_node(ctx, Node, 'io')
    got = []
    io.create_subscription(JointState, 'hyst_id/position', got.append, SENSOR_QOS)
    pub = io.create_publisher(StampedValue, 'hyst_id/command', COMMAND_QOS)
    assert _spin_until(ctx, lambda: pub.get_subscription_count() > 0)
    stamps = [T0_NS + k * 100_000_000 for k in range(4)]
    for ns in stamps:                   # sent in a burst, stamped 0.1 s apart
        pub.publish(StampedValue(header=Header(stamp=_stamp(ns)), value=9.0))
    assert _spin_until(ctx, lambda: len(got) == 4)
    assert [_ns(m.header.stamp) for m in got] == stamps


def test_excitation_stamps_each_sample_when_it_is_meant_to_act(ctx):
    make_node(ctx, Excitation, parameter_overrides=[
        Parameter('topics.output_type', value=STAMPED_VALUE_TYPE),
        Parameter('duration_s', value=1.0), Parameter('sample_period_s', value=0.1),
        Parameter('time_scale', value=10.0)])
    io = make_node(ctx, Node, 'io')
    got = []
    io.create_subscription(StampedValue, 'hyst_id/command', got.append, COMMAND_QOS)
    before = io.get_clock().now().nanoseconds
    assert _spin_until(ctx, lambda: len(got) == 11, timeout=20.0), len(got)
    after = io.get_clock().now().nanoseconds
    ns = np.array([_ns(m.header.stamp) for m in got])
    # stamped when published (the node's clock), one after the other: no timing threshold,
    # so a slow or loaded machine passes as well
    assert before <= ns[0] and ns[-1] <= after and np.all(np.diff(ns) > 0), (before, ns, after)


def test_pipeline_sim_stamps_pressure_and_flow_with_the_command_stamp(ctx):
    make_node(ctx, PipelineSim, parameter_overrides=STAMPED + [
        Parameter('topics.flow_type', value=STAMPED_VALUE_TYPE), Parameter('step_s', value=0.1)])
    io = make_node(ctx, Node, 'io')
    flow, pressure = [], []
    io.create_subscription(StampedValue, 'hyst_id/flow', flow.append, SENSOR_QOS)
    io.create_subscription(FluidPressure, 'hyst_id/pressure', pressure.append, SENSOR_QOS)
    pub = io.create_publisher(StampedValue, 'hyst_id/command', COMMAND_QOS)
    assert _spin_until(ctx, lambda: pub.get_subscription_count() > 0)
    stamps = [T0_NS + k * 100_000_000 for k in range(4)]
    for ns in stamps:
        pub.publish(StampedValue(header=Header(stamp=_stamp(ns)), value=12.0))
    assert _spin_until(ctx, lambda: len(flow) == 4 and len(pressure) == 4)
    assert [_ns(m.header.stamp) for m in flow] == stamps
    assert [_ns(m.header.stamp) for m in pressure] == stamps
    assert all(np.isfinite(m.value) for m in flow)


def test_recorder_writes_stamped_values_that_read_back_by_stamp(ctx, tmp_path):
    from hyst_id.io.bag import iter_bag_messages

    rec = make_node(ctx, Recorder, parameter_overrides=[
        Parameter('output', value=str(tmp_path / 'bag')),
        Parameter('topics', value=['hyst_id/command'])])
    io = make_node(ctx, Node, 'io')
    pub = io.create_publisher(StampedValue, 'hyst_id/command', COMMAND_QOS)
    assert _spin_until(ctx, lambda: '/hyst_id/command' in rec.subscribed
                       and pub.get_subscription_count() > 0)
    stamps = [T0_NS + k * 100_000_000 for k in range(10)]
    for k, ns in enumerate(stamps):
        pub.publish(StampedValue(header=Header(stamp=_stamp(ns)), value=float(k)))
    assert _spin_until(ctx, lambda: rec.counts['/hyst_id/command'] == 10)
    rec.close()
    rows = list(iter_bag_messages(tmp_path / 'bag', topics=['/hyst_id/command']))
    assert [m.value for _, _, _, m in rows] == [float(k) for k in range(10)]
    assert [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _, _, _, m in rows] == \
        stamps


def test_identifier_times_a_burst_of_stamped_samples_by_their_stamps(ctx):
    ident = make_node(ctx, Identifier, parameter_overrides=FAST + STAMPED + [
        Parameter('channel', value='flow'),
        Parameter('topics.flow_type', value=STAMPED_VALUE_TYPE),
        Parameter('topics.flow_field', value='value'),
        Parameter('measurement_reliable', value=True)])
    io = make_node(ctx, Node, 'io')
    cmd = io.create_publisher(StampedValue, 'hyst_id/command', COMMAND_QOS)
    flow = io.create_publisher(StampedValue, 'hyst_id/flow', COMMAND_QOS)
    assert _spin_until(ctx, lambda: cmd.get_subscription_count() > 0
                       and flow.get_subscription_count() > 0)
    n = 60
    for k in range(n):                  # 6 s of samples sent within milliseconds
        ns = T0_NS + k * 100_000_000
        cmd.publish(StampedValue(header=Header(stamp=_stamp(ns)), value=9.0 + np.sin(k / 5)))
        flow.publish(StampedValue(header=Header(stamp=_stamp(ns + 1000)), value=0.1 * k))
    assert _spin_until(ctx, lambda: ident.buffer.n_measurements == n)
    rec = ident.collected_recording()
    np.testing.assert_allclose(np.diff(rec.t_s), 0.1, atol=1e-6)
    np.testing.assert_allclose(rec.command, 9.0 + np.sin(np.arange(n) / 5), atol=1e-12)


def test_a_field_the_type_lacks_is_refused_with_the_fields(ctx):
    wrong = [STAMPED[0], Parameter('topics.command_field', value='position[0]')]
    with pytest.raises(ConfigError, match=r"command_field.*no field 'position'.*header, value"):
        Identifier(context=ctx[0], parameter_overrides=FAST + wrong)
    # the type alone is enough: Float64's default field 'data' reads a StampedValue's value
    ident = make_node(ctx, Identifier, parameter_overrides=FAST + STAMPED[:1])
    assert ident._cmd_field == ('value',)


def test_identifier_publishes_the_typed_result_beside_the_json(ctx):
    ident = make_node(ctx, Identifier, parameter_overrides=FAST)
    t = np.arange(400) * 0.05
    from hyst_id.identification.chains import chain_spec
    y = chain_spec('position').simulate(np.array(list(PAPER.values())), t, eq24(t))
    y = y + np.random.default_rng(0).normal(0, 0.005, t.size)
    for k in range(t.size):
        ident.buffer.add_command(T0_NS + k * 50_000_000, eq24(t)[k])
        ident.buffer.add_measurement(T0_NS + k * 50_000_000 + 1000, y[k])
    io = make_node(ctx, Node, 'io')
    typed, docs = [], []
    io.create_subscription(IdentifiedParams, '/identifier/identified', typed.append,
                           LATCHED_QOS)
    io.create_subscription(String, '/hyst_id/identified_params',
                           lambda m: docs.append(json.loads(m.data)), LATCHED_QOS)
    assert ident.set_parameters([Parameter('identify_now', value=True)])[0].successful
    assert _spin_until(ctx, lambda: typed and docs, timeout=120.0), ident.last_error
    msg, doc = typed[-1], docs[-1]
    assert msg.channel == 'position' and msg.family == doc['family']
    assert dict(zip(msg.names, msg.values)) == pytest.approx(
        {k: v for k, v in doc['params'].items() if isinstance(v, float)})
    assert msg.er_percent == pytest.approx(doc['er_percent'])
    assert msg.noise_floor_percent == pytest.approx(doc['noise_floor_percent'])
    assert list(msg.warnings) == doc['warnings']
    assert msg.handed_over == (doc['compensator_params'] is not None)
    assert json.loads(msg.detail_json)['er_percent'] == doc['er_percent']
    assert _ns(msg.header.stamp) > 0


@pytest.mark.slow
@pytest.mark.thorough
def test_replay_at_rate_4_of_stamped_streams_keeps_tau_without_a_clock(ctx, tmp_path):
    """As test_identifier_node's rate-4 replay, but stamped commands instead of /clock.

    Without use_sim_time the unstamped commands would be timed by their arrival,
    4 x too fast; stamped, they keep the bag's time. Thorough tier: the default run
    checks the stamps' timing on a burst
    (``test_identifier_times_a_burst_of_stamped_samples_by_their_stamps``) and the rate-4
    replay with /clock (``test_identifier_node``); a stamped bag replayed without a
    clock is checked by ``./run test-all`` only.
    """
    from reference_sim import simulate

    from hyst_id.io.bag import write_recording_bag
    from hyst_id.io.recording import Recording
    from hyst_id.io.topics import TopicConfig
    from hyst_id.nodes.replay import Replay

    t = np.arange(900) * 0.1
    v = eq24(t)
    y = simulate('pressure', {**PAPER, 'tau_s': 1.5}, t, v, gain=-40_000.0, offset=600_000.0)
    y = y + np.random.default_rng(5).normal(0, 100.0, t.size)
    cfg = TopicConfig.for_channel('pressure', {'command_type': STAMPED_VALUE_TYPE,
                                               'command_field': 'value'})
    bag = write_recording_bag(tmp_path / 'p', Recording(t, v, y, 'pressure', 'mA', 'Pa'), cfg)
    docs = []
    io = make_node(ctx, Node, 'listener')
    io.create_subscription(String, '/hyst_id/identified_params',
                           lambda m: docs.append(json.loads(m.data)), LATCHED_QOS)
    make_node(ctx, Identifier, parameter_overrides=STAMPED + [
        Parameter('channel', value='pressure'),
        Parameter('seeds', value=2), Parameter('generations', value=60),
        Parameter('global_runs', value=6), Parameter('hops', value=0),
        Parameter('end_of_run_timeout_s', value=1.0), Parameter('compensator_node', value=''),
        Parameter('measurement_reliable', value=True), Parameter('recover_on_start', value=False),
        Parameter('params_out', value=str(tmp_path / 'out.yaml'))])
    make_node(ctx, Replay, parameter_overrides=[
        Parameter('bag', value=str(bag)), Parameter('rate', value=4.0),
        Parameter('publish_clock', value=False),
        Parameter('wait_for_subscribers', value=2), Parameter('shutdown_when_done', value=False)])
    assert _spin_until(ctx, lambda: bool(docs), timeout=150.0)
    assert docs[-1]['n_samples'] >= 890
    assert docs[-1]['params']['tau_s'] == pytest.approx(1.5, rel=0.15), docs[-1]['params']


@pytest.mark.slow
def test_bringup_runs_stamped_streams_in_a_namespace(ros_domain, tmp_path, monkeypatch, capfd):
    """The whole graph with params/stamped.yaml, on flow, under -r __ns:=/valve1."""
    import re

    from test_wiring import TWO_GRAPHS   # the short bringup of the two-namespace test

    from hyst_id.nodes import bringup

    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    params = tmp_path / 'bringup.yaml'
    params.write_text(TWO_GRAPHS.format(channel='flow', bag=tmp_path / 'bag'))
    stamped = Path(__file__).resolve().parents[2] / 'params' / 'stamped.yaml'
    code = bringup.main(['--ros-args', '--params-file', str(params), '--params-file',
                         str(stamped), '-r', '__ns:=/valve1'])
    out = capfd.readouterr().out
    figures = dict(re.findall(r'(%e_r|uncompensated|compensated)\s+([0-9.]+) %', out))
    assert code == 0 and len(figures) == 3, out[-3000:]
    assert 'channel flow' in out, out[-3000:]
    # the lockstep makes the figures load-independent; measured 12.3 vs 50.6 %: a 4 x margin
    assert float(figures['compensated']) < float(figures['uncompensated']), figures
    from hyst_id.io.bag import open_bag
    with open_bag(tmp_path / 'bag') as bag:
        types = dict(bag.topics)
    assert types['/valve1/hyst_id/command'] == STAMPED_VALUE_TYPE, types
    assert all(t.startswith('/valve1/') for t in types), types    # the whole graph's topics
    assert types['/valve1/hyst_id/flow'] == STAMPED_VALUE_TYPE, types


def test_a_command_stamped_before_the_last_moves_no_time():
    from types import SimpleNamespace

    from hyst_id.nodes.support import CommandClock
    warned = []
    log = SimpleNamespace(warning=lambda text, **kw: warned.append(text))
    clock = CommandClock()
    assert clock.advance(T0_NS, log) == (T0_NS, 0.0)
    assert clock.advance(T0_NS + 250_000_000, log) == (T0_NS + 250_000_000, 0.25)
    # a bag replayed again: the stamp goes back, the plant's time does not
    assert clock.advance(T0_NS, log) == (T0_NS + 250_000_000, 0.0) and len(warned) == 1
    assert clock.advance(T0_NS + 350_000_000, log)[1] == pytest.approx(0.1)


def test_a_non_finite_command_is_ignored_and_named_on_diagnostics(ctx):
    """The driver and the simulated pipeline drop a NaN command; their status says so."""
    from std_msgs.msg import Float64
    from hyst_id.nodes.pipeline_sim import PipelineSim
    for cls in (ActuatorDriver, PipelineSim):
        node = make_node(ctx, cls)
        node._on_command(Float64(data=float('nan')), {})
        assert node.non_finite_seen == 1
        assert '1 non-finite input value(s)' in node.non_finite_problem()
        assert node.non_finite_problem() == ''          # said once, the count kept
