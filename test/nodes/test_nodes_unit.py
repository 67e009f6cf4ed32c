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

"""The ROS nodes in-process: defaults, parameter validation, compensator swaps, I/O.

Each test gets its own rclpy context and ROS domain (localhost discovery).
"""

from __future__ import annotations

import json
import math

from conftest import make_node, spin_nodes_until
import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')

from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402

from hyst_id.compensation.params_file import (  # noqa: E402
    command_limits_for,
    COMPENSATOR_NAMES,
    read_compensator_params,
    write_compensator_params,
)
from hyst_id.errors import ConfigError, RecordingError  # noqa: E402
from hyst_id.identification import identify  # noqa: E402
from hyst_id.identification.chains import chain_spec  # noqa: E402
from hyst_id.io.bag import (  # noqa: E402
    BagWriter, iter_bag_messages, open_bag, write_recording_bag)
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.live import pair_streams  # noqa: E402
from hyst_id.nodes.actuator_driver import (  # noqa: E402
    ActuatorDriver,
    PAPER_BACKLASH,
    PAPER_HYSTERESIS,
    SimulatedActuator,
)
from hyst_id.nodes.bringup import control_error_percent  # noqa: E402
from hyst_id.nodes.compensator import Compensator  # noqa: E402
from hyst_id.nodes.excitation import Excitation  # noqa: E402
from hyst_id.nodes.identifier import Identifier  # noqa: E402
from hyst_id.nodes.pipeline_sim import PipelineSim  # noqa: E402
from hyst_id.nodes.recorder import Recorder  # noqa: E402
from hyst_id.nodes.replay import Replay  # noqa: E402
from hyst_id.nodes.support import LATCHED_QOS  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402

pytestmark = pytest.mark.ros

PAPER = {**PAPER_HYSTERESIS, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}


_make = make_node


def _spin_until(ctx, nodes, predicate, timeout=10.0):
    return spin_nodes_until(ctx[0], nodes, predicate, timeout)


def _set(node, **values):
    return node.set_parameters_atomically([Parameter(k, value=v) for k, v in values.items()])


# ------------------------------------------------------------------ construction
def test_every_node_starts_with_defaults(ctx, tmp_path):
    bag = write_recording_bag(tmp_path / 'tiny', Recording(
        np.arange(30) * 0.1, 9 + np.sin(np.arange(30)), np.arange(30) * 1.0, 'position'))
    nodes = [
        _make(ctx, ActuatorDriver), _make(ctx, PipelineSim), _make(ctx, Excitation),
        _make(ctx, Identifier), _make(ctx, Compensator),
        _make(ctx, Recorder, parameter_overrides=[
            Parameter('output', value=str(tmp_path / 'rec'))]),
        _make(ctx, Replay, parameter_overrides=[Parameter('bag', value=str(bag)),
                                                Parameter('shutdown_when_done', value=False)]),
    ]
    for node in nodes:
        names = list(node._param_table)
        for desc in node.describe_parameters(names):
            assert desc.description, f'{node.get_name()}.{desc.name} has no description'
        assert node.get_parameter('use_sim_time').value is False
    comp = nodes[4]
    assert comp.model is None
    assert comp.step(9.5) == 9.5                 # pass-through with no parameter set
    assert comp.step(30.0) == 20.0               # ... within the command limits


def test_the_rig_loader_knows_the_pipeline_sim_nodes_parameters():
    """A rig file's section may hold the node's own scalars; any other scalar is refused."""
    from hyst_id.nodes.pipeline_sim import PARAMS as SIM_PARAMS
    from hyst_id.rig.params_file import NODE_SCALARS
    own = {p.name for p in SIM_PARAMS if '.' not in p.name}
    assert own <= NODE_SCALARS, sorted(own - NODE_SCALARS)


def test_defaults_match_the_params_files():
    """params/<node>.yaml holds exactly the built-in defaults, under /** (any namespace)."""
    import importlib
    from pathlib import Path

    import yaml
    root = Path(__file__).resolve().parents[2] / 'params'
    for name in ('actuator_driver', 'pipeline_sim', 'excitation', 'identifier', 'compensator',
                 'recorder', 'replay'):
        mod = importlib.import_module(f'hyst_id.nodes.{name}')
        doc = yaml.safe_load((root / f'{name}.yaml').read_text())['/**']['ros__parameters']
        flat = {k: v for k, v in doc.items() if not isinstance(v, dict)}
        for group, nested in doc.items():        # topics:, tracking:, ...
            if isinstance(nested, dict):
                flat.update({f'{group}.{k}': v for k, v in nested.items()})
        table = {p.name: p.default for p in mod.PARAMS}
        assert set(flat) == set(table), name
        for key, default in table.items():
            if isinstance(default, float) and math.isnan(default):
                assert math.isnan(flat[key]), (name, key)
            else:
                assert flat[key] == default and type(flat[key]) is type(default), (name, key)


