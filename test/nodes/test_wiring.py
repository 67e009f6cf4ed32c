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

"""Wiring into a larger stack (issue 15): namespaces, hand-over, loud mistakes.

* relative topics and ``/**`` params files: two valves in two namespaces on
  one domain do not cross, and a params file written by one identifier
  loads into a compensator in any namespace;
* the quality gate holds a set back (no push, no params file, WARN);
* restart recovery never overwrites a set loaded on purpose;
* mistakes are loud: unknown params-file keys, a model required but absent,
  a wrong message type on an input, one input arriving without the other.
"""

from __future__ import annotations

import json

from conftest import make_node, other_participant, spin_nodes_until
import pytest

rclpy = pytest.importorskip('rclpy')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402
from test_identifier_node import _feed, _samples, FAST, PAPER  # noqa: E402

from hyst_id.compensation.params_file import (  # noqa: E402
    read_compensator_params,
    write_compensator_params,
)
from hyst_id.nodes.compensator import Compensator  # noqa: E402
from hyst_id.nodes.identifier import Identifier  # noqa: E402
from hyst_id.nodes.support import COMMAND_QOS, LATCHED_QOS  # noqa: E402
from hyst_id.nodes.support.hyst_node import unknown_overrides  # noqa: E402

pytestmark = pytest.mark.ros


def _spin_until(ctx, predicate, timeout=10.0):
    return spin_nodes_until(ctx[0], ctx[1], predicate, timeout)


def _statuses(ctx, name='diag_listener'):
    """Every DiagnosticStatus published on /diagnostics, as (name, level, message)."""
    got = []
    node = make_node(ctx, Node, name)
    node.create_subscription(
        DiagnosticArray, '/diagnostics',
        lambda a: got.extend((s.name, int.from_bytes(s.level, 'little'), s.message)
                             for s in a.status), 10)
    return got


def _identify(ctx, ident):
    _feed(ident, *_samples())
    assert ident.request_identification('test')[0]
    assert _spin_until(ctx, lambda: ident.job is None and ident.last_document is not None,
                       timeout=120.0), ident.last_error


def test_two_namespaced_valves_do_not_cross(ctx, tmp_path):
    out = tmp_path / 'valve1.yaml'
    ident = make_node(ctx, Identifier, namespace='/valve1', parameter_overrides=FAST + [
        Parameter('params_out', value=str(out))])
    comp1 = make_node(ctx, Compensator, namespace='/valve1')
    comp2 = make_node(ctx, Compensator, namespace='/valve2')
    assert ident._result_pub.topic_name == '/valve1/hyst_id/identified_params'
    assert comp2._cmd_pub.topic_name == '/valve2/hyst_id/command'
    _identify(ctx, ident)
    assert _spin_until(ctx, lambda: comp1.model is not None, timeout=10.0)
    _spin_until(ctx, lambda: False, timeout=1.0)
    assert comp2.model is None                       # valve 2 never took valve 1's set
    # the params file is keyed /** and loads into a compensator in any namespace
    assert '/**:' in out.read_text().splitlines()
    comp3 = make_node(ctx, Compensator, namespace='/spare/valve1',
                      cli_args=['--ros-args', '--params-file', str(out)])
    assert comp3.model is not None and comp3._source == 'params'
    assert comp3.p('m_l') == pytest.approx(read_compensator_params(out)['m_l'], rel=1e-12)


def test_the_quality_gate_holds_a_set_back(ctx, tmp_path):
    out = tmp_path / 'comp.yaml'
    statuses = _statuses(ctx)
    ident = make_node(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('params_out', value=str(out)),
        Parameter('gate_max_floor_ratio', value=0.5)])   # a fit at the floor is ~1 x
    comp = make_node(ctx, Compensator)
    _identify(ctx, ident)
    doc = ident.last_document
    assert doc['compensator_params'] is None and not doc['gate']['passed']
    assert 'x the noise floor' in doc['gate']['reasons'][0]
    assert 'held back by the quality gate' in doc['compensator_note']
    assert _spin_until(ctx, lambda: any(n == 'hyst_id: identifier' and lvl == 1
                                        and 'held it back' in m for n, lvl, m in statuses),
                       timeout=5.0)
    assert not out.exists() and comp.model is None   # nothing handed over


