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

"""The identifier node in-process (issues 5 and 6): bad samples, failures, restarts, diagnosis.

* samples out of order are sorted, gaps reported in the result's notes; a
  gap too long to be one run refuses the run with the reason;
* a failed or cancelled identification leaves the last published parameters
  in place (latched topic, params file);
* a restarted node republishes the set of the params file it wrote, and a
  compensator following the topic takes it;
* ``~/diagnose`` / ``diagnose_now`` diagnose in a worker thread and publish
  one ``/diagnostics`` status per finding and the latched ``~/diagnosis`` JSON.
"""

from __future__ import annotations

import json

from conftest import make_node, spin_nodes_until
import numpy as np
import pytest

rclpy = pytest.importorskip('rclpy')

from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import String  # noqa: E402

from hyst_id.compensation.params_file import write_compensator_params  # noqa: E402
from hyst_id.errors import IdentificationError  # noqa: E402
from hyst_id.identification.chains import chain_spec  # noqa: E402
from hyst_id.nodes.compensator import Compensator  # noqa: E402
from hyst_id.nodes.identifier import Identifier  # noqa: E402
from hyst_id.nodes.support import LATCHED_QOS  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402

pytestmark = pytest.mark.ros

PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}
FAST = [Parameter('seeds', value=1), Parameter('generations', value=30),
        Parameter('domains', value='paper'), Parameter('end_of_run_timeout_s', value=0.0),
        Parameter('compensator_node', value='')]


_make = make_node


def _spin_until(ctx, predicate, timeout=10.0):
    return spin_nodes_until(ctx[0], ctx[1], predicate, timeout)


def _samples(n=400, dt_ns=50_000_000, drift_per_s=0.0):
    t = np.arange(n) * dt_ns * 1e-9
    v = eq24(t)
    y = chain_spec('position').simulate(np.array(list(PAPER.values())), t, v)
    y = y + np.random.default_rng(0).normal(0, 0.005, n) + drift_per_s * t
    t0 = 1_800_000_000 * 10**9
    return t0 + np.arange(n) * dt_ns, v, y


def _feed(ident, stamps, v, y, order=None):
    for k in (range(len(stamps)) if order is None else order):
        ident.buffer.add_command(int(stamps[k]), v[k])
        ident.buffer.add_measurement(int(stamps[k]) + 1000, y[k])


def _listen(ctx, topic='/hyst_id/identified_params', name='listener'):
    got = []
    node = _make(ctx, Node, name)
    node.create_subscription(String, topic, lambda m: got.append(json.loads(m.data)),
                             LATCHED_QOS)
    return got


def _recovered(ctx, tmp_path, **extra):
    """An identifier that recovered PAPER (%e_r 0.5) from its params file."""
    out = tmp_path / 'comp.yaml'
    write_compensator_params({'channel': 'position', 'params': PAPER, 'er_percent': 0.5}, out)
    overrides = FAST + [Parameter('params_out', value=str(out))]
    overrides += [Parameter(k, value=v) for k, v in extra.items()]
    ident = _make(ctx, Identifier, parameter_overrides=overrides)
    assert ident.last_document['er_percent'] == 0.5
    return ident, out


def test_out_of_order_samples_are_sorted_and_gaps_reported(ctx):
    ident = _make(ctx, Identifier, parameter_overrides=FAST)
    stamps, v, y = _samples()
    keep = np.r_[0:150, 180:400]                            # 30 samples lost
    order = keep[np.random.default_rng(2).permutation(keep.size)]
    _feed(ident, stamps, v, y, order)
    got = _listen(ctx)
    assert ident.set_parameters([Parameter('identify_now', value=True)])[0].successful
    assert _spin_until(ctx, lambda: bool(got), timeout=120.0), ident.last_error
    doc = got[-1]
    assert doc['n_samples'] == 370 and doc['er_percent'] < 1.0
    assert any('out of order' in n for n in doc['notes']), doc['notes']
    assert any('gap' in n and 'about 30 samples missing' in n for n in doc['notes'])


