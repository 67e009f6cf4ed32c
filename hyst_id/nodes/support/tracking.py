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

"""The compensator's tracking link: measurement subscription, tracker, events in the log.

With ``tracking.enabled`` the compensator subscribes to its channel's
measurement topic and runs :class:`hyst_id.compensation.tracking.AdaptiveCompensator`:
the reading is compared with the model's prediction for the commands sent
(through the sensor dynamics in ``tracking.*``), the plant's slow gain and
offset are tracked, and the desired value is corrected by them. Any change
of a ``tracking.*`` parameter restarts the estimate (and says so).
"""

from __future__ import annotations

import math
from typing import Any

from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from hyst_id.compensation import Compensator as CoreCompensator
from hyst_id.compensation.tracking import (AdaptiveCompensator, GainOffsetTracker,
                                           SensorPredictor)
from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.io.topics import parse_field_path, value_field
from hyst_id.nodes.support.field_reads import FieldReads
from hyst_id.nodes.support.params import Param
from hyst_id.nodes.support.qos import OVERRIDABLE
from hyst_id.nodes.support.ros import check_field, message_class, stamp_ns

__all__ = ['SENSOR_KEYS', 'TRACKING_PARAMS', 'TrackingLink']

#: Sensor parameters per kind, as ``tracking.<name>`` (what an identified set calls them).
SENSOR_KEYS = {'none': (), 'first_order': ('tau_s',), 'second_order': ('zeta', 'omega_n')}
_NAN = math.nan

TRACKING_PARAMS = [
    Param('tracking.enabled', False,
          "track the plant's slow gain and offset (the channel's measurement against the "
          'model prediction) and correct the desired value by them'),
    Param('tracking.sensor', 'auto', "sensor dynamics of the prediction; 'auto': the "
          "channel's (position none, pressure first_order, flow second_order)",
          choices=('auto', 'none', 'first_order', 'second_order')),
    Param('tracking.tau_s', _NAN, 'first-order sensor time constant; .nan = unset', unit='s'),
    Param('tracking.zeta', _NAN, 'second-order sensor damping ratio; .nan = unset'),
    Param('tracking.omega_n', _NAN, 'second-order sensor natural frequency; .nan = unset',
          unit='rad/s'),
    Param('tracking.hold', 'before', "sensor input hold: 'before' (a command acts on the "
          "reading of its own sample) or 'after' (on the next one)",
          choices=('before', 'after')),
    Param('tracking.forget_time_s', 20.0, 'how far back the gain and offset estimate looks',
          low=0.1, high=1e6, unit='s'),
    Param('tracking.min_excitation', 0.0, 'range of the prediction over forget_time_s below '
          'which the estimate is frozen (channel units)', low=0.0, high=1e300),
]


def sensor_predictor(values: dict[str, Any]) -> SensorPredictor:
    """The prediction's sensor from the ``tracking.*`` values and ``channel``.

    Raises
    ------
    InvalidParametersError
        A parameter the sensor needs is unset or not positive.
    """
    kind = values['tracking.sensor']
    if kind == 'auto':
        kind = SensorPredictor.CHANNEL_KIND[values['channel']]
    keys = SENSOR_KEYS[kind]
    unset = [f'tracking.{k}' for k in keys if math.isnan(values[f'tracking.{k}'])]
    if unset:
        raise InvalidParametersError(f'tracking with a {kind} sensor needs {", ".join(unset)}')
    return SensorPredictor(kind, tuple(values[f'tracking.{k}'] for k in keys),
                           values['tracking.hold'])