def test_the_gate_passes_a_good_fit_with_its_warnings_in_the_document(ctx, tmp_path):
    ident = make_node(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('params_out', value=str(tmp_path / 'comp.yaml'))])
    _identify(ctx, ident)
    doc = ident.last_document
    assert doc['gate']['passed'] and doc['compensator_params'] is not None
    assert isinstance(doc['warnings'], list) and isinstance(doc['poorly_determined'], dict)
    assert json.loads(json.dumps(doc)) == doc


def test_recovery_does_not_overwrite_a_set_loaded_on_purpose(ctx, tmp_path):
    stale = tmp_path / 'stale.yaml'
    write_compensator_params({'channel': 'position', 'params': {**PAPER, 'c_br': 0.3},
                              'er_percent': 0.5}, stale)
    comp = make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()])
    assert comp._source == 'params'
    make_node(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('params_out', value=str(stale))])          # republishes the stale set
    _spin_until(ctx, lambda: False, timeout=1.5)
    assert comp.p('c_br') == 0.25                          # the set loaded on purpose stays
    follower = make_node(ctx, Compensator,                 # one without a set takes it
                         cli_args=['--ros-args', '-r', '__node:=follower'])
    assert _spin_until(ctx, lambda: follower.model is not None, timeout=5.0)
    assert follower.p('c_br') == 0.3


def test_every_topic_key_of_a_node_is_known_to_the_recordings_reader():
    """A ``topics:`` key no node has is refused as a typo by the reader; a node's must pass."""
    import importlib
    from hyst_id.io.topics import NODE_STREAM_KEYS, NODE_TOPIC_KEYS
    known = NODE_STREAM_KEYS | NODE_TOPIC_KEYS
    for name in ('actuator_driver', 'pipeline_sim', 'excitation', 'identifier', 'compensator',
                 'recorder', 'replay', 'bringup'):
        params = importlib.import_module(f'hyst_id.nodes.{name}').PARAMS
        for p in params:
            if p.name.startswith('topics.'):
                key = p.name.removeprefix('topics.')
                channel_key = key.split('_')[0] in ('command', 'position', 'pressure', 'flow')
                assert key in known or channel_key or key == 'stamp_source', (name, key)


def test_unknown_parameters_are_an_error(ctx, tmp_path):
    assert unknown_overrides(['max_comand', 'topics.flow_topic', 'use_sim_time',
                              'qos_overrides./x.publisher.depth', 'm_l'],
                             ['m_l', 'max_command']) == ['max_comand']
    params = tmp_path / 'typo.yaml'
    params.write_text('/**:\n  ros__parameters:\n    max_comand: 21.0\n'
                      '    topics:\n      flow_topic: hyst_id/flow\n')
    statuses = _statuses(ctx)
    comp = make_node(ctx, Compensator, cli_args=['--ros-args', '--params-file', str(params)])
    assert comp.unknown_parameters == ['max_comand']
    assert comp.p('max_command') == 20.0
    assert _spin_until(ctx, lambda: any(n == 'hyst_id: compensator: parameters' and lvl == 2
                                        and 'max_comand' in m for n, lvl, m in statuses),
                       timeout=5.0)
    good = make_node(ctx, Compensator, cli_args=['--ros-args', '-r', '__node:=good'])
    assert good.unknown_parameters == []


def test_require_model_holds_the_command_and_reports_error(ctx):
    statuses = _statuses(ctx)
    make_node(ctx, Compensator, parameter_overrides=[
        Parameter('require_model', value=True), Parameter('initial_command', value=9.0),
        Parameter('diagnostics_period_s', value=0.2)])
    io = make_node(ctx, Node, 'io')
    commands = []
    io.create_subscription(Float64, 'hyst_id/command', lambda m: commands.append(m.data),
                           COMMAND_QOS)
    pub = io.create_publisher(Float64, 'hyst_id/desired', COMMAND_QOS)
    io.create_timer(0.05, lambda: pub.publish(Float64(data=15.0)))
    assert _spin_until(ctx, lambda: len(commands) >= 3, timeout=10.0)
    assert set(commands) == {9.0}                          # held, never passed through
    assert _spin_until(ctx, lambda: any(n == 'hyst_id: compensator' and lvl == 2
                                        and 'require_model' in m for n, lvl, m in statuses),
                       timeout=5.0)


