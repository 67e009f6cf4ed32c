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

Samples come from live topics or a replay. Each stream is timed like
:func:`hyst_id.io.readers.read_mcap` times a bag: a measurement by its
``header.stamp`` (``stamp_source: header``, when the type has a header),
anything else by the publisher's source timestamp (``stamp_source: log``
uses source timestamps for everything: use it when replaying a bag, whose
header stamps are old). Each measurement is paired with the last command at
or before it, so the node builds the same recording the CLI reads from the
recorder's bag.

Identification starts when

* the run ends: no new measurement for ``end_of_run_timeout_s``;
* the parameter ``identify_now`` is set true; or
* the ``~/identify`` service (``std_srvs/srv/Trigger``) is called, when
  std_srvs is installed.

It never blocks the executor: :func:`hyst_id.identify.identify` (the very
function behind ``hyst-id identify``, so the same settings and seeds give
the same result) runs in a worker thread, and with ``workers`` 0 or > 1 it
runs the seeds in worker processes; a timer polls it. The numba kernels are
compiled (or loaded from cache) in a thread at start-up.

Progress goes to ``/diagnostics``; the result is published latched
as JSON, written as a compensator params file and pushed to the compensator
with its ``set_parameters_atomically`` service.
"""

from __future__ import annotations

import argparse
from concurrent.futures import Future, ThreadPoolExecutor
import datetime
import json
import os
from pathlib import Path
import threading
import time
from typing import Any, Callable

import numpy as np
from rcl_interfaces.srv import SetParametersAtomically
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64, String

from hyst_id.chains import chain_spec, ChainSpec
from hyst_id.commands.common import make_settings, make_spec
from hyst_id.compensate import InverseModel
from hyst_id.errors import (ConfigError, HystIdError, IdentificationError,
                            InvalidParametersError)
from hyst_id.identify import Identification, identify, IdentifySettings, SeedRun
from hyst_id.io.params_file import (COMPENSATOR_NAMES, read_compensator_params,
                                    write_compensator_params)
from hyst_id.io.readers import get_field, parse_field_path, TopicConfig
from hyst_id.io.recording import CHANNELS, Recording, validate_recording
from hyst_id.nodes import (COMMAND_QOS, HystNode, IDENTIFIED_PARAMS_TOPIC, init_ros, LATCHED_QOS,
                           message_class, Param, stamp_ns, topic_params)

try:  # optional: std_srvs is not a dependency of the package
    from std_srvs.srv import Trigger
except ImportError:  # pragma: no cover - depends on the installation
    Trigger = None

__all__ = ['Identifier', 'IdentificationJob', 'PARAMS', 'SampleBuffer', 'compensator_set',
           'default_params_out', 'main', 'pair_streams', 'result_document']

_FIELD_PARAMS = [Param('topics.command_field', TopicConfig().command_field,
                       'field of the command message', read_only=True)]
for _ch in CHANNELS:
    _cfg = TopicConfig.for_channel(_ch)
    _FIELD_PARAMS += [
        Param(f'topics.{_ch}_type', _cfg.measurement_type, f'message type of {_ch}',
              read_only=True),
        Param(f'topics.{_ch}_field', _cfg.measurement_field, f'field of the {_ch} message',
              read_only=True)]

PARAMS = [
    Param('channel', 'position', 'measured channel to identify', choices=CHANNELS,
          read_only=True),
    *topic_params(), *_FIELD_PARAMS,
    Param('topics.stamp_source', 'header', "'header': measurement header stamps; 'log': "
          'source timestamps for everything (replays)', choices=('header', 'log'),
          read_only=True),
    Param('topics.identified_params_topic', IDENTIFIED_PARAMS_TOPIC,
          'latched identified parameters (std_msgs/String, JSON)', read_only=True),
    Param('measurement_reliable', False, 'subscribe to the measurement with reliable QoS '
          '(for replays; live sensors are best effort)', read_only=True),
    Param('collect', True, 'accumulate samples from the topics'),
    Param('min_samples', 50, 'fewest samples an identification starts with', low=20,
          high=100000000),
    Param('max_samples', 2000000, 'samples kept (oldest dropped)', low=100, high=100000000),
    Param('end_of_run_timeout_s', 2.0, 'identify when no measurement arrived for this long '
          '(0 = only on request)', low=0.0, high=86400.0, unit='s'),
    Param('identify_now', False, 'set true to identify the samples collected so far'),
    Param('clear_after_identify', True, 'start a new run after each identification'),
    Param('pop_size', 10, 'GAASS population size N_pop', low=2, high=100000),
    Param('generations', 500, 'GAASS generations', low=1, high=10000000),
    Param('c', 0.007, 'GAASS search-space contraction rate (Eq. 15)', low=1e-9, high=100.0),
    Param('xi', 0.02, 'GAASS mutation subspace coefficient (Eq. 22)', low=1e-9, high=1.0),
    Param('seeds', 10, 'number of seeds (one GAASS run each)', low=1, high=100000),
    Param('seed_offset', 0, 'first seed', low=0, high=2**31 - 1),
    Param('workers', 1, '1: seeds one after the other in a worker thread; 0: one worker '
          'process per core; n > 1: n processes', low=0, high=1024),
    Param('refine', True, 'polish each GAASS result with bounded least squares'),
    Param('er_bound_percent', 0.0, 'stop a GAASS run once %e_r is below this (0 = never)',
          low=0.0, high=1000.0, unit='%'),
    Param('domains', 'auto', "search domains: 'auto' (from the data), 'paper', or a YAML "
          'file of name: [low, high]'),
    Param('params_out', '', 'compensator params file written after each identification '
          "('' = $ROS_HOME/hyst_id/compensator.yaml)", read_only=True),
    Param('recover_on_start', True, 'republish the parameter set found in params_out at '
          'start (restart recovery)', read_only=True),
    Param('compensator_node', '/compensator', 'node whose set_parameters_atomically service '
          "receives the parameters ('' = do not push)"),
    Param('push_timeout_s', 5.0, 'how long to wait for the compensator service', low=0.0,
          high=3600.0, unit='s'),
]


#: Depth of the measurement subscription's queue.
SENSOR_QUEUE_DEPTH = 1000


def default_params_out() -> Path:
    """``$ROS_HOME/hyst_id/compensator.yaml`` (``ROS_HOME`` defaults to ``~/.ros``)."""
    home = os.environ.get('ROS_HOME') or os.path.join(os.path.expanduser('~'), '.ros')
    return Path(home) / 'hyst_id' / 'compensator.yaml'


# ------------------------------------------------------------------ samples
def _tidy(t_ns: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if (np.diff(t_ns) < 0).any():
        order = np.argsort(t_ns, kind='stable')
        t_ns, values = t_ns[order], values[order]
    keep = np.append(t_ns[1:] != t_ns[:-1], True)
    return t_ns[keep], values[keep]


def pair_streams(cmd_t_ns: np.ndarray, cmd_v: np.ndarray, meas_t_ns: np.ndarray,
                 meas_v: np.ndarray, channel: str, source: str = '',
                 units: tuple[str, str] = ('', '')) -> Recording:
    """Pair each measurement with the last command at or before it (as the bag reader does).

    Streams are sorted by stamp and repeated stamps keep their last sample;
    measurements before the first command are dropped; ``t_s`` counts from
    the first kept measurement.

    Raises
    ------
    IdentificationError
        A stream is empty or no measurement follows a command.
    """
    if len(cmd_t_ns) == 0 or len(meas_t_ns) == 0:
        raise IdentificationError(f'no samples yet: {len(cmd_t_ns)} commands, '
                                  f'{len(meas_t_ns)} measurements')
    cmd_t, cmd_v = _tidy(np.asarray(cmd_t_ns, dtype=np.int64), np.asarray(cmd_v, float))
    meas_t, meas_v = _tidy(np.asarray(meas_t_ns, dtype=np.int64), np.asarray(meas_v, float))
    idx = np.searchsorted(cmd_t, meas_t, side='right') - 1
    keep = idx >= 0
    if not keep.any():
        raise IdentificationError('no measurement at or after the first command (clocks of '
                                  'the publishers differ?)')
    meas_t, meas_v, idx = meas_t[keep], meas_v[keep], idx[keep]
    return Recording(t_s=(meas_t - meas_t[0]).astype(np.float64) * 1e-9, command=cmd_v[idx],
                     measurement=meas_v, channel=channel, command_unit=units[0],
                     measurement_unit=units[1], source=source)


class SampleBuffer:
    """Command and measurement samples of the current run (stamps in ns)."""

    def __init__(self, max_samples: int = 2000000) -> None:
        self.max_samples = int(max_samples)
        self.clear()

    def clear(self) -> None:
        """Forget every sample."""
        self.cmd_t: list[int] = []
        self.cmd_v: list[float] = []
        self.meas_t: list[int] = []
        self.meas_v: list[float] = []
        self.last_rx = None

    def add_command(self, t_ns: int, value: float) -> None:
        """Append a command sample."""
        self.cmd_t.append(int(t_ns))
        self.cmd_v.append(float(value))
        self._trim(self.cmd_t, self.cmd_v)

    def add_measurement(self, t_ns: int, value: float) -> None:
        """Append a measurement sample."""
        self.meas_t.append(int(t_ns))
        self.meas_v.append(float(value))
        self._trim(self.meas_t, self.meas_v)
        self.last_rx = time.monotonic()

    def _trim(self, t: list, v: list) -> None:
        if len(t) > self.max_samples + self.max_samples // 10:
            del t[:len(t) - self.max_samples]
            del v[:len(v) - self.max_samples]

    @property
    def n_measurements(self) -> int:
        """Measurements collected."""
        return len(self.meas_t)

    def recording(self, channel: str, source: str = '',
                  units: tuple[str, str] = ('', '')) -> Recording:
        """The run so far as a :class:`~hyst_id.io.recording.Recording`."""
        return pair_streams(np.array(self.cmd_t), np.array(self.cmd_v), np.array(self.meas_t),
                            np.array(self.meas_v), channel, source, units)


# ---------------------------------------------------------- identification
class IdentificationJob:
    """:func:`hyst_id.identify.identify` of one recording in a worker thread (ROS-free).

    The same function as ``hyst-id identify``, so the same settings and
    seeds give the same result. ``workers == 1`` runs the seeds one after
    the other in the thread; otherwise ``identify`` runs them in worker
    processes and the thread only waits. :meth:`progress` is safe to call
    from another thread at any time.
    """

    def __init__(self, rec: Recording, spec: ChainSpec, settings: IdentifySettings) -> None:
        self.rec, self.spec, self.settings = rec, spec, settings
        self.seeds = tuple(settings.seeds)
        self.runs: list[SeedRun] = []
        self.result: Identification | None = None
        self.error: str | None = None
        self.started = time.monotonic()
        self._thread = threading.Thread(target=self._run, name='identify', daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            self.result = identify(self.rec, spec=self.spec, settings=self.settings,
                                   progress=self._progress)
        except HystIdError as exc:
            self.error = str(exc)
        except Exception as exc:  # noqa: BLE001 - reported by the node, never a traceback
            self.error = f'{type(exc).__name__}: {exc}'

    def _progress(self, done: int, total: int, run: SeedRun) -> None:
        self.runs = self.runs + [run]

    @property
    def done(self) -> bool:
        """True once the thread has ended with a result or an error."""
        return not self._thread.is_alive() and (self.result is not None
                                                or self.error is not None)

    def progress(self) -> dict[str, Any]:
        """Seeds done, best %e_r so far, elapsed time."""
        runs = self.runs
        out: dict[str, Any] = {'seeds_done': len(runs), 'seeds': len(self.seeds),
                               'elapsed_s': time.monotonic() - self.started}
        if runs:
            out['best_er_percent'] = min(r.er_percent for r in runs)
        return out

    def wait(self, timeout: float | None = None) -> bool:
        """Block until done (tests); return whether it is."""
        self._thread.join(timeout)
        return self.done


def compensator_set(ident: Identification) -> tuple[dict | None, float, str]:
    """The parameter set to hand to the compensator, its %e_r, and a note.

    The best run's canonical set when the compensator accepts it (the usual
    case); otherwise the best seed whose canonical set it accepts, with a
    note saying why; ``(None, nan, reason)`` when no seed's set is valid.
    """
    best = dict(ident.params, output_sign=float(getattr(ident, 'output_sign', 1.0)))
    try:
        InverseModel.from_mapping(best)
        return best, float(ident.er_percent), ''
    except InvalidParametersError as exc:
        reason = str(exc)
    for run in sorted(ident.runs, key=lambda r: r.fun):
        values = dict(zip(ident.names, (float(x) for x in run.x)))
        values['output_sign'] = float(getattr(run, 'sign', 1.0))
        try:
            InverseModel.from_mapping(values)
        except InvalidParametersError:
            continue
        return values, float(run.er_percent), (
            f'the best canonical set is not a valid compensator model ({reason}); using seed '
            f'{run.seed} (%e_r {run.er_percent:.4g}) instead')
    return None, float('nan'), f'no seed gave a valid compensator model: {reason}'


def result_document(ident: Identification, n_samples: int, duration_s: float) -> dict:
    """JSON-ready summary published on the identified-parameters topic.

    ``params`` and ``er_percent`` are the identification's (as ``hyst-id
    identify`` reports them); ``compensator_params`` / ``compensator_er_percent``
    are the set the compensator should use (see :func:`compensator_set`).
    """
    comp, comp_er, note = compensator_set(ident)
    return {
        'compensator_params': comp, 'compensator_er_percent': comp_er,
        'compensator_note': note,
        'channel': ident.channel, 'params': ident.params, 'er_percent': ident.er_percent,
        'output_sign': float(getattr(ident, 'output_sign', 1.0)),
        'params_mean': ident.params_mean,
        'er_mean_params_percent': ident.er_mean_params_percent,
        'noise_floor_percent': ident.noise_floor_percent,
        'er_seeds_percent': [r.er_percent for r in ident.runs],
        'seeds': [r.seed for r in ident.runs], 'n_samples': int(n_samples),
        'duration_s': float(duration_s), 'domain_source': ident.domain_source,
        'settings': ident.to_dict()['settings'], 'source': ident.source,
        'identified_at': datetime.datetime.now(datetime.timezone.utc).isoformat(),
    }


# --------------------------------------------------------------------- node
class Identifier(HystNode):
    """Collect samples, identify the chain with GAASS, publish and push the result."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('identifier', PARAMS, **kwargs)
        v = self.param_values()
        self.channel = v['channel']
        self.buffer = SampleBuffer(v['max_samples'])
        self.job: IdentificationJob | None = None
        self.last_identification: Identification | None = None
        self.last_document: dict | None = None
        self.last_error = ''
        self.on_identified: Callable[[dict], None] | None = None
        self._eor_tried = False
        self._identify_requested = False
        self._push: tuple[list, float] | None = None
        self._cmd_field = parse_field_path(v['topics.command_field'])
        self._meas_field = parse_field_path(v[f'topics.{self.channel}_field'])
        self._meas_topic = v[f'topics.{self.channel}_topic']
        meas_type = v[f'topics.{self.channel}_type']
        self._stamp_header = v['topics.stamp_source'] == 'header'
        self._units = (TopicConfig().command_unit,
                       TopicConfig.for_channel(self.channel).measurement_unit)
        self.params_out = Path(v['params_out']).expanduser() if v['params_out'] \
            else default_params_out()
        # Best effort like every sensor subscriber, but with a deep queue: samples that
        # arrive while the executor is busy (GIL held by the identification thread or
        # the JIT warm-up) wait in the queue instead of being dropped.
        meas_qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=SENSOR_QUEUE_DEPTH,
                              reliability=(ReliabilityPolicy.RELIABLE
                                           if v['measurement_reliable']
                                           else ReliabilityPolicy.BEST_EFFORT))
        self.create_subscription(Float64, v['topics.command_topic'], self._on_command,
                                 COMMAND_QOS)
        self.create_subscription(message_class(meas_type), self._meas_topic,
                                 self._on_measurement, meas_qos)
        self._result_pub = self.create_publisher(String, v['topics.identified_params_topic'],
                                                 LATCHED_QOS)
        self._client = None
        if Trigger is not None:
            self.create_service(Trigger, '~/identify', self._on_trigger)
        self._warm = ThreadPoolExecutor(max_workers=1, thread_name_prefix='jit-warm-up')
        self._warm_future = self._warm.submit(_warm_up, self.channel)
        self.create_timer(0.02, self._tick)
        self.create_timer(1.0, self._status)
        self.get_logger().info(
            f'identifying {self.channel} from {v["topics.command_topic"]} + {self._meas_topic}'
            f' ({meas_type} {v[f"topics.{self.channel}_field"]}); trigger: end of run after '
            f'{v["end_of_run_timeout_s"]:g} s idle, identify_now:=true'
            + (', ~/identify service' if Trigger is not None else ''))
        if v['recover_on_start'] and self.params_out.is_file():
            self._recover()

    # ---------------------------------------------------------------- params
    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        dom = values['domains']
        if 'domains' in changed and dom not in ('auto', 'paper') \
                and not Path(dom).expanduser().is_file():
            return f"domains must be 'auto', 'paper' or an existing YAML file; got {dom!r}"
        return None

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        if 'identify_now' in changed and values['identify_now']:
            self._identify_requested = True
        if 'max_samples' in changed and hasattr(self, 'buffer'):
            self.buffer.max_samples = values['max_samples']

    # ------------------------------------------------------------- samples
    def _stamp(self, msg: Any, info: dict) -> int:
        if self._stamp_header and hasattr(msg, 'header'):
            ns = stamp_ns(msg.header.stamp)
            if ns:
                return ns
        return int(info.get('source_timestamp') or 0) or int(
            info.get('received_timestamp') or 0) or self.get_clock().now().nanoseconds

    def _on_command(self, msg: Float64, info: dict) -> None:
        if self.p('collect'):
            self.buffer.add_command(self._stamp(msg, info), get_field(msg, self._cmd_field))

    def _on_measurement(self, msg: Any, info: dict) -> None:
        if not self.p('collect'):
            return
        try:
            value = float(get_field(msg, self._meas_field))
        except (AttributeError, IndexError, KeyError, TypeError, ValueError) as exc:
            self.get_logger().warning(f'{self._meas_topic}: cannot read the measurement '
                                      f'field ({exc})', throttle_duration_sec=5.0)
            return
        self.buffer.add_measurement(self._stamp(msg, info), value)
        self._eor_tried = False

    # -------------------------------------------------------------- trigger
    def _on_trigger(self, request: Any, response: Any) -> Any:
        response.success, response.message = self.request_identification('service call')
        return response

    def request_identification(self, why: str) -> tuple[bool, str]:
        """Start identifying the samples collected so far; return (started, message)."""
        log = self.get_logger()
        if self.job is not None:
            return False, 'an identification is already running'
        n = self.buffer.n_measurements
        if n < self.p('min_samples'):
            return False, f'only {n} samples collected (min_samples {self.p("min_samples")})'
        try:
            rec = self.buffer.recording(self.channel, f'live: {self.p("topics.command_topic")}'
                                        f', {self._meas_topic}', self._units)
            rec = validate_recording(rec)
            spec = make_spec(argparse.Namespace(domains=self.p('domains')), rec)
            settings = self.settings()
            self.job = IdentificationJob(rec, spec, settings)
        except HystIdError as exc:
            self._fail(f'cannot identify ({why}): {exc}')
            if self.p('clear_after_identify'):
                self.buffer.clear()
            return False, str(exc)
        if self.p('clear_after_identify'):
            self.buffer.clear()
        s = self.job.settings
        msg = (f'identifying {self.channel} ({why}): {rec.n_samples} samples over '
               f'{rec.duration_s:.1f} s, {len(s.seeds)} seed(s) x {s.maxiter} generations '
               f'(N_pop {s.pop_size}), '
               + ('in a worker thread' if s.workers == 1 else 'in worker processes'))
        log.info(msg)
        return True, msg

    def settings(self) -> IdentifySettings:
        """GAASS settings from the parameters, built as ``hyst-id identify`` builds them."""
        bound = self.p('er_bound_percent')
        return make_settings(argparse.Namespace(
            seeds=self.p('seeds'), seed_offset=self.p('seed_offset'),
            pop_size=self.p('pop_size'), generations=self.p('generations'), c=self.p('c'),
            xi=self.p('xi'), workers=self.p('workers'), gaass_only=not self.p('refine'),
            er_bound=bound if bound > 0 else None))

    def _fail(self, message: str) -> None:
        self.last_error = message
        self.get_logger().error(message)
        self.publish_diagnostics(2, message, {'samples': self.buffer.n_measurements})

    # ----------------------------------------------------------------- tick
    def _tick(self) -> None:
        if self._identify_requested:
            self._identify_requested = False
            ok, message = self.request_identification('identify_now')
            if not ok:
                self.get_logger().warning(f'identify_now: {message}')
            self.set_parameters([Parameter('identify_now', value=False)])
        timeout = self.p('end_of_run_timeout_s')
        last = self.buffer.last_rx
        if (self.job is None and timeout > 0 and not self._eor_tried and last is not None
                and time.monotonic() - last >= timeout):
            self._eor_tried = True
            if self.buffer.n_measurements >= self.p('min_samples'):
                self.request_identification(f'end of run, {timeout:g} s without samples')
        if self.job is not None and self.job.done:
            job, self.job = self.job, None
            if job.error:
                self._fail(f'identification failed: {job.error}')
            else:
                self._publish_result(job)
        self._push_pending()

    def _publish_result(self, job: IdentificationJob) -> None:
        ident = job.result
        self.last_identification = ident
        doc = result_document(ident, job.rec.n_samples, job.rec.duration_s)
        self.last_document = doc
        self.last_error = ''
        self._result_pub.publish(String(data=json.dumps(doc)))
        elapsed = time.monotonic() - job.started
        self.get_logger().info(
            f'identified {ident.channel} in {elapsed:.1f} s: %e_r {ident.er_percent:.3f} '
            f'(noise floor {ident.noise_floor_percent:.3f}); ' + ', '.join(
                f'{n}={ident.params[n]:.4g}' for n in ident.names))
        comp, comp_er = doc['compensator_params'], doc['compensator_er_percent']
        if doc['compensator_note']:
            (self.get_logger().warning if comp else self.get_logger().error)(
                doc['compensator_note'])
        self.publish_diagnostics(0 if comp else 2, f'identified {ident.channel}: %e_r '
                                 f'{ident.er_percent:.3f}' + (
                                     '' if comp else '; no valid compensator model'),
                                 {'er_percent': ident.er_percent, 'elapsed_s': elapsed})
        if comp is not None:
            try:
                write_compensator_params({'channel': ident.channel, 'params': comp,
                                          'er_percent': comp_er}, self.params_out)
                self.get_logger().info(f'wrote {self.params_out}')
            except HystIdError as exc:
                self.get_logger().error(f'cannot write the params file: {exc}')
            if self.p('compensator_node'):
                params = [Parameter(n, value=float(comp[n]))
                          for n in COMPENSATOR_NAMES + ('output_sign',)]
                params += [Parameter('er_percent', value=comp_er),
                           Parameter('channel', value=ident.channel)]
                self._push = (params, time.monotonic() + self.p('push_timeout_s'))
        if self.on_identified is not None:
            self.on_identified(doc)

    def _push_pending(self) -> None:
        if self._push is None:
            return
        params, deadline = self._push
        name = self.p('compensator_node').rstrip('/') + '/set_parameters_atomically'
        if self._client is None or self._client.srv_name != name:
            if self._client is not None:
                self.destroy_client(self._client)
            self._client = self.create_client(SetParametersAtomically, name)
        if not self._client.service_is_ready():
            if time.monotonic() > deadline:
                self.get_logger().warning(f'{name} not available: parameters not pushed (they '
                                          'are on the latched topic and in the params file)')
                self._push = None
            return
        self._push = None
        future = self._client.call_async(SetParametersAtomically.Request(
            parameters=[p.to_parameter_msg() for p in params]))
        future.add_done_callback(lambda f, n=name: self._pushed(f, n))

    def _pushed(self, future: Future, name: str) -> None:
        try:
            result = future.result().result
        except Exception as exc:  # noqa: BLE001 - a failed call is logged, not raised
            self.get_logger().warning(f'{name} failed: {exc}')
            return
        if result.successful:
            self.get_logger().info(f'pushed the parameters to {name}')
        else:
            self.get_logger().warning(f'{name} rejected the parameters: {result.reason}')

    def _recover(self) -> None:
        try:
            values = read_compensator_params(self.params_out)
        except ConfigError as exc:
            self.get_logger().warning(f'no recovery from {self.params_out}: {exc}')
            return
        if values['channel'] != self.channel:
            return
        params = {n: values[n] for n in COMPENSATOR_NAMES + ('output_sign',)}
        doc = {'channel': values['channel'], 'params': params, 'compensator_params': params,
               'output_sign': values['output_sign'],
               'er_percent': values['er_percent'],
               'compensator_er_percent': values['er_percent'],
               'source': f'recovered from {self.params_out}'}
        self.last_document = doc
        self._result_pub.publish(String(data=json.dumps(doc)))
        self.get_logger().info(f'republished the parameter set of {self.params_out} '
                               f'(%e_r {values["er_percent"]:.3g})')

    def _status(self) -> None:
        values: dict[str, Any] = {'samples': self.buffer.n_measurements,
                                  'channel': self.channel}
        if self.job is not None:
            prog = self.job.progress()
            values.update(prog)
            msg = (f'identifying: {prog["seeds_done"]}/{prog["seeds"]} seeds done, '
                   f'{prog["elapsed_s"]:.1f} s')
            if 'best_er_percent' in prog:
                msg += f', best %e_r {prog["best_er_percent"]:.3f}'
            self.publish_diagnostics(0, msg, values)
        elif self.last_error:
            self.publish_diagnostics(2, self.last_error, values)
        else:
            state = 'collecting' if self.p('collect') else 'idle'
            if self.last_document:
                values['last_er_percent'] = self.last_document['er_percent']
            self.publish_diagnostics(0, f'{state}: {self.buffer.n_measurements} samples',
                                     values)

    def destroy_node(self) -> None:
        """Stop workers, then the node."""
        if hasattr(self, '_warm'):    # also called on a node whose __init__ failed
            self._warm.shutdown(wait=False, cancel_futures=True)
        super().destroy_node()


def _warm_up(channel: str) -> None:
    """Compile (or load from cache) the numba kernels off the executor thread."""
    spec = chain_spec(channel)
    t = np.arange(8) * 0.1
    v = np.array([1.0, 2.0, 3.0, 2.0, 1.0, 2.0, 3.0, 2.0])
    x = np.array([[1.01, 1.05, 0.1, 0.15, -0.25, 0.5, 14.0, 7.0, 1.0, -0.2, 0.2, 1.0, 1.0,
                   1.0][:spec.n_params]])
    spec.cost_function(t, v, v)(x)
    spec.signal(x[0], t, v)


def main(args: list[str] | None = None) -> int:
    """Run the identifier until Ctrl-C / SIGTERM."""
    if not init_ros(args, 'identifier'):
        return 2
    node = None
    try:
        node = Identifier()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except HystIdError as exc:
        rclpy.logging.get_logger('identifier').error(str(exc))
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