# ------------------------------------------------------------------ validation
@pytest.mark.parametrize('cls, values, needle', [
    (Compensator, {'min_command': 25.0}, 'min_command'),
    (Compensator, {'diagnostics_period_s': 0.0}, 'diagnostics_period_s'),
    (Compensator, {'channel': 'torque'}, 'one of'),
    (Compensator, {'topics.command_topic': '/x'}, 'read-only'),
    (Compensator, {'output_sign': 0.5}, 'output_sign'),
    (Compensator, {'er_percent': -5.0}, 'er_percent'),
    (Compensator, {**PAPER, 'c_l': 0.9}, 'not proper'),
    (Compensator, {**PAPER, 'm_t': 2.0}, 'm_t'),
    (Compensator, {**PAPER, 'm_l': math.inf}, 'finite'),
    (ActuatorDriver, {'m_b': 1.5}, 'm_b'),
    (Excitation, {'profile': 'square'}, 'one of'),
    (Excitation, {'hold_s': -1.0}, 'hold_s'),
    # eq24 (9 +- 2 mA, decaying) peaks at 10.99 mA: a limit of 10.5 refuses it
    (Excitation, {'max_command': 10.5}, 'leaves the command limits [-1e+06, 10.5]'),
    (Excitation, {'min_command': 12.0, 'max_command': 11.0}, 'must be below max_command'),
    (Excitation, {'profile': 'steps', 'min_command': 7.2}, 'leaves the command limits'),
    (Identifier, {'domains': '/no/such/domains.yaml'}, 'domains'),
    (Identifier, {'pop_size': 1}, 'pop_size'),
    (Identifier, {'hops': -1}, 'hops'),
    (Identifier, {'min_samples': 5000000}, 'must not exceed max_samples'),
    (Compensator, {'initial_command': 100.0}, 'initial_command (100) must lie within'),
    (Identifier, {'model': 'preisach'}, 'one of'),
    (Identifier, {'model': 'smooth', 'domains': 'paper'}, 'paper'),
    (Identifier, {'model': 'auto', 'domains': 'paper'}, 'domains must be auto'),
])
def test_bad_parameters_are_rejected_with_a_reason(ctx, cls, values, needle):
    node = _make(ctx, cls)
    before = node.param_values()
    result = _set(node, **values)
    assert not result.successful
    assert needle in result.reason, result.reason
    assert node.param_values().keys() == before.keys()
    for key in values:
        a, b = node.p(key), before[key]
        assert a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))


def test_channel_changes_only_with_a_new_set(ctx):
    comp = _make(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in PAPER.items()])
    result = _set(comp, channel='pressure')
    assert not result.successful and 'together with a new parameter set' in result.reason
    assert comp.p('channel') == 'position'
    assert _set(comp, channel='pressure', **{**PAPER, 'c_br': 0.3}).successful
    assert comp.p('channel') == 'pressure' and comp.p('c_br') == 0.3


def test_bad_params_file_is_a_one_line_config_error(ros_domain, tmp_path):
    bad_value = tmp_path / 'bad.yaml'
    bad_value.write_text('compensator:\n  ros__parameters:\n' + ''.join(
        f'    {k}: {float(v)!r}\n' for k, v in {**PAPER, 'c_l': 0.9}.items()))
    bad_type = tmp_path / 'type.yaml'
    bad_type.write_text('compensator:\n  ros__parameters:\n    max_command: high\n')
    empty = tmp_path / 'empty.yaml'      # an empty list has no type in ROS 2: not initialised
    empty.write_text('/**:\n  ros__parameters:\n    topics: []\n')
    bad_topic = tmp_path / 'topic.yaml'
    bad_topic.write_text('/**:\n  ros__parameters:\n    topics:\n      desired_topic: a-b\n')
    for cls, path, needle in ((Compensator, bad_value, 'not proper'),
                              (Compensator, bad_type, 'double'),
                              (Recorder, empty, 'topics is given no value'),
                              (Compensator, bad_topic, "'a-b' is not a ROS topic name")):
        context = rclpy.Context()
        rclpy.init(args=['--ros-args', '--params-file', str(path)], context=context)
        try:
            with pytest.raises(ConfigError, match=needle) as info:
                cls(context=context)
            assert '\n' not in str(info.value)
        finally:
            context.try_shutdown()


def test_a_whole_number_for_a_double_is_taken(ros_domain, tmp_path, ctx):
    path = tmp_path / 'whole.yaml'
    path.write_text('compensator:\n  ros__parameters:\n    max_command: 19\n')
    context = rclpy.Context()
    rclpy.init(args=['--ros-args', '--params-file', str(path), '-p', 'min_command:=5'],
               context=context)
    try:
        comp = Compensator(context=context)
        assert (comp.p('max_command'), comp.p('min_command')) == (19.0, 5.0)
        assert isinstance(comp.p('max_command'), float)
        comp.destroy_node()
    finally:
        context.try_shutdown()
    live = _make(ctx, Compensator)
    assert _set(live, max_command=18).successful
    assert live.p('max_command') == 18.0 and isinstance(live.p('max_command'), float)
    result = _set(live, max_command=3)  # below min_command: validated like a double
    assert not result.successful, result.reason
    # an integer parameter still refuses a double, and a double a string
    ident = _make(ctx, Identifier)
    assert not _set(ident, pop_size=40.0).successful
    assert not _set(live, max_command='19').successful