def test_a_gap_too_long_for_one_run_is_refused_and_the_last_set_stays(ctx, tmp_path):
    ident, out = _recovered(ctx, tmp_path)
    before = out.read_bytes()
    stamps, v, y = _samples()
    stamps = stamps.copy()
    stamps[200:] += 3600 * 10**9                            # an hour without samples
    _feed(ident, stamps, v, y)
    ok, message = ident.request_identification('test')
    assert not ok and 'gap' in message
    assert 'gap' in ident.last_error and 'stay in place' in ident.last_error
    assert ident.last_document['er_percent'] == 0.5 and out.read_bytes() == before


def test_a_refused_run_keeps_its_samples_and_non_finite_ones_are_not_collected(ctx, tmp_path):
    """A NaN is dropped on arrival (counted, an ERROR on the next status, then a WARN).

    A run refused keeps what was collected.
    """
    ident = _make(ctx, Identifier, parameter_overrides=FAST + [Parameter('min_samples',
                                                                         value=50)])
    sent: list[tuple[int, str]] = []
    ident.publish_diagnostics = lambda level, msg, values=None, **kw: sent.append((level, msg))
    stamps, v, y = _samples()
    _feed(ident, stamps, v, y, order=np.r_[0:150, 151:400])
    ident._on_measurement(JointState(position=[np.nan]), {})     # as the subscription does
    assert ident.buffer.n_measurements == 399 and ident.buffer.non_finite['measurement'] == 1
    assert '1 measurement sample(s) with a NaN' in ident.collected_recording().notes[-1]
    ident._status()
    assert sent[-1][0] == 2 and '1 non-finite input value(s)' in sent[-1][1], sent[-1]
    ident._status()                     # none since: the run's gap stays visible as a WARN
    assert sent[-1][0] == 1 and 'with a NaN' in sent[-1][1], sent[-1]
    ident.buffer.clear()
    _feed(ident, stamps, np.full(400, 9.0), y)              # no excitation: refused
    ok, message = ident.request_identification('test')
    assert not ok and 'samples kept' in ident.last_error, ident.last_error
    assert ident.buffer.n_measurements == 400               # not cleared: nothing lost


def test_messages_whose_field_cannot_be_read_are_an_error_not_a_silent_ok(ctx):
    """A field that cannot be read: not collected, and the next status an ERROR saying why.

    A JointState with empty ``position``, a command message without the field: the node had
    stayed OK, collecting 0 samples.
    """
    from std_msgs.msg import Float64
    ident = _make(ctx, Identifier, parameter_overrides=FAST)
    sent: list[tuple[int, str]] = []
    ident.publish_diagnostics = lambda level, msg, values=None, **kw: sent.append((level, msg))
    for _ in range(3):
        ident._on_measurement(JointState(position=[]), {})   # as the subscription does
        ident._on_command(JointState(), {})                  # no ``data`` field: no traceback
        ident._on_command(Float64(data=9.0), {})
    assert ident.buffer.n_measurements == 0
    ident._status()
    assert sent[-1][0] == 2, sent[-1]
    assert ('3 message(s) not collected: hyst_id/position: cannot read the measurement field'
            in sent[-1][1]), sent[-1]
    assert '3 message(s) not collected: hyst_id/command: cannot read the command' in sent[-1][1]
    ident._on_measurement(JointState(position=[1.0]), {})
    ident._status()                     # none since: not an error any more
    assert 'not collected' not in sent[-1][1]


def test_a_bad_compensator_node_domains_file_or_mechanism_is_refused_when_set(ctx, tmp_path):
    ident = _make(ctx, Identifier, parameter_overrides=FAST)
    res = ident.set_parameters([Parameter('compensator_node', value='bad name!')])[0]
    assert not res.successful and 'not a valid node name' in res.reason
    assert ident.set_parameters([Parameter('compensator_node', value='/v1/compensator')])[
        0].successful
    bad = tmp_path / 'dom.yaml'
    bad.write_text('m_l: [0.1, 0.5]\nnot_a_parameter: [0, 1]\n')
    res = ident.set_parameters([Parameter('domains', value=str(bad))])[0]
    assert not res.successful and 'not_a_parameter' in res.reason, res.reason
    bad.write_text('m_l: [0.5, 0.1]\n')
    res = ident.set_parameters([Parameter('domains', value=str(bad))])[0]
    assert not res.successful and 'low < high' in res.reason, res.reason
    bad.write_text('m_l: [0.1, 0.5]\n')
    assert ident.set_parameters([Parameter('domains', value=str(bad))])[0].successful
    res = ident.set_parameters([Parameter('diagnose_mechanisms', value='dead_time, foo')])[0]
    assert not res.successful and "unknown mechanism(s) ['foo']" in res.reason, res.reason
    assert ident.set_parameters([Parameter('diagnose_mechanisms', value='dead_time')])[
        0].successful