def test_a_wrong_message_type_on_the_desired_topic_is_an_error(ctx):
    statuses = _statuses(ctx)
    make_node(ctx, Compensator, parameter_overrides=[
        Parameter('diagnostics_period_s', value=0.2)])
    with other_participant() as io:   # a wrong type can only come from elsewhere
        io.create_publisher(String, 'hyst_id/desired', LATCHED_QOS)
        assert _spin_until(ctx, lambda: any(n == 'hyst_id: compensator' and lvl == 2
                                            and 'std_msgs/msg/String' in m
                                            for n, lvl, m in statuses), timeout=10.0)


def test_a_best_effort_publisher_on_the_reliable_desired_topic_is_an_error(ctx):
    """A publisher whose QoS the subscription does not match is named, not silence.

    The compensator stayed OK "compensating" while a best-effort publisher's desired
    values never reached it (found by an independent review).
    """
    statuses = _statuses(ctx)
    make_node(ctx, Compensator, parameter_overrides=[
        Parameter('diagnostics_period_s', value=0.2)])
    io = make_node(ctx, Node, 'loose')
    io.create_publisher(Float64, 'hyst_id/desired',
                        QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    assert _spin_until(ctx, lambda: any(n == 'hyst_id: compensator' and lvl == 2
                                        and '/loose publishes best effort' in m
                                        for n, lvl, m in statuses), timeout=10.0)


def test_commands_without_measurements_are_an_error(ctx):
    statuses = _statuses(ctx)
    make_node(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('input_timeout_s', value=0.3)])
    io = make_node(ctx, Node, 'io')
    pub = io.create_publisher(Float64, 'hyst_id/command', COMMAND_QOS)
    io.create_timer(0.05, lambda: pub.publish(Float64(data=9.0)))
    assert _spin_until(ctx, lambda: any(n == 'hyst_id: identifier' and lvl == 2
                                        and 'no measurement' in m for n, lvl, m in statuses),
                       timeout=10.0)


def test_qos_of_a_stream_is_overridable_from_a_params_file(ctx, tmp_path):
    params = tmp_path / 'qos.yaml'
    params.write_text('/**:\n  ros__parameters:\n    qos_overrides:\n'
                      '      /hyst_id/command:\n        publisher:\n'
                      '          history: keep_last\n          depth: 7\n')
    comp = make_node(ctx, Compensator, cli_args=['--ros-args', '--params-file', str(params)])
    assert comp._cmd_pub.qos_profile.depth == 7
    assert comp.unknown_parameters == []


def test_bypass_and_reset_services(ctx):
    pytest.importorskip('std_srvs')
    from std_srvs.srv import SetBool, Trigger
    comp = make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()])
    caller = make_node(ctx, Node, 'caller')
    bypass = caller.create_client(SetBool, 'compensator/bypass')
    reset = caller.create_client(Trigger, 'compensator/reset')
    assert _spin_until(ctx, lambda: bypass.service_is_ready() and reset.service_is_ready())
    future = bypass.call_async(SetBool.Request(data=True))
    assert _spin_until(ctx, future.done) and future.result().success
    assert comp.step(12.345) == 12.345                 # passed through
    future = bypass.call_async(SetBool.Request(data=False))
    assert _spin_until(ctx, future.done) and not comp._comp.bypass
    assert comp.step(12.345) != 12.345                 # compensated again
    future = reset.call_async(Trigger.Request())
    assert _spin_until(ctx, future.done) and 'reset' in future.result().message


def test_the_last_sets_warnings_stay_on_diagnostics(ctx):
    """A set published with warnings keeps the identifier's status at WARN, not one tick."""
    statuses = _statuses(ctx)
    ident = make_node(ctx, Identifier, parameter_overrides=FAST)
    ident.last_document = {'er_percent': 0.5, 'warnings': ['c_t is not identifiable']}

    def mine():
        return [s for s in statuses if s[0] == 'hyst_id: identifier']

    # three 1 Hz status ticks (over two seconds), every one of them WARN with the warning
    assert _spin_until(ctx, lambda: len(mine()) >= 3, timeout=10.0), statuses
    assert all(lvl == 1 and 'c_t is not identifiable' in m for _, lvl, m in mine()), mine()