def test_a_set_of_an_actuator_outside_4_20_brings_its_command_limits(ros_domain, tmp_path):
    """A set identified in volts (``--params-out``): the node clamps to its range, not 4-20."""
    assert command_limits_for(np.linspace(7.0, 11.0, 5)) is None      # the defaults fit
    limits = command_limits_for(np.array([0.0, -150.0, 150.0]))
    assert limits == (-150.0, 150.0, 0.0)
    path = write_compensator_params({'channel': 'position', 'params': dict(PAPER)},
                                    tmp_path / 'c.yaml', command_limits=limits)
    with pytest.raises(ConfigError, match='finite min < max'):
        write_compensator_params({'params': dict(PAPER)}, tmp_path / 'x.yaml',
                                 command_limits=(1.0, 1.0))
    with pytest.raises(ConfigError, match='got 4 values'):
        write_compensator_params({'params': dict(PAPER)}, tmp_path / 'y.yaml',
                                 command_limits=(0.0, 5.0, 1.0, 2.0))
    two = write_compensator_params({'params': dict(PAPER)}, tmp_path / 'z.yaml',
                                   command_limits=(0.0, 5.0))   # limits, no first command
    assert 'max_command: 5.0' in two.read_text() and 'initial_command' not in two.read_text()
    assert read_compensator_params(path)['m_l'] == PAPER['m_l']
    context = rclpy.Context()
    rclpy.init(args=['--ros-args', '--params-file', str(path)], context=context)
    try:
        comp = Compensator(context=context)
        try:
            assert (comp.p('min_command'), comp.p('max_command'),
                    comp.p('initial_command')) == (-150.0, 150.0, 0.0)
        finally:
            comp.destroy_node()
    finally:
        context.try_shutdown()