def test_a_failed_identification_keeps_the_last_parameters(ctx, tmp_path, monkeypatch):
    import hyst_id.live.jobs

    def boom(*args, **kwargs):
        raise IdentificationError('boom: the optimiser gave up')

    monkeypatch.setattr(hyst_id.live.jobs, 'identify', boom)
    ident, out = _recovered(ctx, tmp_path)
    before = out.read_bytes()
    _feed(ident, *_samples())
    ok, _ = ident.request_identification('test')
    assert ok
    assert _spin_until(ctx, lambda: ident.job is None, timeout=30.0)
    assert 'boom' in ident.last_error and 'stay in place' in ident.last_error
    late = _listen(ctx, name='late_joiner')                 # the latched doc is the old one
    assert _spin_until(ctx, lambda: bool(late), timeout=5.0)
    assert late[-1]['er_percent'] == 0.5 and 'recovered' in late[-1]['source']
    assert out.read_bytes() == before


def test_cancel_service_and_parameter_keep_the_last_parameters(ctx, tmp_path):
    pytest.importorskip('std_srvs')
    from std_srvs.srv import Trigger
    ident, out = _recovered(ctx, tmp_path, seeds=40, refine=False)
    before = out.read_bytes()
    got = _listen(ctx)
    assert _spin_until(ctx, lambda: bool(got), timeout=10.0)   # the recovered, latched doc
    caller = _make(ctx, Node, 'caller')
    cancel = caller.create_client(Trigger, '/identifier/cancel')
    assert _spin_until(ctx, cancel.service_is_ready, timeout=5.0)
    _feed(ident, *_samples())
    assert ident.request_identification('test')[0]
    job = ident.job
    assert _spin_until(ctx, lambda: bool(job.runs), timeout=60.0)
    future = cancel.call_async(Trigger.Request())
    assert _spin_until(ctx, future.done, timeout=5.0)
    assert future.result().success and 'stay in place' in future.result().message
    assert ident.job is None
    again = ident.request_identification('test')              # buffer was cleared anyway
    assert not again[0]
    assert job.wait(60.0) and job.cancelled and len(job.runs) < 40
    assert _spin_until(ctx, lambda: not ident._cancelled, timeout=5.0)
    assert len(got) == 1 and 'recovered' in got[0]['source']      # nothing new published
    assert out.read_bytes() == before
    assert ident.set_parameters([Parameter('cancel_now', value=True)])[0].successful
    assert _spin_until(ctx, lambda: ident.p('cancel_now') is False, timeout=5.0)


def test_a_restart_recovers_the_last_result(ctx, tmp_path):
    out = tmp_path / 'live.yaml'
    first = _make(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('params_out', value=str(out))])
    _feed(first, *_samples())
    got = _listen(ctx)
    assert first.request_identification('test')[0]
    assert _spin_until(ctx, lambda: bool(got), timeout=120.0), first.last_error
    identified = got[-1]['compensator_params']
    ctx[1].remove(first)
    first.destroy_node()                                     # "crash"
    got.clear()
    second = _make(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('params_out', value=str(out))])
    comp = _make(ctx, Compensator)
    assert _spin_until(ctx, lambda: bool(got) and comp.model is not None, timeout=10.0)
    recovered = dict(got[-1]['compensator_params'])
    assert recovered.pop('family') == identified['family'] == 'tk'
    assert recovered == pytest.approx({k: v for k, v in identified.items() if k != 'family'},
                                      rel=1e-12)
    assert 'recovered' in got[-1]['source'] and second.last_document == got[-1]
    assert comp.p('m_l') == pytest.approx(identified['m_l'], rel=1e-12)


