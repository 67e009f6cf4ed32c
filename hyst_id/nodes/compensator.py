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

"""Compensator node: desired output -> B^-1 -> H^-1 -> command, sample by sample.

Parameters ``m_l ... c_b`` (hysteresis) and ``m_bl c_bl c_br`` (backlash),
canonical gauge, are ordinary ROS parameters. A change is validated as a
whole set: a set violating the loop constraints is rejected with the reason
and the last good set stays in use. Unset parameters are ``.nan``; while no
complete valid set exists the node passes the desired value through (within
the command limits) and says so in its log and on ``/diagnostics``.

Coupled parameters must change together: use ``set_parameters_atomically``
(the identifier does), a params file, or the latched identified-parameters
topic, which the node also follows. Each accepted change that alters the
output (model or command limits) starts a new *generation*: it applies
between two samples, to every sample from the next one on, and the node
publishes it (generation, first sample it applies to, the full set and
limits, where it came from) on the latched ``~/active_set`` topic
(std_msgs/String JSON), so which set produced which command can be checked.

With ``tracking.enabled`` the node also subscribes to its channel's
measurement topic and tracks the plant's slow gain and offset against the
model's prediction (:mod:`hyst_id.compensation.tracking`; a supply running
down, a drifting gain or sensor offset), correcting the desired value by
them; every change of the tracker's state is logged with its reason and the
estimate is on ``/diagnostics``. The sensor parameters come from
``tracking.*`` or from the identified-parameters topic. With in-line
corrections (``augment.*``) the prediction is the augmented model's, so the
tracker follows what the schedules leave; a change of the corrections
restarts the estimate.

Commands are published reliable keep-all (:data:`hyst_id.nodes.COMMAND_QOS`):
a command the middleware refuses (a subscriber stalled for seconds) is
counted and reported on ``/diagnostics`` (ERROR), never dropped silently.
"""

from __future__ import annotations

from collections import deque
import json
import math
import statistics
import time
from typing import Any

from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from hyst_id.compensation import CommandLimits, InverseModel
from hyst_id.compensation.augment import AugmentedCompensator
from hyst_id.compensation.inverse import warm_up
from hyst_id.compensation.params_file import (ALL_MODEL_NAMES, compensator_names,
                                              NODE_COMMAND_LIMITS, read_set_document)
from hyst_id.errors import InvalidParametersError
from hyst_id.io.recording import CHANNELS
from hyst_id.models.registry import DEFAULT_FAMILY, FAMILIES, get_family
from hyst_id.nodes.support import (
    COMMAND_QOS,
    DESIRED_TOPIC,
    field_params,
    HystNode,
    IDENTIFIED_PARAMS_TOPIC,
    input_problems,
    LATCHED_QOS,
    OVERRIDABLE,
    Param,
    resolved,
    scalar_type_param,
    ScalarStream,
    spin_node,
    stamp_ns,
    TOPIC_KEYS,
    topic_params,
    try_publish,
)
from hyst_id.nodes.support.augment import AUGMENT_PARAMS, augmentation_from_values
from hyst_id.nodes.support.tracking import SENSOR_KEYS, TRACKING_PARAMS, TrackingLink

try:  # optional: std_srvs is not a dependency of the package
    from std_srvs.srv import SetBool, Trigger
except ImportError:  # pragma: no cover - depends on the installation
    SetBool = Trigger = None

__all__ = ['ACTIVE_SET_QOS', 'Compensator', 'PARAMS', 'main']

