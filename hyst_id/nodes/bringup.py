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

"""Bringup: the paper's section 4 experiment as one process of ROS nodes.

One MultiThreadedExecutor runs the simulated actuator, the pipeline
simulator, the recorder, the identifier, the compensator and three
excitation nodes, and a ``bringup`` node sequences them:

1. ``excitation_identify`` drives the command with Eq. 24 while the
   recorder writes the MCAP bag and the identifier collects samples;
2. the identifier identifies (GAASS), publishes the latched parameters and
   pushes them to the compensator;
3. ``excitation_uncompensated`` drives the command with Eq. 25 directly;
4. ``excitation_compensated`` sends Eq. 25 as the desired value through
   the compensator;
5. %eps_c (Eq. 26) of both runs is printed and the process exits 0.

%eps_c compares the measured channel, mapped back through the simulated
sensor calibration into command-equivalent units, with the desired Eq. 25
value it answers. Every node reads its parameters from the same params file
(sections by node name); ``time_scale`` in the ``bringup`` section runs the
whole experiment faster than real time.

The run is the same on any machine and under any load: each excitation
waits until the measurement answering its previous sample has arrived
(lockstep, :class:`Lockstep`), the pipeline simulator advances by the
run's sample period per command rather than by wall-clock stamps
(``step_s``), and the compensator compiles its inverse before it takes
the first sample. A slow machine only takes longer.
"""

from __future__ import annotations

import datetime
import math
import signal
import sys
import time
from typing import Any

import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.task import Future

from hyst_id.errors import HystIdError
from hyst_id.io.recording import CHANNELS
from hyst_id.io.topics import parse_field_path, value_field
from hyst_id.live.buffer import SampleBuffer
from hyst_id.nodes.actuator_driver import ActuatorDriver
from hyst_id.nodes.compensator import Compensator
from hyst_id.nodes.excitation import Excitation
from hyst_id.nodes.identifier import Identifier
from hyst_id.nodes.pipeline_sim import PipelineSim
from hyst_id.nodes.recorder import Recorder
from hyst_id.nodes.support import (
    COMMAND_QOS,
    DESIRED_TOPIC,
    exit_code_after,
    HystNode,
    init_ros,
    message_class,
    Param,
    scalar_type_param,
    ScalarStream,
    SENSOR_QOS,
    spin_until_stopped,
    stamp_ns,
    stop_signals,
)
from hyst_id.nodes.support.field_reads import FieldReads

__all__ = ['Bringup', 'Lockstep', 'PARAMS', 'control_error_percent', 'main']

PARAMS = [
    Param('channel', 'position', 'channel identified and compensated', choices=CHANNELS,
          read_only=True),
    Param('time_scale', 1.0, "profile seconds per wall-clock second (1 = the paper's pace)",
          low=1e-3, high=1e4, read_only=True),
    Param('identify_duration_s', 120.0, 'length of the Eq. 24 run', low=1.0, high=1e6,
          unit='s', read_only=True),
    Param('identify_sample_period_s', 0.1, 'sampling of the Eq. 24 run', low=1e-4, high=100.0,
          unit='s', read_only=True),
    Param('compensate_duration_s', 60.0, 'length of each Eq. 25 run (paper: 60 s)', low=1.0,
          high=1e6, unit='s', read_only=True),
    Param('compensate_sample_period_s', 0.5, 'sampling of the Eq. 25 runs (paper: 0.5 s)',
          low=1e-4, high=100.0, unit='s', read_only=True),
    Param('bag', '', "bag directory to record; '' = hyst_id_bringup_<date-time>",
          read_only=True),
    Param('settle_s', 0.3, 'wall-clock pause between phases', low=0.0, high=60.0, unit='s',
          read_only=True),
    Param('timeout_s', 600.0, 'give up (exit 1) after this long', low=1.0, high=86400.0,
          unit='s', read_only=True),
    Param('lockstep_timeout_s', 2.0, 'wall-clock wait for the answer to a sample before '
          'counting it lost and going on', low=0.01, high=600.0, unit='s', read_only=True),
    scalar_type_param('topics.command_type', 'command stream'),
    scalar_type_param('topics.desired_type', 'desired output stream'),
]