def test_diagnose_service_publishes_findings_and_json(ctx):
    pytest.importorskip('std_srvs')
    from diagnostic_msgs.msg import DiagnosticArray
    from std_srvs.srv import Trigger
    ident = _make(ctx, Identifier, parameter_overrides=FAST + [
        Parameter('diagnose_seeds', value=1), Parameter('diagnose_generations', value=20),
        Parameter('diagnose_hops', value=20),
        Parameter('diagnose_more_starts', value=True), Parameter('more_starts', value=True),
        Parameter('diagnose_mechanisms', value='offset_drift, sensor_lag')])
    caller = _make(ctx, Node, 'caller')
    diag = caller.create_client(Trigger, '/identifier/diagnose')
    arrays = []
    caller.create_subscription(DiagnosticArray, '/diagnostics', arrays.append, 10)
    docs = _listen(ctx, '/identifier/diagnosis', 'diagnosis_listener')
    assert _spin_until(ctx, diag.service_is_ready, timeout=5.0)
    future = diag.call_async(Trigger.Request())
    assert _spin_until(ctx, future.done, timeout=5.0)
    assert not future.result().success and 'nothing to diagnose' in future.result().message
    _feed(ident, *_samples(drift_per_s=0.01))                # the sensor zero drifts
    future = diag.call_async(Trigger.Request())
    assert _spin_until(ctx, future.done, timeout=5.0)
    assert future.result().success, future.result().message
    assert ident.diag_job.options['hops'] == 20              # diagnose_hops reaches it
    assert ident.diag_job.options['more_starts'] is True     # and diagnose_more_starts
    assert ident.settings().more_starts is True              # identify's own more_starts
    assert _spin_until(ctx, lambda: bool(docs), timeout=120.0), ident.last_error
    assert docs[-1]['verdict'] == 'offset_drift'

    def finding():
        for arr in arrays:
            for st in arr.status:
                if st.name.endswith('diagnosis: offset_drift'):
                    return st
        return None

    assert _spin_until(ctx, lambda: finding() is not None, timeout=5.0)
    st = finding()
    values = {kv.key: kv.value for kv in st.values}
    assert st.level == bytes([1]) and 'drift' in st.message
    assert float(values['er_holdout_after_percent']) < float(values['er_holdout_before_percent'])
    assert 'param.rate_per_s' in values and values['mechanism'] == 'offset_drift'
    assert ident.buffer.n_measurements == 400                 # diagnosing keeps the samples


@pytest.mark.slow
def test_replay_at_rate_4_with_sim_time_keeps_the_sensor_time_constant(ctx, tmp_path):
    """Pressure (header-stamped) and commands (unstamped) replayed 4x fast, use_sim_time.

    The recording comes from the independent reference simulator (tau 1.5 s).
    Before /clock the commands were timed by arrival and tau came out near 1.5 / 4.
    """
    from reference_sim import simulate

    from hyst_id.io.bag import write_recording_bag
    from hyst_id.io.recording import Recording
    from hyst_id.nodes.replay import Replay

    t = np.arange(900) * 0.1
    v = eq24(t)
    y = simulate('pressure', {**PAPER, 'tau_s': 1.5}, t, v, gain=-40_000.0, offset=600_000.0)
    y = y + np.random.default_rng(5).normal(0, 100.0, t.size)
    bag = write_recording_bag(tmp_path / 'p', Recording(t, v, y, 'pressure', 'mA', 'Pa'))
    got = _listen(ctx)
    _make(ctx, Identifier, parameter_overrides=[
        Parameter('channel', value='pressure'), Parameter('use_sim_time', value=True),
        Parameter('seeds', value=2), Parameter('generations', value=60),
        Parameter('global_runs', value=6), Parameter('hops', value=0),
        Parameter('end_of_run_timeout_s', value=1.0), Parameter('compensator_node', value=''),
        Parameter('measurement_reliable', value=True), Parameter('recover_on_start', value=False),
        Parameter('params_out', value=str(tmp_path / 'out.yaml'))])
    _make(ctx, Replay, parameter_overrides=[
        Parameter('bag', value=str(bag)), Parameter('rate', value=4.0),
        Parameter('wait_for_subscribers', value=2), Parameter('shutdown_when_done', value=False)])
    assert _spin_until(ctx, lambda: bool(got), timeout=150.0)
    assert got[-1]['n_samples'] >= 890
    assert got[-1]['params']['tau_s'] == pytest.approx(1.5, rel=0.15), got[-1]['params']