_NAN = math.nan
_MODEL_KEYS = set(ALL_MODEL_NAMES) | {'output_sign', 'family'}
_LIMIT_KEYS = {'min_command', 'max_command', 'max_rate_per_s'}
SENSOR_NAMES = tuple(k for keys in SENSOR_KEYS.values() for k in keys)
#: ``~/active_set``: every generation, late joiners get the last 100.
ACTIVE_SET_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                            durability=DurabilityPolicy.TRANSIENT_LOCAL)
_DESCRIPTIONS = {
    'm_l': 'hysteresis left-line slope', 'm_r': 'hysteresis right-line slope',
    'm_t': 'hysteresis top-line slope', 'm_b': 'hysteresis bottom-line slope',
    'c_l': 'hysteresis left-line crossing', 'c_r': 'hysteresis right-line crossing',
    'c_t': 'hysteresis top-line intercept', 'c_b': 'hysteresis bottom-line intercept',
    'm_bl': 'backlash slope (1 in the canonical gauge)', 'c_bl': 'backlash left crossing',
    'c_br': 'backlash right crossing',
    # every other family's parameters (one module each, hyst_id.models.registry)
    **{n: f'{f} family: {get_family(f).descriptions.get(n, n)}' for f in FAMILIES
       for n in get_family(f).names if f != DEFAULT_FAMILY},
}
_UNITS = {'m_l': 'out/mA', 'm_r': 'out/mA', 'm_t': 'out/mA', 'm_b': 'out/mA', 'c_l': 'mA',
          'c_r': 'mA', 'c_t': 'out', 'c_b': 'out', 'm_bl': '1', 'c_bl': 'out', 'c_br': 'out',
          **{n: u.replace('cmd', 'mA') for f in FAMILIES if f != DEFAULT_FAMILY
             for n, u in get_family(f).units.items()}}

PARAMS = [
    Param('channel', 'position', 'measured channel the model was identified on; '
          'identified-parameter messages of another channel are ignored', choices=CHANNELS),
    Param('family', DEFAULT_FAMILY, "H's family of the set: 'tk' (the paper's loop) or "
          "'smooth' (Prandtl-Ishlinskii); only that family's parameters are used",
          choices=tuple(FAMILIES)),
    *[Param(n, _NAN, _DESCRIPTIONS.get(n, n) + '; .nan = unset', unit=_UNITS.get(n, ''))
      for n in ALL_MODEL_NAMES],
    Param('output_sign', 1.0, 'sign of the sensor gain (canonical calibration): -1 when the '
          'measurement falls as the actuator output rises', low=-1.0, high=1.0),
    Param('er_percent', _NAN, '%e_r (Eq. 7) of the identification; information only'),
    Param('min_command', NODE_COMMAND_LIMITS[0], 'lowest command sent', low=-1e6, high=1e6,
          unit='mA'),
    Param('max_command', NODE_COMMAND_LIMITS[1], 'highest command sent', low=-1e6, high=1e6,
          unit='mA'),
    Param('max_rate_per_s', 0.0, 'largest command change per second; 0 = unlimited',
          low=0.0, high=1e9, unit='mA/s'),
    Param('initial_command', 9.0, 'command the actuator holds before the first sample',
          low=-1e6, high=1e6, unit='mA'),
    Param('follow_identified_params', True,
          'apply parameter sets published on the identified-parameters topic (relative: the '
          "node's namespace's identifier)"),
    Param('require_model', False, 'without a valid parameter set, hold initial_command (or the '
          'last command) instead of passing the desired value through, and report ERROR'),
    Param('diagnostics_period_s', 1.0, 'period of the /diagnostics status', low=0.05,
          high=3600.0, unit='s'),
    *topic_params(TOPIC_KEYS),
    *field_params(),
    *TRACKING_PARAMS,
    *AUGMENT_PARAMS,
    Param('topics.desired_topic', DESIRED_TOPIC, 'desired output topic (topics.desired_type)',
          read_only=True),
    scalar_type_param('topics.desired_type', 'desired output stream'),
    Param('topics.identified_params_topic', IDENTIFIED_PARAMS_TOPIC,
          'latched identified parameters (std_msgs/String, JSON)', read_only=True),
]


def _limits(values: dict[str, Any]) -> CommandLimits:
    rate = values['max_rate_per_s']
    return CommandLimits(min_command=values['min_command'], max_command=values['max_command'],
                         max_rate_per_s=rate if rate > 0 else math.inf)