class Lockstep:
    """Hold an excitation's sample ``k`` until ``k`` measurements of its run arrived.

    ``answered()`` is called for every measurement; ``ready(k)`` is the
    excitation's gate. A measurement that never comes (best-effort sensor
    data) holds the run for ``timeout_s`` of wall clock, then counts as
    lost: :attr:`lost` says how many.
    """

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = float(timeout_s)
        self.lost = 0
        self._count = 0
        self._base = 0
        self._since = time.monotonic()

    def answered(self) -> None:
        """One measurement arrived."""
        self._count += 1

    def ready(self, k: int) -> bool:
        """Whether sample ``k`` of the current run may go out."""
        now = time.monotonic()
        if k == 0:
            self._base = self._count
        missing = k - (self._count - self._base)
        if missing <= 0:
            self._since = now
            return True
        if now - self._since < self.timeout_s:
            return False
        self.lost += missing
        self._base -= missing
        self._since = now
        return True


def control_error_percent(output: np.ndarray, desired: np.ndarray) -> float:
    """%eps_c of Eq. 26: ``sqrt(sum |w - r|^2 / sum |r|^2) * 100``."""
    w = np.asarray(output, dtype=float)
    r = np.asarray(desired, dtype=float)
    return float(np.sqrt(np.sum((w - r) ** 2) / np.sum(r ** 2)) * 100.0)