def test_a_float64_command_publisher_is_an_error_at_a_stamped_actuator(ctx):
    statuses = _statuses(ctx)
    from hyst_id.nodes.actuator_driver import ActuatorDriver
    make_node(ctx, ActuatorDriver, parameter_overrides=[
        Parameter('topics.command_type', value='hyst_id_interfaces/msg/StampedValue')])
    with other_participant() as io:   # a wrong type can only come from elsewhere
        io.create_publisher(Float64, 'hyst_id/command', COMMAND_QOS)
        assert _spin_until(ctx, lambda: any(
            n == 'hyst_id: actuator_driver' and lvl == 2 and 'std_msgs/msg/Float64' in m
            for n, lvl, m in statuses), timeout=10.0), statuses


def test_kernels_are_warmed_before_traffic_and_before_a_swap(ctx, monkeypatch):
    """The compensator compiles a set's kernels before it subscribes and before it swaps."""
    import hyst_id.nodes.compensator as module
    events = []
    original = module.warm_up

    def warm(model):
        events.append(('warm', model.hysteresis[5]))     # c_r
        original(model)

    monkeypatch.setattr(module, 'warm_up', warm)
    real_subscribe = Compensator.create_subscription

    def subscribe(self, msg_type, topic, *args, **kwargs):
        events.append(('subscribe', topic))
        return real_subscribe(self, msg_type, topic, *args, **kwargs)

    monkeypatch.setattr(Compensator, 'create_subscription', subscribe)
    comp = make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()])
    assert events.index(('warm', 0.5)) < events.index(('subscribe', 'hyst_id/desired'))
    events.clear()
    swapped = []
    monkeypatch.setattr(comp._comp, 'set_model',
                        lambda model, f=comp._comp.set_model: (swapped.append(len(events)),
                                                               f(model)))
    assert comp.set_parameters([Parameter('c_r', value=0.6)])[0].successful
    assert events == [('warm', 0.6)] and swapped == [1]     # compiled, then swapped


#: A short bringup (every node, one channel) whose wiring, not fit, is tested.
TWO_GRAPHS = """
/**/bringup:
  ros__parameters:
    channel: {channel}
    time_scale: 20.0
    identify_duration_s: 30.0
    compensate_duration_s: 20.0
    bag: {bag}
    settle_s: 0.1
    timeout_s: 300.0
/**/identifier:
  ros__parameters:
    channel: {channel}
    generations: 60
    seeds: 2
    global_runs: 6
    hops: 0
    gate_max_floor_ratio: 0.0
    gate_max_uncertainty: 0.0
"""


@pytest.mark.slow
@pytest.mark.thorough
def test_two_whole_graphs_in_two_namespaces_do_not_cross(ros_domain, tmp_path):
    """Two bringup processes (every node of the graph each) on one domain, /valve1 and /valve2.

    Thorough tier: the default run checks two namespaced valves in one process
    (``test_two_namespaced_valves_do_not_cross``) and every topic of a whole graph in
    its namespace (``test_bringup_runs_stamped_streams_in_a_namespace``); two whole
    graphs on one domain at once run in ``./run test-all`` only.

    Each bag holds its own namespace's streams only, with exactly its own run's
    samples (301 + 41 + 41 commands): a topic shared across the namespaces would
    show the other graph's samples too.
    """
    import os
    import re
    import subprocess
    import sys

    from hyst_id.io.bag import open_bag

    procs = {}
    for valve, channel in (('valve1', 'position'), ('valve2', 'pressure')):
        params = tmp_path / f'{valve}.yaml'
        params.write_text(TWO_GRAPHS.format(channel=channel, bag=tmp_path / f'bag_{valve}'))
        procs[valve] = subprocess.Popen(
            [sys.executable, '-m', 'hyst_id.nodes.bringup', '--ros-args', '--params-file',
             str(params), '-r', f'__ns:=/{valve}'],
            env=dict(os.environ, ROS_HOME=str(tmp_path / valve)), stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True)
    outs = {v: p.communicate(timeout=600)[0] for v, p in procs.items()}
    for valve, proc in procs.items():
        figures = re.findall(r'(uncompensated|compensated)\s+([0-9.]+) %', outs[valve])
        assert proc.returncode == 0 and len(figures) == 2, outs[valve][-3000:]
        with open_bag(tmp_path / f'bag_{valve}') as bag:
            assert all(t.startswith(f'/{valve}/') for t in bag.topics), bag.topics
            assert bag.counts[f'/{valve}/hyst_id/command'] == 301 + 41 + 41, bag.counts
            assert bag.counts[f'/{valve}/hyst_id/desired'] == 41, bag.counts