def test_node_main_reports_bad_input_in_one_line(ros_domain, tmp_path, capfd):
    from hyst_id.nodes import replay
    assert replay.main(['--ros-args', '-p', f'bag:={tmp_path / "missing"}']) == 2
    junk = tmp_path / 'junk.mcap'
    junk.write_bytes(b'not a bag at all')
    assert replay.main(['--ros-args', '-p', f'bag:={junk}']) == 2
    with BagWriter(tmp_path / 'empty') as bag:      # topics, no messages: not a success
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
    assert replay.main(['--ros-args', '-p', f'bag:={tmp_path / "empty"}']) == 2
    cut = tmp_path / 'cut.mcap'                      # the remedy spelled as a node parameter
    whole = tmp_path / 'whole'
    write_recording_bag(whole, Recording(np.arange(400) * 0.05, np.sin(np.arange(400) * 0.1),
                                         np.cos(np.arange(400) * 0.1), 'position'))
    data = next(whole.glob('*.mcap')).read_bytes()
    cut.write_bytes(data[:len(data) // 2])
    assert replay.main(['--ros-args', '-p', f'bag:={cut}']) == 2
    err = capfd.readouterr()
    text = err.out + err.err
    assert 'Traceback' not in text
    assert 'no such file' in text and 'cannot read bag' in text
    assert 'its topics hold no messages (/hyst_id/command): nothing to replay' in text
    assert '-p recover_truncated:=true' in text and 'recover_truncated=True' not in text


def test_a_refused_set_parameters_is_logged_in_words(ctx, capfd):
    """An unknown name or a wrong type is said in the log (rclpy's answer names neither)."""
    from rclpy.exceptions import ParameterNotDeclaredException
    comp = _make(ctx, Compensator)
    with pytest.raises(ParameterNotDeclaredException):
        comp.set_parameters([Parameter('max_comand', value=1.0)])
    result = comp.set_parameters([Parameter('max_command', value='high')])[0]
    assert not result.successful
    text = ''.join(capfd.readouterr())
    assert 'set_parameters: max_comand refused, compensator has no such parameter' in text
    assert "max_command refused, it is a double and was given a string ('high')" in text


# ------------------------------------------------------------------ compensator
def test_compensator_swaps_valid_sets_and_keeps_the_last_good(ctx):
    comp = _make(ctx, Compensator)
    assert _set(comp, **PAPER).successful
    good = comp.model
    assert good is not None and good.hysteresis[0] == PAPER['m_l']
    out = comp.step(9.5)
    assert 4.0 <= out <= 20.0 and out != 9.5
    bad = _set(comp, **{**PAPER, 'c_l': 0.9, 'c_r': 0.5})
    assert not bad.successful and 'keeping the last good set' in bad.reason
    assert comp.model is good
    partial = _set(comp, m_l=math.nan)
    assert not partial.successful and 'incomplete' in partial.reason
    assert comp.model is good
    assert _set(comp, **{**PAPER, 'c_r': 0.6}).successful
    assert comp.model is not good and comp.model.hysteresis[5] == 0.6
    assert _set(comp, max_command=9.2).successful
    assert comp.step(15.0) <= 9.2
    assert _set(comp, **{n: math.nan for n in COMPENSATOR_NAMES}).successful
    assert comp.model is None
    assert comp.step(9.1) == 9.1


def test_compensator_incomplete_set_from_pass_through_is_accepted(ctx):
    comp = _make(ctx, Compensator)
    assert _set(comp, m_l=1.0).successful        # building a set one value at a time
    assert comp.model is None
    rest = {k: v for k, v in PAPER.items() if k != 'm_l'}
    assert _set(comp, **rest).successful
    assert comp.model is not None


def test_compensator_follows_the_latched_identified_params(ctx):
    comp = _make(ctx, Compensator)
    talker = _make(ctx, Node, 'talker')
    pub = talker.create_publisher(String, '/hyst_id/identified_params', LATCHED_QOS)
    pub.publish(String(data='{not json'))
    pub.publish(String(data=json.dumps({'channel': 'flow', 'params': PAPER})))
    assert not _spin_until(ctx, [comp, talker], lambda: comp.model is not None, timeout=1.5)
    bad = {**PAPER, 'c_l': 0.9}
    pub.publish(String(data=json.dumps({'channel': 'position', 'params': bad})))
    assert not _spin_until(ctx, [comp, talker], lambda: comp.model is not None, timeout=1.0)
    pub.publish(String(data=json.dumps({'channel': 'position', 'params': bad,
                                        'compensator_params': PAPER, 'er_percent': 1.5})))
    assert _spin_until(ctx, [comp, talker], lambda: comp.model is not None)
    assert comp.p('m_l') == PAPER['m_l'] and comp.p('er_percent') == 1.5


SMOOTH = {'family': 'smooth', 'w_0': 0.8, 'w_1': 0.4, 'w_2': 0.0, 'w_3': 0.3, 'w_4': 0.2,
          'w_5': 0.1, 'w_l': 0.05, 'r_max': 0.6, 'v_s': 3.0, 'v_c': 9.0, 'c_o': 9.0,
          'm_bl': 1.0, 'c_bl': -0.05, 'c_br': 0.05}


def test_compensator_swaps_between_families_atomically(ctx):
    """Either family runs in-line, with the same atomic swaps, limits and rejections."""
    comp = _make(ctx, Compensator)
    assert _set(comp, **PAPER).successful
    tk_model = comp.model
    assert _set(comp, **SMOOTH).successful
    assert comp.model is not tk_model and comp.model.family == 'smooth'
    smooth_model = comp.model
    bad = _set(comp, **{**SMOOTH, 'w_0': 0.0})
    assert not bad.successful and 'w_0' in bad.reason and 'keeping the last good' in bad.reason
    assert comp.model is smooth_model
    assert not _set(comp, w_l=math.inf).successful and comp.model is smooth_model
    missing = _set(comp, family='tk', **{n: math.nan for n in ('m_l', 'm_r')})
    assert not missing.successful and 'incomplete tk set' in missing.reason
    assert comp.model is smooth_model
    assert _set(comp, max_command=9.2).successful
    assert comp.step(15.0) <= 9.2
    assert not _set(comp, family='preisach').successful
    assert _set(comp, family='tk', **PAPER).successful and comp.model.family == 'tk'


def test_compensator_follows_identified_smooth_params(ctx):
    comp = _make(ctx, Compensator)
    talker = _make(ctx, Node, 'talker')
    pub = talker.create_publisher(String, '/hyst_id/identified_params', LATCHED_QOS)
    params = {k: v for k, v in SMOOTH.items() if k != 'family'}
    pub.publish(String(data=json.dumps({'channel': 'position', 'family': 'smooth',
                                        'compensator_params': params, 'er_percent': 0.7})))
    assert _spin_until(ctx, [comp, talker], lambda: comp.model is not None)
    assert comp.p('family') == 'smooth' and comp.p('w_3') == SMOOTH['w_3']
    assert comp.model.family == 'smooth'


def test_compensator_inverts_the_simulated_actuator(ctx):
    comp = _make(ctx, Compensator)
    assert _set(comp, **PAPER).successful
    act = SimulatedActuator(PAPER_HYSTERESIS, {'m_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25})
    t = np.arange(0, 60, 0.5)
    desired = 9.0 + np.sin(2 * np.pi * t / 12.0)
    act.apply(comp.step(desired[0]))
    out = np.array([act.apply(comp.step(d)) for d in desired])
    plain = SimulatedActuator(PAPER_HYSTERESIS, {'m_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25})
    raw = np.array([plain.apply(d) for d in desired])
    assert control_error_percent(out[10:], desired[10:]) < 1e-6
    assert control_error_percent(raw, desired) > 1.0


# ------------------------------------------------------------------ core of the nodes
def test_simulated_actuator_matches_the_chain():
    t = np.arange(0, 50, 0.1)
    v = eq24(t)
    act = SimulatedActuator(noise_std=0.0)
    y = np.array([act.apply(x) for x in v])
    x = np.array(list(PAPER_HYSTERESIS.values()) + list(PAPER_BACKLASH.values()))
    np.testing.assert_allclose(y, chain_spec('position').simulate(x, t, v), atol=1e-12)


def test_pair_streams_pairs_like_the_bag_reader(tmp_path):
    rng = np.random.default_rng(3)
    t = np.arange(200) * 0.05
    cmd = 9 + 2 * np.sin(t)
    meas = cmd * 0.5 + rng.normal(0, 0.01, t.size)
    rec = Recording(t, cmd, meas, 'position')
    bag = write_recording_bag(tmp_path / 'b', rec)
    from hyst_id.io.readers import read_recording
    read = read_recording(bag, 'position')
    cmd_ns = [], []
    meas_ns = [], []
    for topic, _, t_ns, msg in iter_bag_messages(bag):
        if topic == '/hyst_id/command':
            cmd_ns[0].append(t_ns)
            cmd_ns[1].append(msg.data)
        else:
            meas_ns[0].append(msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec)
            meas_ns[1].append(msg.position[0])
    live = pair_streams(np.array(cmd_ns[0]), np.array(cmd_ns[1]), np.array(meas_ns[0]),
                        np.array(meas_ns[1]), 'position')
    np.testing.assert_array_equal(live.command, read.command)
    np.testing.assert_array_equal(live.measurement, read.measurement)
    np.testing.assert_array_equal(live.t_s, read.t_s)
    # a measurement before the first command is dropped; the last command <= stamp wins
    r = pair_streams(np.array([10, 20, 30]), np.array([1.0, 2.0, 3.0]),
                     np.array([5, 10, 25, 40, 40]), np.array([0.0, 1.0, 2.5, 3.5, 3.6]),
                     'position')
    np.testing.assert_array_equal(r.command, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(r.measurement, [1.0, 2.5, 3.6])


def test_params_file_round_trip_and_errors(tmp_path):
    values = {'channel': 'pressure', 'params': dict(PAPER), 'er_percent': 2.5,
              'output_sign': -1.0}
    path = write_compensator_params(values, tmp_path / 'sub' / 'c.yaml')
    back = read_compensator_params(path)
    assert back['channel'] == 'pressure' and back['output_sign'] == -1.0
    assert all(back[n] == PAPER[n] for n in COMPENSATOR_NAMES) and back['er_percent'] == 2.5
    assert 'm_bl: 1.0\n' in path.read_text()       # doubles stay doubles for ROS
    with pytest.raises(ConfigError, match='missing compensator parameters: m_l'):
        write_compensator_params({k: v for k, v in PAPER.items() if k != 'm_l'}, path)
    with pytest.raises(ConfigError, match='no such file'):
        read_compensator_params(tmp_path / 'none.yaml')
    (tmp_path / 'bad.yaml').write_text('compensator: [1, 2')
    with pytest.raises(ConfigError, match='not valid YAML'):
        read_compensator_params(tmp_path / 'bad.yaml')


# ------------------------------------------------------------------ identifier
def _feed(ident: Identifier, n: int = 400, dt_ns: int = 50_000_000) -> Recording:
    t = np.arange(n) * dt_ns * 1e-9
    v = eq24(t)
    x = np.array(list(PAPER.values()))
    y = chain_spec('position').simulate(x, t, v)
    y = y + np.random.default_rng(0).normal(0, 0.005, n)
    t0 = 1_800_000_000 * 10**9
    for k in range(n):
        ident.buffer.add_command(t0 + k * dt_ns, v[k])
        ident.buffer.add_measurement(t0 + k * dt_ns + 1000, y[k])
    return Recording(t, v, y, 'position')


def _identify_now(ctx, out, timeout: float, **params):
    """An identifier fed a simulated run, triggered; its node, the run and the document."""
    ident = _make(ctx, Identifier, parameter_overrides=[
        Parameter(k, value=v) for k, v in params.items()] + [
        Parameter('params_out', value=str(out)), Parameter('end_of_run_timeout_s', value=0.0)])
    got = []
    listener = _make(ctx, Node, 'listener')
    listener.create_subscription(String, '/hyst_id/identified_params',
                                 lambda m: got.append(json.loads(m.data)), LATCHED_QOS)
    rec = _feed(ident)
    assert _set(ident, identify_now=True).successful
    assert _spin_until(ctx, [ident, listener], lambda: bool(got), timeout=timeout)
    return ident, rec, got[-1]


def test_identifier_identify_now_publishes_writes_and_matches_identify(ctx, tmp_path):
    out = tmp_path / 'comp.yaml'
    ident, rec, doc = _identify_now(ctx, out, 120.0, seeds=2, generations=40, domains='paper',
                                    global_runs=6, hops=0)
    # identify's global phase and hopping are the node's parameters too
    assert (ident.settings().global_runs, ident.settings().hops) == (6, 0)
    assert ident.settings().global_evals == 200000
    assert doc['channel'] == 'position' and doc['n_samples'] == rec.n_samples
    assert doc['er_percent'] < 1.0
    assert ident.p('identify_now') is False
    assert read_compensator_params(out)['m_l'] == doc['compensator_params']['m_l']
    ref = identify(rec, settings=ident.settings(), spec=chain_spec('position'))
    assert ref.params == doc['params']


def test_identifier_model_auto_chooses_and_reports_the_family(ctx, tmp_path):
    out = tmp_path / 'comp.yaml'
    _, _, doc = _identify_now(ctx, out, 300.0, seeds=1, generations=40, model='auto')
    choice = doc['model_choice']
    assert {f['family'] for f in choice['families']} == {'tk', 'smooth'}
    assert doc['family'] == choice['chosen']
    assert read_compensator_params(out)['family'] == choice['chosen']


def test_identifier_refuses_with_a_reason(ctx):
    ident = _make(ctx, Identifier)
    ok, message = ident.request_identification('test')
    assert not ok and 'only 0 samples' in message
    t0 = 10**18
    for k in range(100):                        # constant command: nothing excited
        ident.buffer.add_command(t0 + k * 10**7, 9.0)
        ident.buffer.add_measurement(t0 + k * 10**7 + 1, 9.0)
    ok, message = ident.request_identification('test')
    assert not ok and 'constant' in message
    assert ident.last_error


def test_identifier_trigger_service(ctx):
    pytest.importorskip('std_srvs')
    from std_srvs.srv import Trigger
    ident = _make(ctx, Identifier)
    client_node = _make(ctx, Node, 'caller')
    client = client_node.create_client(Trigger, '/identifier/identify')
    assert _spin_until(ctx, [ident, client_node], client.service_is_ready, timeout=5.0)
    future = client.call_async(Trigger.Request())
    assert _spin_until(ctx, [ident, client_node], future.done, timeout=5.0)
    assert not future.result().success and 'samples' in future.result().message


# ------------------------------------------------------------------ I/O nodes
def test_excitation_publishes_the_profile_samples(ctx):
    exc = _make(ctx, Excitation, parameter_overrides=[
        Parameter('duration_s', value=2.0), Parameter('time_scale', value=100.0),
        Parameter('wait_for_subscribers', value=1)])
    got = []
    sink = _make(ctx, Node, 'sink')
    sink.create_subscription(Float64, '/hyst_id/command', lambda m: got.append(m.data), 100)
    assert _spin_until(ctx, [exc, sink], lambda: exc.finished and len(got) == 21)
    np.testing.assert_allclose(got, eq24(np.arange(21) * 0.1), rtol=0, atol=1e-15)


def test_excitation_refuses_a_profile_outside_its_command_limits(ctx):
    """A start that would publish outside min/max_command fails with the sample; inside runs."""
    with pytest.raises(ConfigError, match=r'leaves the command limits \[8, 10\]: .* at t ='):
        Excitation(context=ctx[0], parameter_overrides=[
            Parameter('min_command', value=8.0), Parameter('max_command', value=10.0)])
    exc = _make(ctx, Excitation, parameter_overrides=[
        Parameter('min_command', value=6.9), Parameter('max_command', value=11.1),
        Parameter('duration_s', value=2.0), Parameter('time_scale', value=100.0),
        Parameter('wait_for_subscribers', value=1)])
    assert not _set(exc, amplitude_ma=3.0).successful      # 9 +- 3 leaves [6.9, 11.1]
    got = []
    sink = _make(ctx, Node, 'sink')
    sink.create_subscription(Float64, '/hyst_id/command', lambda m: got.append(m.data), 100)
    assert _spin_until(ctx, [exc, sink], lambda: exc.finished and len(got) == 21)
    np.testing.assert_allclose(got, eq24(np.arange(21) * 0.1), rtol=0, atol=1e-15)


def test_excitation_clips_a_value_between_its_checked_samples(ctx, monkeypatch):
    """The last guard: a value outside the limits (unchecked sample) goes out clipped, WARN."""
    exc = _make(ctx, Excitation, parameter_overrides=[
        Parameter('max_command', value=11.0), Parameter('duration_s', value=0.5),
        Parameter('time_scale', value=100.0), Parameter('wait_for_subscribers', value=1)])
    monkeypatch.setattr(exc, '_profile', lambda t_s: 12.0 if t_s > 0.25 else 9.0)
    status = []
    monkeypatch.setattr(exc, 'publish_diagnostics',
                        lambda level, msg, values=None: status.append((level, msg)))
    got = []
    sink = _make(ctx, Node, 'sink')
    sink.create_subscription(Float64, '/hyst_id/command', lambda m: got.append(m.data), 100)
    assert _spin_until(ctx, [exc, sink], lambda: exc.finished and len(got) == 6)
    assert got == [9.0, 9.0, 9.0, 11.0, 11.0, 11.0]
    exc._status()
    assert status[-1][0] == 1 and '3 value(s) clipped to [-1e+06, 11]' in status[-1][1]


def test_recorder_writes_a_readable_bag(ctx, tmp_path):
    rec = _make(ctx, Recorder, namespace='/valve1', parameter_overrides=[
        Parameter('output', value=str(tmp_path / 'bag')),
        Parameter('topics', value=['hyst_id/command', '/hyst_id/position', 'latched'])])
    talker = _make(ctx, Node, 'talker', namespace='/valve1')
    pub = talker.create_publisher(Float64, 'hyst_id/command', 100)
    talker.create_publisher(Float64, 'latched', LATCHED_QOS).publish(Float64(data=1.0))
    # relative names are recorded in the recorder's namespace, absolute ones as given
    assert rec._wanted == ['/valve1/hyst_id/command', '/hyst_id/position', '/valve1/latched']
    assert _spin_until(ctx, [rec, talker], lambda: {'/valve1/hyst_id/command',
                                                    '/valve1/latched'} <= set(rec.subscribed))
    assert _spin_until(ctx, [rec, talker], lambda: pub.get_subscription_count() > 0)
    for k in range(20):
        pub.publish(Float64(data=float(k)))
    assert _spin_until(ctx, [rec, talker],
                       lambda: rec.counts['/valve1/hyst_id/command'] == 20)
    rec.close()
    rows = list(iter_bag_messages(tmp_path / 'bag', topics=['/valve1/hyst_id/command']))
    assert [m.data for _, _, _, m in rows] == [float(k) for k in range(20)]
    meta = (tmp_path / 'bag' / 'metadata.yaml').read_text()
    assert 'ros_distro: rosbags' not in meta and 'offered_qos_profiles' in meta
    with open_bag(tmp_path / 'bag') as bag:             # the latched topic replays latched
        assert bag.latched == {'/valve1/latched'}
    with pytest.raises(RecordingError, match='cannot create bag'):
        Recorder(context=ctx[0], parameter_overrides=[
            Parameter('output', value=str(tmp_path / 'bag'))])


def test_control_error_percent_is_eq26():
    assert control_error_percent([1.0, 2.0], [1.0, 2.0]) == 0.0
    assert control_error_percent([1.1, 2.0], [1.0, 2.0]) == pytest.approx(
        100 * math.sqrt(0.01 / 5.0))


def test_replay_says_when_nothing_subscribes_yet(ctx, tmp_path, monkeypatch):
    """Without wait_for_subscribers a replay to topics nobody listens to warns (data lost)."""
    t = np.arange(20) * 0.1
    bag = write_recording_bag(tmp_path / 'src', Recording(t, 9 + np.sin(t), t, 'position'))
    said: list[str] = []
    play = _make(ctx, Replay, parameter_overrides=[
        Parameter('bag', value=str(bag)), Parameter('rate', value=20.0),
        Parameter('start_delay_s', value=1.0), Parameter('shutdown_when_done', value=False)])
    monkeypatch.setattr(play.get_logger(), 'warning', lambda m, **kw: said.append(m))
    _spin_until(ctx, [play], lambda: bool(said), timeout=10.0)
    assert said and 'nothing subscribes to' in said[0] and 'wait_for_subscribers' in said[0]
    assert '/hyst_id/command' in said[0]


@pytest.mark.parametrize('sim_time', [True, False])
def test_replay_clock_keeps_bag_time_at_any_rate(ctx, tmp_path, sim_time):
    """Unstamped commands replayed at rate 4 keep their 0.1 s spacing for a sim-time node."""
    t = np.arange(60) * 0.1
    bag = write_recording_bag(tmp_path / 'src', Recording(t, 9 + np.sin(t), t, 'position'))
    rec = _make(ctx, Recorder, parameter_overrides=[
        Parameter('output', value=str(tmp_path / 'rec')),
        Parameter('use_sim_time', value=sim_time),
        Parameter('topics', value=['/hyst_id/command'])])
    play = _make(ctx, Replay, parameter_overrides=[
        Parameter('bag', value=str(bag)), Parameter('rate', value=4.0),
        Parameter('topics', value=['/hyst_id/command']),
        Parameter('wait_for_subscribers', value=1), Parameter('shutdown_when_done', value=False)])
    _spin_until(ctx, [rec, play], lambda: rec.counts.get('/hyst_id/command') == 60,
                timeout=20.0)
    assert rec.counts.get('/hyst_id/command') == 60, (rec.counts, play.published)
    rec.close()
    stamps = np.array([t_ns for _, _, t_ns, _ in iter_bag_messages(tmp_path / 'rec')]) * 1e-9
    spacing = float(np.median(np.diff(stamps)))
    if sim_time:     # the bag's time (a message may take the previous clock tick: one sample)
        assert spacing == pytest.approx(0.1, abs=0.01)
        assert stamps[-1] - stamps[0] == pytest.approx(5.9, abs=0.25)
    else:            # arrival time: four times faster
        assert spacing == pytest.approx(0.025, abs=0.01)


def test_a_push_to_an_invalid_node_name_is_logged_and_dropped(ctx, monkeypatch):
    """The pusher never raises into the executor: a bad target is an ERROR log, not a crash."""
    from hyst_id.nodes.support.pusher import ParameterPusher
    node = _make(ctx, Node, 'pusher_host')
    said: list[str] = []
    monkeypatch.setattr(node.get_logger(), 'error', lambda m, **kw: said.append(m))
    pusher = ParameterPusher(node)
    pusher.push('bad name!', [Parameter('m_l', value=1.0)], timeout_s=1.0)
    pusher.poll()
    assert said and 'cannot push the parameters to bad name!' in said[0]
    assert pusher._pending is None


def test_recorder_follows_a_best_effort_publisher_and_names_a_second_type(ctx, tmp_path):
    """A best-effort publisher joining a reliable one is recorded; a second type is an ERROR.

    Before, the recorder kept the first QoS and type it saw: every message of a
    best-effort publisher joining a reliable one, and a Float64 stream after a String
    publisher, were lost without a word (found by an independent review). Fast DDS
    takes one type per topic in a process, so the second type is named, not recorded.
    """
    rec = _make(ctx, Recorder, parameter_overrides=[
        Parameter('output', value=str(tmp_path / 'bag')),
        Parameter('topics', value=['/mixed', '/joined'])])
    talker = _make(ctx, Node, 'talker')
    text = talker.create_publisher(String, '/mixed', 10)
    reliable = talker.create_publisher(Float64, '/joined', 10)
    assert _spin_until(ctx, [rec, talker], lambda: {'/mixed', '/joined'} <= set(rec.subscribed))
    other = rclpy.Context()      # one participant cannot publish two types on a topic
    rclpy.init(context=other)
    try:
        stranger = Node('stranger', context=other)
        stranger.create_publisher(Float64, '/mixed', 10)
        best = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
        loose = talker.create_publisher(Float64, '/joined', best)
        assert _spin_until(ctx, [rec, talker], lambda: loose.get_subscription_count() > 0
                           and rec.not_recorded, timeout=15.0), rec.not_recorded
        assert list(rec.not_recorded) == ['/mixed (std_msgs/msg/Float64)']
        assert 'one type per topic' in rec.not_recorded['/mixed (std_msgs/msg/Float64)']
        text.publish(String(data='hello'))
        for k in range(10):
            reliable.publish(Float64(data=100.0 + k))
            loose.publish(Float64(data=200.0 + k))
        assert _spin_until(ctx, [rec, talker], lambda: rec.counts['/mixed'] == 1
                           and rec.counts['/joined'] == 20), rec.counts
        stranger.destroy_node()
    finally:
        other.try_shutdown()
    rec.close()
    rows = list(iter_bag_messages(tmp_path / 'bag', topics=['/joined']))
    assert sorted(m.data for _, _, _, m in rows) == [100.0 + k for k in range(10)] + [
        200.0 + k for k in range(10)]


def test_status_names_carry_the_namespace(ctx):
    """Two valves' compensators report apart on /diagnostics (both were 'hyst_id: compensator')."""
    assert _make(ctx, Compensator, namespace='/rig1').status_name == 'rig1/compensator'
    assert _make(ctx, Excitation).status_name == 'excitation'


def test_a_resubscription_does_not_record_a_latched_message_twice(ctx, tmp_path):
    """The new subscription gets a latched topic's history again; it is written once.

    A volatile publisher joining a latched one makes the recorder subscribe volatile;
    when it leaves, the recorder subscribes latched again, and the latched message,
    recorded already, arrives again on the new subscription: dropped as a repeat.
    """
    rec = _make(ctx, Recorder, parameter_overrides=[
        Parameter('output', value=str(tmp_path / 'bag')),
        Parameter('topics', value=['/params'])])
    talker = _make(ctx, Node, 'talker')
    talker.create_publisher(String, '/params', LATCHED_QOS).publish(String(data='first'))
    assert _spin_until(ctx, [rec, talker], lambda: rec.counts.get('/params') == 1)
    volatile = talker.create_publisher(String, '/params', 10)
    assert _spin_until(ctx, [rec, talker], lambda: volatile.get_subscription_count() > 0,
                       timeout=15.0)
    talker.destroy_publisher(volatile)
    stream = rec._subs[('/params', 'std_msgs/msg/String')]
    assert _spin_until(ctx, [rec, talker], lambda: stream.qos.durability
                       == LATCHED_QOS.durability, timeout=15.0)
    _spin_until(ctx, [rec, talker], lambda: False, timeout=1.0)    # the history arrives
    assert rec.counts['/params'] == 1
    rec.close()
    rows = list(iter_bag_messages(tmp_path / 'bag', topics=['/params']))
    assert [m.data for _, _, _, m in rows] == ['first']


def test_the_identifier_node_searches_proper_loops_only():
    # its sets go to the compensator, which inverts proper loops only (test_loose_loops.py)
    from hyst_id.nodes.support.identifier_params import identify_settings, PARAMS
    defaults = {q.name: q.default for q in PARAMS}
    assert identify_settings(defaults.__getitem__).loose_loops is False