class Bringup(HystNode):
    """Create the graph's nodes and sequence the experiment."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('bringup', PARAMS, report_unknown=False, **kwargs)
        v = self.param_values()
        ts, ch = v['time_scale'], v['channel']
        bag = v['bag'] or datetime.datetime.now().strftime('hyst_id_bringup_%Y_%m_%d-%H_%M_%S')
        self.done = Future()
        self.exit_code = 1
        self.results: dict[str, float] = {}
        self.actuator = ActuatorDriver(defaults={'time_scale': ts}, report_unknown=False)
        self.pipeline = PipelineSim(defaults={'time_scale': ts}, report_unknown=False)
        self.recorder = Recorder(defaults={'output': bag}, report_unknown=False)
        self.identifier = Identifier(defaults={'channel': ch, 'end_of_run_timeout_s': 0.0,
                                               'recover_on_start': False},
                                     report_unknown=False)
        self.compensator = Compensator(defaults={'channel': ch}, report_unknown=False)
        k, b = self._calibration()
        comp_profile = {'profile': 'eq25'}
        if (k, b) != (1.0, 0.0):   # desired value in the sensor's units
            comp_profile.update(offset_ma=k * 9.0 + b, amplitude_ma=k)
        common = {'time_scale': ts, 'autostart': False,
                  'topics.output_type': v['topics.command_type']}
        self.excite_identify = Excitation(
            'excitation_identify', defaults={**common, 'profile': 'eq24',
                                             'duration_s': v['identify_duration_s'],
                                             'sample_period_s': v['identify_sample_period_s']},
            report_unknown=False)
        comp = {**common, 'duration_s': v['compensate_duration_s'],
                'sample_period_s': v['compensate_sample_period_s']}
        self.excite_plain = Excitation('excitation_uncompensated',
                                       defaults={**comp, 'profile': 'eq25'},
                                       report_unknown=False)
        self.excite_comp = Excitation('excitation_compensated',
                                      defaults={**comp, **comp_profile,
                                                'topics.output_topic': DESIRED_TOPIC,
                                                'topics.output_type': v['topics.desired_type']},
                                      report_unknown=False)
        self.nodes = [self, self.actuator, self.pipeline, self.recorder, self.identifier,
                      self.compensator, self.excite_identify, self.excite_plain,
                      self.excite_comp]
        # -p arguments reach every node of the process: a name is unknown only when no
        # node of the graph declares it
        declared = {n for node in self.nodes for n in node._param_table}
        for node in self.nodes:
            node.report_unknown_parameters(declared)
        self._k, self._b = k, b
        self.lockstep = Lockstep(v['lockstep_timeout_s'])
        for exc in (self.excite_identify, self.excite_plain, self.excite_comp):
            exc.ready = self.lockstep.ready
        self._periods = {'identify': v['identify_sample_period_s'],
                         'compensate': v['compensate_sample_period_s']}
        self.pipeline.set_parameters([Parameter('step_s', value=self._periods['identify'])])
        self._field = parse_field_path(value_field(self.identifier.p(f'topics.{ch}_type'),
                                                   self.identifier.p(f'topics.{ch}_field')))
        self._reads = FieldReads(self.get_logger())   # an unreadable one is logged, not kept
        self._buffers = {'uncompensated': SampleBuffer(), 'compensated': SampleBuffer()}
        self._phase = 'start'
        self._phase_t = time.monotonic()
        self._t0 = time.monotonic()
        self._identified = False
        self.identifier.on_identified = lambda doc: setattr(self, '_identified', True)
        # the identifier's names and types (relative: the graph's namespace applies)
        self.create_subscription(message_class(self.identifier.p(f'topics.{ch}_type')),
                                 self.identifier.p(f'topics.{ch}_topic'), self._on_measurement,
                                 SENSOR_QOS)
        self._streams = {'uncompensated': ScalarStream(v['topics.command_type']),
                         'compensated': ScalarStream(v['topics.desired_type'])}
        self.create_subscription(self._streams['uncompensated'].cls,
                                 self.identifier.p('topics.command_topic'),
                                 lambda m, i: self._on_reference('uncompensated', m, i),
                                 COMMAND_QOS)
        self.create_subscription(self._streams['compensated'].cls, DESIRED_TOPIC,
                                 lambda m, i: self._on_reference('compensated', m, i),
                                 COMMAND_QOS)
        self.create_timer(0.05, self._step)
        self.get_logger().info(
            f'bringup: {ch}, time_scale {ts:g}: Eq. 24 for {v["identify_duration_s"]:g} s, '
            f'identify, then Eq. 25 for {v["compensate_duration_s"]:g} s without and with '
            f'the compensator; bag {self.recorder.path}')

    def _calibration(self) -> tuple[float, float]:
        ch = self.p('channel')
        if ch == 'pressure':
            return (self.pipeline.p('pressure_gain_pa'), self.pipeline.p('pressure_offset_pa'))
        if ch == 'flow':
            return self.pipeline.p('flow_gain_g_s'), self.pipeline.p('flow_offset_g_s')
        return 1.0, 0.0

    # -------------------------------------------------------------- samples
    def _on_measurement(self, msg: Any, info: dict) -> None:
        self.lockstep.answered()
        buf = self._buffers.get(self._phase)
        if buf is None:
            return
        t_ns = stamp_ns(msg.header.stamp) if hasattr(msg, 'header') else 0
        t_ns = t_ns or int(info.get('source_timestamp') or 0)
        value = self._reads.read('measurement', 'bringup', msg, self._field)
        if value is not None:
            buf.add_measurement(t_ns, value)

    def _on_reference(self, phase: str, msg: Any, info: dict) -> None:
        if self._phase == phase:
            stamp = self._streams[phase].stamp(msg)
            t_ns = stamp_ns(stamp) if stamp is not None else (
                int(info.get('source_timestamp') or 0) or self.get_clock().now().nanoseconds)
            self._buffers[phase].add_command(t_ns, self._streams[phase].value(msg))

    # ------------------------------------------------------------- sequence
    def _goto(self, phase: str) -> None:
        self._phase = phase
        self._phase_t = time.monotonic()

    def _step(self) -> None:
        if self.done.done():
            return
        if time.monotonic() - self._t0 > self.p('timeout_s'):
            self.get_logger().error(f'bringup timed out in phase {self._phase}')
            self.done.set_result(False)
            return
        elapsed = time.monotonic() - self._phase_t
        settle = self.p('settle_s')
        if self._phase == 'start':
            ch_topic = self.identifier.p(f'topics.{self.p("channel")}_topic')
            cmd_topic = self.identifier.p('topics.command_topic')
            if {cmd_topic, ch_topic} <= set(self.recorder.subscribed) or elapsed > 5.0:
                self.excite_identify.request_start()
                self._goto('exciting')
        elif self._phase == 'exciting':
            if self.excite_identify.finished and elapsed > 0:
                self._goto('settling')
        elif self._phase == 'settling':
            if elapsed >= settle:
                self.identifier.set_parameters([Parameter('identify_now', value=True)])
                self._goto('identifying')
        elif self._phase == 'identifying':
            if self.identifier.last_error and not self._identified:
                self.get_logger().error(f'identification failed: {self.identifier.last_error}')
                self.done.set_result(False)
            elif self._identified and self.compensator.model is not None:
                self.identifier.set_parameters([Parameter('collect', value=False)])
                self.pipeline.set_parameters(
                    [Parameter('step_s', value=self._periods['compensate'])])
                self._goto('uncompensated')
                self.excite_plain.request_start()
            elif self._identified and (
                    not (self.identifier.last_document or {}).get('compensator_params')
                    or elapsed > self.identifier.p('push_timeout_s') + 60.0):
                note = (self.identifier.last_document or {}).get('compensator_note', '')
                self.get_logger().error('the compensator has no valid parameter set after '
                                        'identification' + (f': {note}' if note else ''))
                self.done.set_result(False)
        elif self._phase in ('uncompensated', 'compensated'):
            exc = self.excite_plain if self._phase == 'uncompensated' else self.excite_comp
            if exc.finished and not getattr(self, '_wait_end', False):
                self._wait_end = True
                self._phase_t = time.monotonic()
            elif getattr(self, '_wait_end', False) and elapsed >= max(settle, 0.2):
                self._wait_end = False
                self._score(self._phase)
                if self._phase == 'uncompensated':
                    self._goto('compensated')
                    self.excite_comp.request_start()
                else:
                    self._goto('finished')
                    self._report()
                    self.done.set_result(True)

    def _score(self, phase: str) -> None:
        buf = self._buffers[phase]
        try:
            rec = buf.recording(self.p('channel'))
        except HystIdError as exc:
            self.get_logger().error(f'{phase}: {exc}')
            self.results[phase] = math.nan
            return
        w = (rec.measurement - self._b) / self._k
        r = (rec.command - self._b) / self._k
        self.results[phase] = control_error_percent(w, r)
        self.get_logger().info(f'{phase}: %eps_c {self.results[phase]:.3f} % over '
                               f'{rec.n_samples} samples')

    def _report(self) -> None:
        doc = self.identifier.last_document or {}
        ch = self.p('channel')
        lines = [
            '',
            f'hyst_id bringup: channel {ch}, time_scale {self.p("time_scale"):g}, '
            f'{time.monotonic() - self._t0:.1f} s wall clock',
            f'  identification (Eq. 24, {self.p("identify_duration_s"):g} s): %e_r '
            f'{doc.get("er_percent", math.nan):.3f} %',
            f'  %eps_c (Eq. 26), Eq. 25 for {self.p("compensate_duration_s"):g} s:',
            f'    uncompensated  {self.results.get("uncompensated", math.nan):8.3f} %',
            f'    compensated    {self.results.get("compensated", math.nan):8.3f} %',
            f'  bag: {self.recorder.path}',
            *([f'  WARNING: {self.lockstep.lost} measurement(s) never arrived (lockstep '
               'went on without them)'] if self.lockstep.lost else []),
            f'  compensator params: {self.identifier.params_out}',
        ]
        print('\n'.join(lines), flush=True)
        ok = all(math.isfinite(self.results.get(p, math.nan))
                 for p in ('uncompensated', 'compensated'))
        self.exit_code = 0 if ok else 1

    def destroy_node(self) -> None:
        """Destroy every node of the graph (the recorder finalises its bag)."""
        for node in reversed(getattr(self, 'nodes', [])[1:]):
            node.destroy_node()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the whole experiment in one process; exit 0 when it completed."""
    if not init_ros(args, 'bringup'):
        return 2
    node = None
    code = 1
    with stop_signals() as state:
        try:
            node = Bringup()
            executor = MultiThreadedExecutor(num_threads=4)
            for n in node.nodes:
                executor.add_node(n)
            spin_until_stopped(executor, state, node.done.done)
            if node.done.done():
                code = node.exit_code
            elif state['signal']:
                code = 0             # a requested stop (130 after Ctrl-C, below)
        except (KeyboardInterrupt, ExternalShutdownException):
            state['signal'] = state['signal'] or signal.SIGINT
        except HystIdError as exc:
            rclpy.logging.get_logger('bringup').error(str(exc))
            code = 2
        finally:
            if node is not None:
                node.destroy_node()
            rclpy.try_shutdown()
    sys.stdout.flush()
    return exit_code_after(state, code)


if __name__ == '__main__':
    raise SystemExit(main())