class TrackingLink:
    """Owns the measurement subscription and the adaptive compensator of a node."""

    def __init__(self, node: Any) -> None:
        self.node = node
        self.adaptive: AdaptiveCompensator | None = None
        self._sub = None
        self._field = None
        self._channel = ''
        #: the measurement's field read from each message; unread ones are counted and
        #: make the compensator's next status an ERROR
        self.reads = FieldReads(node.get_logger())
        #: time measurements by their header stamps (the compensator runs on stamped
        #: desired values); else by the node's clock, as unstamped desired values are
        self.use_stamps = False

    @staticmethod
    def validate(values: dict[str, Any]) -> str | None:
        """Why the tracking settings cannot run, or None."""
        if not values['tracking.enabled']:
            return None
        try:
            sensor_predictor(values)
            channel = values['channel']
            check_field(message_class(values[f'topics.{channel}_type']),
                        parse_field_path(value_field(values[f'topics.{channel}_type'],
                                                     values[f'topics.{channel}_field'])),
                        f'topics.{channel}_field')
        except (InvalidParametersError, ConfigError) as exc:
            return f'tracking: {exc}'
        return None

    def configure(self, values: dict[str, Any], comp: CoreCompensator) -> None:
        """(Re)start tracking with ``values``, or stop it."""
        log = self.node.get_logger()
        if not values['tracking.enabled']:
            if self.adaptive is not None:
                log.warning('tracking off: the desired value is no longer corrected')
            self.adaptive = None
            return
        problem = self.validate(values)
        if problem:         # at start (a set is refused in the on-set callback before)
            raise ConfigError(problem)
        channel = values['channel']
        if self._sub is not None and channel != self._channel:
            self.node.destroy_subscription(self._sub)
            self._sub = None
        if self._sub is None:
            self._channel = channel
            topic = values[f'topics.{channel}_topic']
            self._field = parse_field_path(value_field(values[f'topics.{channel}_type'],
                                                       values[f'topics.{channel}_field']))
            qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=50,
                             reliability=ReliabilityPolicy.BEST_EFFORT)
            self._sub = self.node.create_subscription(
                message_class(values[f'topics.{channel}_type']), topic, self._on_measurement,
                qos, qos_overriding_options=OVERRIDABLE)
        tracker = GainOffsetTracker(forget_time_s=values['tracking.forget_time_s'],
                                    min_excitation=values['tracking.min_excitation'])
        self.adaptive = AdaptiveCompensator(comp, tracker, sensor_predictor(values))
        log.warning(f'tracking on ({self.adaptive.sensor.kind} sensor, forgetting '
                    f'{tracker.forget_time_s:g} s): estimate restarted at gain 1, offset 0')

    def step(self, desired: float, t_s: float) -> float:
        """Command for ``desired`` with the tracked correction."""
        return self.adaptive.step(desired, t_s)

    def _on_measurement(self, msg: Any) -> None:
        if self.adaptive is None:
            return
        value = self.reads.read('measurement', 'tracking', msg, self._field)
        if value is None:
            return
        if not math.isfinite(value):      # counted: the node's next status is an ERROR
            self.node.note_non_finite('measurement (tracking)')
            return
        header = getattr(msg, 'header', None)
        ns = stamp_ns(header.stamp) if self.use_stamps and header is not None else 0
        t_s = (ns or self.node.get_clock().now().nanoseconds) * 1e-9
        self.adaptive.observe(value, t_s)
        self._log_events()

    def _log_events(self) -> None:
        events = self.adaptive.tracker.events
        log = self.node.get_logger()
        while events:        # drained here, so a node running for days keeps no history
            e = events.pop(0)
            text = (f'tracking {e.state} at t={e.t_s:.3f} s: {e.reason} (gain {e.gain:.4g}, '
                    f'offset {e.offset:.4g})')
            if e.state == 'tracking':      # rclpy wants one severity per call site
                log.info(text)
            else:
                log.warning(text)

    def status(self) -> dict[str, Any]:
        """Key values for ``/diagnostics``."""
        if self.adaptive is None:
            return {'tracking': 'off'}
        tr = self.adaptive.tracker
        return {'tracking': tr.state, 'tracking_gain': tr.gain, 'tracking_offset': tr.offset,
                'tracking_rate_per_s': tr.rate_per_s,
                'tracking_unreadable_samples': self.reads.count.get('measurement', 0)}