def _model_state(values: dict[str, Any]) -> tuple[str, InverseModel | None, list[str]]:
    """Classify the model parameters: ('none'|'incomplete'|'valid', model, unset names).

    Only the parameters of ``values['family']`` count; the other families' are ignored.
    """
    names = compensator_names(values['family'])
    unset = [n for n in names if math.isnan(values[n])]
    if len(unset) == len(names):
        return 'none', None, unset
    if unset:
        return 'incomplete', None, unset
    mapping = {n: values[n] for n in names + ('output_sign', 'family')}
    return 'valid', InverseModel.from_mapping(mapping), []


class Compensator(HystNode):
    """Inverse hysteresis + backlash compensation between desired and command topics."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('compensator', PARAMS, **kwargs)
        values = self.param_values()
        kind, model, unset = _model_state(values)
        if model is not None:
            warm_up(model)
        self._comp = AugmentedCompensator(model, augmentation_from_values(values),
                                          _limits(values), v0=values['initial_command'])
        self._desired = ScalarStream(values['topics.desired_type'])
        self._command = ScalarStream(values['topics.command_type'])
        self._tracking = TrackingLink(self)
        self._tracking.use_stamps = self._desired.stamped
        self._tracking.configure(values, self._comp)
        self._source = 'params' if model is not None else ''
        self._n = 0
        self._not_sent = 0
        self._generation = 0
        self._step_ns: deque[int] = deque(maxlen=2000)
        self._cmd_pub = self.create_publisher(self._command.cls, self.p('topics.command_topic'),
                                              COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        self._set_pub = self.create_publisher(String, '~/active_set', ACTIVE_SET_QOS)
        self._publish_active_set('parameters at start')
        self.create_subscription(self._desired.cls, self.p('topics.desired_topic'),
                                 self._on_desired,
                                 COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        self.create_subscription(String, self.p('topics.identified_params_topic'),
                                 self._on_identified, LATCHED_QOS)
        self._diag_timer = self.create_steady_timer(values['diagnostics_period_s'],
                                                    self._publish_status)
        if SetBool is not None:
            self.create_service(SetBool, '~/bypass', self._on_bypass)
            self.create_service(Trigger, '~/reset', self._on_reset)
        log = self.get_logger()
        log.info(f'compensating {resolved(self, self.p("topics.desired_topic"))} -> '
                 f'{self._cmd_pub.topic_name}, command in [{values["min_command"]:g}, '
                 f'{values["max_command"]:g}] mA'
                 + ''.join(f'; {what} {stream.type_name}' for what, stream in (
                     ('desired', self._desired), ('command', self._command)) if stream.stamped)
                 + (f'; following {resolved(self, self.p("topics.identified_params_topic"))}'
                    if values['follow_identified_params'] else ''))
        without = ('holding the initial command (require_model)' if values['require_model']
                   else 'passing the desired value through unchanged')
        if model is not None:
            log.info(f'model from parameters: {self._describe(values)}')
            if self._comp.augmentation.active:
                log.info(f'in-line corrections: {self._comp.augmentation.describe()}')
        elif kind == 'incomplete':
            (log.error if values['require_model'] else log.warning)(
                f'parameter set incomplete (unset: {", ".join(unset)}): {without}')
        else:
            (log.error if values['require_model'] else log.warning)(
                f'no parameter set yet: {without} until one arrives (parameters'
                + (', identified-params topic)' if values['follow_identified_params'] else ')'))

    # ---------------------------------------------------------------- params
    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        if not values['min_command'] < values['max_command']:
            return (f'min_command ({values["min_command"]:g}) must be < max_command '
                    f'({values["max_command"]:g})')
        if 'initial_command' in changed and not (
                values['min_command'] <= values['initial_command'] <= values['max_command']):
            return (f'initial_command ({values["initial_command"]:g}) must lie within '
                    f'[min_command, max_command] = [{values["min_command"]:g}, '
                    f'{values["max_command"]:g}]: the actuator holds it before the first sample')
        tracking = TrackingLink.validate(values)
        if tracking:
            return tracking
        augment_changed = any(n.startswith('augment.') for n in changed)
        if augment_changed or changed & _LIMIT_KEYS or 'tracking.enabled' in changed:
            try:
                aug = augmentation_from_values(values)
                aug.limits(_limits(values))
            except InvalidParametersError as exc:
                return f'{exc}; keeping the last limits and corrections'
        if changed & _MODEL_KEYS and not augment_changed and getattr(self, '_comp', None) \
                is not None and self._comp.augmentation.has_output_map:
            return ("the in-line output map (augment.poly_*) belongs to the diagnosis's own "
                    'set, whose H and B output its normalised travel: give a new set together '
                    'with its augment.* values (identity poly_c0..c3 = 0, 1, 0, 0 to clear it)')
        if values['output_sign'] not in (1.0, -1.0):
            return f'output_sign must be 1.0 or -1.0; got {values["output_sign"]!r}'
        er = values['er_percent']
        if 'er_percent' in changed and not (math.isnan(er) or 0.0 <= er < math.inf):
            return f'er_percent must be >= 0 (or .nan); got {er!r}'
        if 'channel' in changed and getattr(self, '_comp', None) is not None \
                and self._comp.model is not None \
                and not set(compensator_names(values['family'])) <= changed:
            return (f'channel changes only together with a new parameter set (the set in use '
                    f'was identified on {self.p("channel")!r})')
        if changed & _MODEL_KEYS:
            names = compensator_names(values['family'])
            inf = [n for n in names if math.isinf(values[n])]
            if inf:
                return f'{", ".join(inf)} must be finite (or .nan for unset)'
            try:
                kind, _, unset = _model_state(values)
            except InvalidParametersError as exc:     # at startup there is no set to keep
                running = getattr(self, '_comp', None) is not None
                return f'{exc}' + ('; keeping the last good set' if running else '')
            if kind == 'incomplete' and getattr(self, '_comp', None) is not None \
                    and self._comp.model is not None:
                return (f'incomplete {values["family"]} set (unset: {", ".join(unset)}): '
                        f'give all {len(names)} parameters together; keeping the last good '
                        'set')
        return None

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        if not hasattr(self, '_comp'):
            return
        before = (self._comp.model, self._comp.limits, self._comp.augmentation)
        if any(n.startswith('augment.') for n in changed) or changed & _LIMIT_KEYS:
            aug = augmentation_from_values(values)
            self._comp.configure(aug, _limits(values))     # both or neither (validated)
            if aug != before[2]:
                src = self._source_hint or 'set_parameters'
                self.get_logger().warning(f'in-line corrections from {src}: {aug.describe()}')
        if 'diagnostics_period_s' in changed:
            self._diag_timer.cancel()
            self.destroy_timer(self._diag_timer)
            self._diag_timer = self.create_steady_timer(values['diagnostics_period_s'],
                                                        self._publish_status)
        source = self._source_hint or 'set_parameters'
        self._source_hint = ''
        # the tracked gain and offset are what the corrections left: new ones, a new estimate
        if any(n.startswith('tracking.') for n in changed) or (
                self._tracking.adaptive is not None and ('channel' in changed
                                                         or self._comp.augmentation != before[2])):
            self._tracking.configure(values, self._comp)
        if changed & _MODEL_KEYS:
            kind, model, unset = _model_state(values)
            if model is None or model != self._comp.model:
                if model is not None:
                    warm_up(model)   # compile before the first real sample, not on it
                self._comp.set_model(model)
                if model is not None:
                    self._source = source
                    self.get_logger().warning(f'applied parameter set from {source}: '
                                              f'{self._describe(values)}')
                elif kind == 'none':
                    self._source = ''
                    self.get_logger().warning('parameter set cleared: passing the desired '
                                              'value through unchanged')
                else:
                    self.get_logger().info(f'parameter set incomplete (unset: '
                                           f'{", ".join(unset)})')
        if (self._comp.model, self._comp.limits, self._comp.augmentation) != before:
            self._generation += 1
            self._publish_active_set(source, values)

    def _publish_active_set(self, source: str, values: dict[str, Any] | None = None) -> None:
        """Publish the set in use from the next sample on (``~/active_set``)."""
        values = values or self.param_values()
        model = self._comp.model
        lim = self._comp.limits
        doc = {'generation': self._generation, 'first_sample': self._n, 'source': source,
               'channel': values['channel'],
               'model': None if model is None else {
                   n: values[n] for n in compensator_names(values['family'])
                   + ('output_sign', 'family')},
               'min_command': lim.min_command, 'max_command': lim.max_command,
               'max_rate_per_s': None if math.isinf(lim.max_rate_per_s)
               else lim.max_rate_per_s,
               'augment': {k: (None if isinstance(v, float) and math.isinf(v) else v)
                           for k, v in self._comp.augmentation.as_mapping().items()}
               if self._comp.augmentation.active else None}
        try_publish(self._set_pub, String(data=json.dumps(doc)))

    _source_hint = ''

    @staticmethod
    def _describe(values: dict[str, Any]) -> str:
        er = values.get('er_percent', _NAN)
        head = f'channel {values["channel"]}' + ('' if math.isnan(er) else f', %e_r {er:.3g}')
        if values.get('output_sign', 1.0) < 0:
            head += ', output_sign -1'
        names = compensator_names(values['family'])
        return (head + f', family {values["family"]}: '
                + ', '.join(f'{n}={values[n]:.6g}' for n in names))

    # ------------------------------------------------------------- callbacks
    def _on_desired(self, msg: Any) -> None:
        # a stamped desired value acts at its stamp (schedules run on it, the command
        # carries it); an unstamped one now (a message of it only for a stamped command)
        stamp = self._desired.stamp(msg)
        if stamp is None:
            now = self.get_clock().now()
            t_s = now.nanoseconds * 1e-9
            stamp = now.to_msg() if self._command.stamped else None
        else:
            t_s = stamp_ns(stamp) * 1e-9
        desired = self._desired.value(msg)
        t0 = time.perf_counter_ns()
        if self._comp.model is None and self.p('require_model'):
            v = self._comp.state[0]           # hold: no model, no pass-through
        elif self._tracking.adaptive is not None and self._comp.model is not None \
                and not self._comp.bypass:
            v = self._tracking.step(desired, t_s)
        else:
            v = self._comp.step(desired, t_s)
        self._step_ns.append(time.perf_counter_ns() - t0)
        self._n += 1
        if not try_publish(self._cmd_pub, self._command.make(v, stamp)):
            self._not_sent += 1
            self.get_logger().error(f'{self._not_sent} command(s) refused by the middleware '
                                    '(a subscriber stalled?)', throttle_duration_sec=1.0)
        if not math.isfinite(desired):
            self.note_non_finite('desired value (the last command is held)')

    def set_bypass(self, on: bool) -> str:
        """Pass the desired value through (on) or compensate again (off); the reason.

        While bypassed the model state keeps following the commands sent, so
        compensation resumes from the actuator's real state.
        """
        self._comp.bypass = bool(on)
        msg = ('bypass on: passing the desired value through (the model state follows)'
               if on else 'bypass off: compensating again')
        self.get_logger().warning(msg)
        return msg

    def reset_state(self) -> str:
        """Forget the loop's memory: the model state restarts on the rising boundary."""
        v = self._comp.state[0]
        self._comp.reset(v)
        msg = f'model state reset on the rising boundary at command {v:g}'
        self.get_logger().warning(msg)
        return msg

    def _on_bypass(self, request: Any, response: Any) -> Any:
        response.message, response.success = self.set_bypass(request.data), True
        return response

    def _on_reset(self, request: Any, response: Any) -> Any:
        response.message, response.success = self.reset_state(), True
        return response

    def _on_identified(self, msg: String) -> None:
        if not self.p('follow_identified_params'):
            return
        log = self.get_logger()
        try:
            doc = json.loads(msg.data)
            if not isinstance(doc, dict):
                raise ValueError(f'a JSON object was expected, got {type(doc).__name__}')
            if 'compensator_params' in doc and doc['compensator_params'] is None:
                log.warning('identified parameters not handed over: '
                            + str(doc.get('compensator_note') or 'no compensator set'))
                return
            if str(doc.get('source', '')).startswith('recovered') \
                    and self._source in ('params', 'set_parameters'):
                log.warning(f'ignored the identifier\'s {doc["source"]}: this compensator\'s '
                            f'set was loaded on purpose ({self._source}) and stays')
                return
            channel, values, er = read_set_document(doc, SENSOR_NAMES)
        except ValueError as exc:       # json's own errors are ValueErrors too
            self.note_refused('identified parameters', f'not the expected JSON: {exc}')
            return
        if channel != self.p('channel'):
            log.info(f'ignored identified parameters of channel {channel!r} (this compensator '
                     f'is for {self.p("channel")!r})')
            return
        current = self.param_values()
        if all(current[n] == values[n] for n in values):
            return
        self._source_hint = 'identified-params topic'
        result = self.set_parameters_atomically(
            [Parameter(n, value=v) for n, v in values.items()]
            + [Parameter('er_percent', value=er)])
        self._source_hint = ''
        if not result.successful:
            self.note_refused('identified parameters', result.reason, counted=False)

    def _publish_status(self) -> None:
        model = self._comp.model
        steps = list(self._step_ns)
        median_us = statistics.median(steps) / 1e3 if steps else _NAN
        values = {'channel': self.p('channel'), 'samples': self._n,
                  'compute_median_us': median_us, 'source': self._source or 'none',
                  'er_percent': self.p('er_percent'), 'command': self._comp.state[0],
                  'generation': self._generation, 'rejected_updates': self.rejected_updates,
                  'bypass': self._comp.bypass,
                  'commands_not_sent': self._not_sent, 'non_finite_inputs': self.non_finite_seen,
                  **self._tracking.status()}
        inputs = [(self.p('topics.desired_topic'), self._desired.type_name)]
        if self._tracking.adaptive is not None:     # the measurement tracking reads
            ch = self.p('channel')
            inputs.append((self.p(f'topics.{ch}_topic'), self.p(f'topics.{ch}_type')))
        wrong = input_problems(self, inputs, {}, 0.0, math.inf, {})
        wrong += [w for w in [self.non_finite_problem()] if w] + self._tracking.reads.problems()
        if wrong:
            text = '; '.join(wrong)
            self.get_logger().error(text, throttle_duration_sec=10.0)
            self.publish_diagnostics(2, text, values)
        elif self._not_sent:
            self.publish_diagnostics(2, f'{self._not_sent} command(s) could not be sent (a '
                                     'subscriber stalled?)', values)
        elif self._comp.bypass:
            self.publish_diagnostics(1, 'bypassed: passing the desired value through (~/bypass)',
                                     values)
        elif model is None and self.p('require_model'):
            self.publish_diagnostics(2, 'no valid parameter set and require_model: holding '
                                     'the command', values)
        elif model is None:
            self.publish_diagnostics(1, 'no valid parameter set: passing the desired value '
                                     'through unchanged', values)
        elif self.refused_note:             # the last set from the topic: the one before stays
            self.publish_diagnostics(1, self.refused_note + '; the set before it stays', values)
        else:
            self.publish_diagnostics(0, f'compensating ({self.p("channel")})', values)

    @property
    def model(self) -> InverseModel | None:
        """The parameter set in use (None: pass-through)."""
        return self._comp.model

    def step(self, desired: float, t_s: float | None = None) -> float:
        """Compensate one sample without ROS (tests, benchmarks)."""
        return self._comp.step(desired, t_s)


def main(args: list[str] | None = None) -> int:
    """Run the compensator node until Ctrl-C / SIGTERM."""
    return spin_node(Compensator, 'compensator', args)


if __name__ == '__main__':
    raise SystemExit(main())
