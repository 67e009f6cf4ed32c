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

"""Identifier node: collects command + one measured channel, identifies, publishes.

A thin ROS shell over :mod:`hyst_id.live` (sample buffer and pairing, worker
jobs, result documents); ``docs/nodes.md`` describes topics, parameters and
behaviour. Samples with a header (stamped commands too) are timed by its
stamp (``stamp_source: header``), others by the publisher's source
timestamp; out-of-order samples are sorted, gaps noted in the result.
Identification (:func:`hyst_id.identification.identify`, as ``hyst-id
identify``) and diagnosis (:func:`hyst_id.diagnosis.diagnose`) run in worker
threads, never on the executor; triggers are the end of a run, the
``identify_now`` / ``cancel_now`` / ``diagnose_now`` parameters and the
``~/identify`` / ``~/cancel`` / ``~/diagnose`` services. A failed or
cancelled identification leaves the last published parameters in place; a
restart republishes the set of the params file the node wrote.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
import json
import math
from pathlib import Path
import time
from typing import Any, Callable

from diagnostic_msgs.msg import DiagnosticStatus
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from hyst_id.compensation.params_file import (
    compensator_values,
    read_compensator_params,
    write_compensator_params,
)
from hyst_id.errors import ConfigError, HystIdError
from hyst_id.identification import Identification, IdentifySettings
from hyst_id.identification.config import make_spec
from hyst_id.identification.model_choice import AUTO_FAMILIES
from hyst_id.io.recording import Recording, validate_recording
from hyst_id.io.topics import parse_field_path, TopicConfig, value_field
from hyst_id.live import (
    diagnosis_statuses,
    DiagnosisJob,
    IdentificationJob,
    QualityGate,
    recovered_document,
    result_document,
    SampleBuffer,
    warm_up_kernels,
)
from hyst_id.nodes.support import (
    check_field,
    COMMAND_QOS,
    diagnostic_array,
    HystNode,
    input_problems,
    LATCHED_QOS,
    message_class,
    OVERRIDABLE,
    ParameterPusher,
    resolved,
    ScalarStream,
    source_time_ns,
    spin_node,
    stamp_ns,
)
from hyst_id.nodes.support.field_reads import FieldReads
from hyst_id.nodes.support.identifier_params import (
    default_params_out, identify_settings, PARAMS, validate_identifier_params)
from hyst_id.nodes.support.result_pub import ResultPublisher
from hyst_id.nodes.support.sliding import SlidingLink

try:  # optional: std_srvs is not a dependency of the package
    from std_srvs.srv import Trigger
except ImportError:  # pragma: no cover - depends on the installation
    Trigger = None

__all__ = ['Identifier', 'PARAMS', 'default_params_out', 'main']


#: Depth of the best-effort measurement subscription's queue.
SENSOR_QUEUE_DEPTH = 1000
#: The triggers (parameter -> what it starts), reset to false once handled.
_TRIGGERS = ('identify_now', 'cancel_now', 'diagnose_now')


class Identifier(HystNode):
    """Collect samples, identify the chain with GAASS, publish and push the result."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('identifier', PARAMS, **kwargs)
        v = self.param_values()
        self.channel = v['channel']
        self.buffer = SampleBuffer(v['max_samples'])
        self.job: IdentificationJob | None = None
        self.diag_job: DiagnosisJob | None = None
        self.last_identification: Identification | None = None
        self.handed_over: Identification | None = None   # the set sliding refits
        self.last_document: dict | None = None
        self.last_diagnosis: dict | None = None
        self.last_error = self._gate_message = ''
        self._eor_tried, self._requested = False, set()
        self.on_identified: Callable[[dict], None] | None = None
        self._cancelled: list[IdentificationJob | DiagnosisJob] = []
        self._last_rec: Recording | None = None
        self._diag_statuses: list[DiagnosticStatus] = []
        self._pusher = ParameterPusher(self)
        self.sliding = SlidingLink(self)
        self._started = time.monotonic()
        self._rx: dict[str, float] = {}     # monotonic time each input was last received
        self._reads = FieldReads(self.get_logger())
        meas_type = v[f'topics.{self.channel}_type']
        self._cmd_field = parse_field_path(value_field(v['topics.command_type'], v[
            'topics.command_field']))
        self._meas_field = parse_field_path(value_field(meas_type,
                                                        v[f'topics.{self.channel}_field']))
        self._meas_topic = v[f'topics.{self.channel}_topic']
        self._expected = ((v['topics.command_topic'], v['topics.command_type']),
                          (self._meas_topic, meas_type))
        cmd_cls, meas_cls = ScalarStream(v['topics.command_type']).cls, message_class(meas_type)
        check_field(cmd_cls, self._cmd_field, 'topics.command_field')
        check_field(meas_cls, self._meas_field, f'topics.{self.channel}_field')
        self._stamp_header = v['topics.stamp_source'] == 'header'
        self._units = (TopicConfig().command_unit,
                       TopicConfig.for_channel(self.channel).measurement_unit)
        self.params_out = Path(v['params_out']).expanduser() if v['params_out'] \
            else default_params_out()
        # Best effort like every sensor subscriber, with a deep queue: samples arriving while
        # the executor is busy (GIL, JIT warm-up) wait, not dropped. Reliable (replays): all.
        meas_qos = (QoSProfile(history=HistoryPolicy.KEEP_ALL,
                               reliability=ReliabilityPolicy.RELIABLE)
                    if v['measurement_reliable'] else
                    QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=SENSOR_QUEUE_DEPTH,
                               reliability=ReliabilityPolicy.BEST_EFFORT))
        self.create_subscription(cmd_cls, v['topics.command_topic'], self._on_command,
                                 COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        self.create_subscription(meas_cls, self._meas_topic,
                                 self._on_measurement, meas_qos,
                                 qos_overriding_options=OVERRIDABLE)
        self._result_pub = ResultPublisher(self, v['topics.identified_params_topic'],
                                           v['topics.identified_typed_topic'], LATCHED_QOS)
        self._diag_json_pub = self.create_publisher(String, '~/diagnosis', LATCHED_QOS)
        if Trigger is not None:
            for name, fn in (('identify', self.request_identification),
                             ('cancel', self.cancel_identification),
                             ('diagnose', self.request_diagnosis)):
                self.create_service(Trigger, f'~/{name}',
                                    lambda req, res, fn=fn: self._on_trigger(fn, res))
        self._warm = ThreadPoolExecutor(max_workers=1, thread_name_prefix='jit-warm-up')
        self._warm_future = self._warm.submit(warm_up_kernels, self.channel)
        self.create_steady_timer(0.02, self._tick)
        self.create_steady_timer(1.0, self._status)
        self.get_logger().info(
            f'identifying {self.channel} from {resolved(self, v["topics.command_topic"])} + '
            f'{resolved(self, self._meas_topic)} ({meas_type} '
            f'{v[f"topics.{self.channel}_field"]}); publishing on '
            f'{self._result_pub.topic_name}'
            + (f' and {self._result_pub.typed_topic_name}' if self._result_pub.typed_topic_name
               else '') + '; trigger: '
            + (f'end of run after {v["end_of_run_timeout_s"]:g} s idle, '
               if v['end_of_run_timeout_s'] > 0 else '') + 'identify_now:=true'
            + (', ~/identify, ~/cancel, ~/diagnose services' if Trigger is not None else ''))
        if v['recover_on_start'] and self.params_out.is_file():
            self._recover()

    # ---------------------------------------------------------------- params
    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        return validate_identifier_params(values, changed)

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        self._requested |= {n for n in _TRIGGERS if n in changed and values[n]}
        if 'max_samples' in changed and hasattr(self, 'buffer'):
            self.buffer.max_samples = values['max_samples']

    # ------------------------------------------------------------- samples
    def _stamp(self, msg: Any, info: dict) -> int:
        if self._stamp_header and hasattr(msg, 'header'):
            ns = stamp_ns(msg.header.stamp)
            if ns:
                return ns
        return source_time_ns(self, info)

    def _on_command(self, msg: Any, info: dict) -> None:
        self._rx['command'] = time.monotonic()
        if not self.p('collect') or (value := self._reads.read(
                'command', self.p('topics.command_topic'), msg, self._cmd_field)) is None:
            return
        if not self.buffer.add_command(self._stamp(msg, info), value):
            self._non_finite()

    def _on_measurement(self, msg: Any, info: dict) -> None:
        self._rx['measurement'] = time.monotonic()
        if not self.p('collect'):
            return
        if (value := self._reads.read('measurement', self._meas_topic, msg,
                                      self._meas_field)) is None:
            return
        if not self.buffer.add_measurement(self._stamp(msg, info), value):
            self._non_finite()
        self._eor_tried = False

    def _non_finite(self) -> None:
        # counted and logged; the next /diagnostics status is an ERROR, as on every node
        self.note_non_finite('sample (not collected)')

    # ------------------------------------------------------------ requests
    def _on_trigger(self, fn: Callable[[str], tuple[bool, str]], response: Any) -> Any:
        response.success, response.message = fn('service call')
        return response

    def collected_recording(self, last_s: float | None = None) -> Recording:
        """The samples collected (the newest ``last_s`` seconds of them) as a Recording."""
        return self.buffer.recording(
            self.channel, f'live: {self.p("topics.command_topic")}, {self._meas_topic}',
            self._units, (self.p('topics.command_topic'), self._meas_topic), last_s=last_s)

    def _busy(self) -> str:
        if any(not j.done for j in self._cancelled):
            return 'a cancelled job is still finishing its current step; try again shortly'
        return ''

    def request_identification(self, why: str) -> tuple[bool, str]:
        """Start identifying the samples collected so far; return (started, message)."""
        if self.job is not None:
            return False, 'an identification is already running'
        n = self.buffer.n_measurements
        if n < self.p('min_samples'):
            return False, f'only {n} samples collected (min_samples {self.p("min_samples")})'
        if self._busy():
            return False, self._busy()
        self.sliding.cancel('a full identification starts')
        try:
            rec = validate_recording(self.collected_recording())
            model = self.p('model')
            if model == 'auto':
                self.job = IdentificationJob(rec, None, self.settings(), families=AUTO_FAMILIES)
            else:
                spec = make_spec(rec, self.p('domains'), family=model)
                self.job = IdentificationJob(rec, spec, self.settings())
        except HystIdError as exc:     # the samples stay (mend the cause, identify_now)
            self._fail(f'cannot identify ({why}): {exc}; {self._kept()}; the {n} samples kept')
            return False, str(exc)
        if self.p('clear_after_identify'):
            self.buffer.clear()
        for note in rec.notes:
            self.get_logger().warning(f'samples: {note}')
        s = self.job.settings
        msg = (f'identifying {self.channel} ({why}): {rec.n_samples} samples over '
               f'{rec.duration_s:.1f} s, {len(s.seeds)} seed(s) x {s.maxiter} generations '
               f'(N_pop {s.pop_size}), '
               + ('in a worker thread' if s.workers == 1 else 'in worker processes'))
        self.get_logger().info(msg)
        return True, msg

    def cancel_identification(self, why: str) -> tuple[bool, str]:
        """Cancel the running identification; the last published parameters stay."""
        job, self.job = self.job, None
        if job is None:
            return False, 'no identification is running'
        job.cancel()
        self._cancelled.append(job)
        msg = (f'identification cancelled ({why}) after {job.elapsed_s:.1f} s; '
               + self._kept())
        self.get_logger().warning(msg)
        self.publish_diagnostics(1, msg, {'samples': self.buffer.n_measurements})
        return True, msg

    def request_diagnosis(self, why: str) -> tuple[bool, str]:
        """Start diagnosing the samples collected (else the last identified run)."""
        if self.diag_job is not None:
            return False, 'a diagnosis is already running'
        if self._busy():
            return False, self._busy()
        try:
            if self.buffer.n_measurements >= self.p('min_samples'):
                rec, what = self.collected_recording(), 'the samples collected'
            elif self._last_rec is not None:
                rec, what = self._last_rec, 'the last identified run'
            else:
                return False, (f'nothing to diagnose: {self.buffer.n_measurements} samples '
                               f'collected (min_samples {self.p("min_samples")}) and no '
                               'identified run')
            self.diag_job = DiagnosisJob(
                validate_recording(rec), train_fraction=self.p('diagnose_train_fraction'),
                seeds=self.p('diagnose_seeds'), generations=self.p('diagnose_generations'),
                mechanisms=self.p('diagnose_mechanisms'), hops=self.p('diagnose_hops'),
                more_starts=self.p('diagnose_more_starts'))
        except HystIdError as exc:
            self._fail(f'cannot diagnose ({why}): {exc}')
            return False, str(exc)
        msg = f'diagnosing {what} ({why}): {rec.n_samples} samples in a worker thread'
        self.get_logger().info(msg)
        return True, msg

    def settings(self) -> IdentifySettings:
        """GAASS settings from the parameters, built as ``hyst-id identify`` builds them."""
        return identify_settings(self.p)

    def _kept(self) -> str:
        doc = self.last_document
        return (f'the last published parameters (%e_r {doc["er_percent"]:.4g}) stay in place'
                if doc else 'no parameters published yet')

    def _fail(self, message: str) -> None:
        self.last_error = message
        self.get_logger().error(message)
        self.publish_diagnostics(2, message, {'samples': self.buffer.n_measurements})

    # ----------------------------------------------------------------- tick
    def _tick(self) -> None:
        requested, self._requested = self._requested, set()
        for name, fn in (('cancel_now', self.cancel_identification),
                         ('identify_now', self.request_identification),
                         ('diagnose_now', self.request_diagnosis)):
            if name in requested:
                ok, message = fn(name)
                if not ok:
                    self.get_logger().warning(f'{name}: {message}')
                self.set_parameters([Parameter(name, value=False)])
        timeout = self.p('end_of_run_timeout_s')
        last = self.buffer.last_rx
        if (self.job is None and timeout > 0 and not self._eor_tried and last is not None
                and time.monotonic() - last >= timeout):
            self._eor_tried = True
            if self.buffer.n_measurements >= self.p('min_samples'):
                self.request_identification(f'end of run, {timeout:g} s without samples')
        self._cancelled = [j for j in self._cancelled if not j.done]
        if self.job is not None and self.job.done:
            job, self.job = self.job, None
            if job.error:
                self._fail(f'identification failed: {job.error}; {self._kept()}')
            elif job.result is not None:
                self.publish_identified(job.result, job.rec, job.elapsed_s, job.choice)
        if self.diag_job is not None and self.diag_job.done:
            job, self.diag_job = self.diag_job, None
            if job.error:
                self._fail(f'diagnosis failed: {job.error}')
            elif job.result is not None:
                self._publish_diagnosis(job.result.to_dict(), job.elapsed_s)
        self.sliding.tick()
        self._pusher.poll()

    def quality_gate(self) -> QualityGate:
        """The gate a set must pass to be handed over (from the ``gate_*`` parameters)."""
        return QualityGate(self.p('gate_max_floor_ratio'), self.p('gate_max_uncertainty'))

    def publish_identified(self, ident: Identification, rec: Recording, elapsed_s: float,
                           choice: Any = None, sliding: dict | None = None) -> bool:
        """Publish an identified set and hand it over (params file, compensator) if it may be.

        ``sliding`` (a swap decision, JSON-ready) marks a set from a
        sliding-window re-identification; it goes into the document. Returns
        whether the set was handed over.
        """
        self.last_identification = ident
        self._last_rec = rec
        doc = result_document(ident, rec.n_samples, rec.duration_s, rec.notes,
                              gate=self.quality_gate())
        if sliding is not None:
            doc['sliding'] = sliding
        comp = doc['compensator_params']
        if comp is None and not doc['gate']['passed']:
            self._publish_held_back(ident, rec, doc)
            return False
        if comp is None:
            self._fail(f'identified {ident.channel} (%e_r {ident.er_percent:.3f}) but '
                       f'{doc["compensator_note"]}; {self._kept()}')
            return False
        self.handed_over = ident
        if choice is not None:
            doc['model_choice'] = choice.to_dict()
            self.get_logger().info('H family chosen on held-out data: ' + ', '.join(
                f'{c.family} {c.holdout_er_percent:.4f} %' for c in choice.scores)
                + f' -> {choice.chosen}')
        self.last_document = doc
        self.last_error = ''
        self._gate_message = ''
        self._result_pub.publish(doc)
        self.get_logger().info(
            f'identified {ident.channel} in {elapsed_s:.1f} s: %e_r '
            f'{ident.er_percent:.3f} (noise floor {ident.noise_floor_percent:.3f}); '
            + ', '.join(f'{n}={ident.params[n]:.4g}' for n in ident.names))
        for w in ident.warnings:
            self.get_logger().warning(f'identification: {w}')
        self.publish_diagnostics(1 if ident.warnings else 0,
                                 f'identified {ident.channel}: %e_r {ident.er_percent:.3f}'
                                 + (f'; {len(ident.warnings)} warning(s): '
                                    + ' | '.join(ident.warnings) if ident.warnings else ''),
                                 {'er_percent': ident.er_percent, 'elapsed_s': elapsed_s})
        values = compensator_values({**comp, 'channel': ident.channel,
                                     'er_percent': doc['compensator_er_percent']})
        try:
            write_compensator_params(values, self.params_out)
            self.get_logger().info(f'wrote {self.params_out}')
        except HystIdError as exc:
            self.get_logger().error(f'cannot write the params file: {exc}')
        if self.p('compensator_node'):
            self._pusher.push(self.p('compensator_node'),
                              [Parameter(k, value=v) for k, v in values.items()],
                              self.p('push_timeout_s'))
        if self.on_identified is not None:
            self.on_identified(doc)
        return True

    def _publish_held_back(self, ident: Identification, rec: Recording, doc: dict) -> None:
        """Publish a result the quality gate holds back: nothing is handed over."""
        self.last_document = doc
        self.last_error = ''
        self._result_pub.publish(doc)
        self._gate_message = (
            f'identified {ident.channel} (%e_r {ident.er_percent:.3f}, noise floor '
            f'{ident.noise_floor_percent:.3f}) but held it back: '
            + '; '.join(doc['gate']['reasons'])
            + f'; the compensator and {self.params_out} keep their set (relax '
            'gate_max_floor_ratio / gate_max_uncertainty to hand such sets over)')
        self.get_logger().warning(self._gate_message)
        for w in ident.warnings:        # as for a set handed over
            self.get_logger().warning(f'identification: {w}')
        self.publish_diagnostics(1, self._gate_message, {'er_percent': ident.er_percent})
        if self.on_identified is not None:
            self.on_identified(doc)

    def _publish_diagnosis(self, doc: dict, elapsed_s: float) -> None:
        self.last_diagnosis = doc
        self._diag_json_pub.publish(String(data=json.dumps(doc)))
        prefix = f'hyst_id: {self.status_name}: diagnosis'
        self._diag_statuses = [
            diagnostic_array(self, f'{prefix}: {name}', level, message, values).status[0]
            for level, name, message, values in diagnosis_statuses(doc)]
        msg = (f'diagnosis done in {elapsed_s:.1f} s: verdict {doc.get("verdict", "?")}, '
               f'{len(doc.get("findings") or [])} finding(s)')
        self.get_logger().info(msg)
        self.publish_diagnostics(0, msg, {'verdict': doc.get('verdict', '?')},
                                 extra=self._diag_statuses)

    def _recover(self) -> None:
        try:
            doc = recovered_document(read_compensator_params(self.params_out), self.params_out)
        except ConfigError as exc:
            self.get_logger().warning(f'no recovery from {self.params_out}: {exc}')
            return
        if doc['channel'] != self.channel:
            return
        self.last_document = doc
        self._result_pub.publish(doc)
        self.get_logger().info(f'republished the parameter set of {self.params_out} '
                               f'(%e_r {doc["er_percent"]:.3g})')

    def _status(self) -> None:
        n = self.buffer.n_measurements
        values: dict[str, Any] = {'samples': n, 'channel': self.channel}
        if self.diag_job is not None:
            values['diagnosis'] = f'{self.diag_job.step} ({self.diag_job.elapsed_s:.0f} s)'
        level, msg = 0, f'{"collecting" if self.p("collect") else "idle"}: {n} samples'
        if self.job is not None:
            prog = self.job.progress()
            values.update(prog)
            best, runs = prog.get('best_er_percent'), prog.get('global_runs_done', 0)
            msg = (f'identifying: {prog["seeds_done"]}/{prog["seeds"]} seeds, {runs} global '
                   f'runs, {prog["elapsed_s"]:.1f} s' + ('' if best is None else
                                                         f', best %e_r {best:.3f}'))
            if 'generation' in prog:
                msg += (f'; seed {prog["seed"]} run {prog["restart"] + 1} generation '
                        f'{prog["generation"]}, %e_r {prog["seed_er_percent"]:.3f}')
            if 'hop' in prog:
                msg += f'; hopping {prog["hop"]}/{prog["hops"]}'
        elif self.last_error:
            level, msg = 2, self.last_error
        elif self._gate_message or self.buffer.non_finite_note:
            level, msg = 1, self._gate_message or f'{msg}; {self.buffer.non_finite_note}'
        elif self.last_document:
            values['last_er_percent'] = self.last_document.get('er_percent') or math.nan
            if self.last_document.get('warnings'):     # the set's warnings stay visible
                level, msg = 1, msg + '; last set: ' + ' | '.join(self.last_document['warnings'])
        values.update(self.sliding.status())
        problems = input_problems(   # a wrong type, or one input arriving without the other
            self, self._expected, self._rx, self._started, self.p('input_timeout_s'),
            {'command': self.p('topics.command_topic'), 'measurement': self._meas_topic})
        problems += [w for w in [self.non_finite_problem()] if w] + self._reads.problems()
        if problems:
            level, msg = 2, '; '.join(problems) + f' ({msg})'
            self.get_logger().error('; '.join(problems), throttle_duration_sec=10.0)
        self.publish_diagnostics(level, msg, values, extra=self._diag_statuses)

    def destroy_node(self) -> None:
        """Stop workers, then the node."""
        if hasattr(self, '_warm'):    # also called on a node whose __init__ failed
            self._warm.shutdown(wait=False, cancel_futures=True)
            jobs = [j for j in (self.job, self.diag_job, self.sliding.cancel('shutdown'),
                                *self._cancelled) if j is not None]
            for job in jobs:
                job.cancel()
            for job in jobs:        # worker processes end within 0.2 s of a cancel
                job.wait(2.0)
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the identifier until Ctrl-C / SIGTERM."""
    return spin_node(Identifier, 'identifier', args)


if __name__ == '__main__':
    raise SystemExit(main())
