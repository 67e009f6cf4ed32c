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

"""ROS 2 nodes of hyst_id (one per module) and what they share.

Shared here: the QoS of each kind of stream, the default topic names, a
declarative parameter table (:class:`Param`) that every node declares with a
``ParameterDescriptor`` (description, range, read-only) and validates in one
on-set-parameters callback (:class:`HystNode`), and a DiagnosticArray helper.

QoS per stream:

* sensor data (position, pressure, flow): ``qos_profile_sensor_data``
  (best effort, depth 5);
* commands (command, desired): reliable, volatile, depth 100;
* identified parameters: reliable, transient local, depth 1 (latched);
* ``/diagnostics``: reliable, depth 10.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib
import math
import sys
from typing import Any, Iterable, Mapping, Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                SetParametersResult)
import rclpy
from rclpy.exceptions import (InvalidParameterTypeException, InvalidParameterValueException,
                              ParameterException)
from rclpy.node import Node
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, qos_profile_sensor_data, QoSProfile,
                       ReliabilityPolicy)

from hyst_id.errors import ConfigError
from hyst_id.io.readers import TopicConfig
from hyst_id.io.recording import CHANNELS

__all__ = [
    'COMMAND_QOS', 'DESIRED_TOPIC', 'DIAGNOSTICS_QOS', 'DIAGNOSTICS_TOPIC', 'HystNode',
    'IDENTIFIED_PARAMS_TOPIC', 'LATCHED_QOS', 'Param', 'SENSOR_QOS', 'TOPIC_KEYS',
    'diagnostic_array', 'init_ros', 'message_class', 'stamp_ns', 'topic_params',
]

#: Desired output fed to the compensator (std_msgs/Float64).
DESIRED_TOPIC = '/hyst_id/desired'
#: Latched JSON of the last identification (std_msgs/String).
IDENTIFIED_PARAMS_TOPIC = '/hyst_id/identified_params'
#: Standard diagnostics topic (diagnostic_msgs/DiagnosticArray).
DIAGNOSTICS_TOPIC = '/diagnostics'

SENSOR_QOS = qos_profile_sensor_data
COMMAND_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
DIAGNOSTICS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE)

_TYPE_NAMES = {bool: 'a bool', int: 'an integer', float: 'a double', str: 'a string',
               list: 'an array'}


@dataclass(frozen=True)
class Param:
    """One ROS parameter: default, description, and what values are valid.

    ``low``/``high`` become a FloatingPointRange or IntegerRange (inclusive);
    ``choices`` restricts a string; ``read_only`` marks structural parameters
    (topic names, channel) that only a params file or the command line sets.
    """

    name: str
    default: Any
    description: str
    low: float | None = None
    high: float | None = None
    read_only: bool = False
    choices: tuple[str, ...] = ()
    unit: str = ''

    def descriptor(self) -> ParameterDescriptor:
        """Return the ParameterDescriptor declared for this parameter."""
        text = self.description + (f' [{self.unit}]' if self.unit else '')
        d = ParameterDescriptor(description=text, read_only=self.read_only)
        if self.choices:
            d.additional_constraints = 'one of: ' + ', '.join(self.choices)
        if self.low is not None and self.high is not None:
            if isinstance(self.default, bool):
                pass
            elif isinstance(self.default, int):
                d.integer_range = [IntegerRange(from_value=int(self.low),
                                                to_value=int(self.high), step=0)]
            elif isinstance(self.default, float):
                d.floating_point_range = [FloatingPointRange(
                    from_value=float(self.low), to_value=float(self.high), step=0.0)]
        return d

    def check(self, value: Any) -> str | None:
        """Return why ``value`` is invalid for this parameter, or None."""
        if self.choices and value not in self.choices:
            return f'{self.name} must be one of {", ".join(self.choices)}; got {value!r}'
        if self.low is not None and isinstance(value, (int, float)) \
                and not isinstance(value, bool):
            high = math.inf if self.high is None else self.high
            if not (math.isfinite(value) and self.low <= value <= high):
                return (f'{self.name} must be in [{self.low:g}, {high:g}]'
                        f'{" " + self.unit if self.unit else ""}; got {value!r}')
        return None


#: Topic-name keys of ``params/topics.yaml`` declared as ``topics.<key>``.
TOPIC_KEYS = ('command_topic',) + tuple(f'{ch}_topic' for ch in CHANNELS)


def topic_params(keys: Iterable[str] = TOPIC_KEYS) -> list[Param]:
    """Read-only ``topics.<key>`` parameters with the defaults of ``params/topics.yaml``."""
    out = []
    for key in keys:
        if key == 'command_topic':
            default = TopicConfig().command_topic
        else:
            default = TopicConfig.for_channel(key[:-len('_topic')]).measurement_topic
        out.append(Param(f'topics.{key}', default,
                         f'topic name ({key.replace("_", " ")})', read_only=True))
    return out


def message_class(type_name: str) -> type:
    """Import a message class from ``pkg/msg/Name`` (or ``pkg/Name``)."""
    parts = [p for p in str(type_name).split('/') if p]
    if len(parts) == 2:
        parts = [parts[0], 'msg', parts[1]]
    if len(parts) != 3:
        raise ConfigError(f'bad message type {type_name!r}: expected pkg/msg/Name')
    try:
        module = importlib.import_module(f'{parts[0]}.{parts[1]}')
        return getattr(module, parts[2])
    except (ImportError, AttributeError):
        raise ConfigError(f'message type {type_name} is not installed') from None


def init_ros(args: list[str] | None, name: str) -> bool:
    """``rclpy.init``; on bad command-line arguments print one line and return False."""
    try:
        rclpy.init(args=args)
    except Exception as exc:  # noqa: BLE001 - rcl's RCLError for a malformed --ros-args
        print(f'{name}: error: {_first_line(exc)}', file=sys.stderr)
        return False
    return True


def stamp_ns(stamp: Any) -> int:
    """Nanoseconds of a ``builtin_interfaces/Time``."""
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def diagnostic_array(node: Node, name: str, level: int | bytes, message: str,
                     values: Mapping[str, Any] | None = None) -> DiagnosticArray:
    """Build a one-status DiagnosticArray stamped now."""
    status = DiagnosticStatus(name=name, hardware_id=node.get_fully_qualified_name(),
                              message=message)
    status.level = level if isinstance(level, bytes) else bytes([int(level)])
    for key, val in (values or {}).items():
        text = f'{val:.6g}' if isinstance(val, float) else str(val)
        status.values.append(KeyValue(key=str(key), value=text))
    arr = DiagnosticArray()
    arr.header.stamp = node.get_clock().now().to_msg()
    arr.status.append(status)
    return arr


class HystNode(Node):
    """A Node whose parameters come from a :class:`Param` table.

    Parameters
    ----------
    node_name : str
        Default node name (remappable with ``__node:=``).
    params : sequence of Param
        Parameters to declare; defaults are those of the table unless
        ``defaults`` overrides them (a params file still wins over both).
    defaults : mapping, optional
        Per-instance default values (used by ``bringup`` to run several
        instances of one node with different roles).
    **kwargs
        Passed to :class:`rclpy.node.Node`.

    Subclasses override :meth:`validate_params` (cross-parameter checks,
    return a reason string to reject) and :meth:`apply_params` (act on an
    accepted change). Startup values are validated too: an invalid params
    file raises :class:`~hyst_id.errors.ConfigError`.
    """

    def __init__(self, node_name: str, params: Sequence[Param],
                 defaults: Mapping[str, Any] | None = None, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self._param_table = {p.name: p for p in params}
        self._diag_pub = None
        defaults = dict(defaults or {})
        unknown = set(defaults) - set(self._param_table)
        if unknown:
            raise ConfigError(f'{node_name}: unknown parameter defaults {sorted(unknown)}')
        for p in params:
            default = defaults.get(p.name, p.default)
            try:
                self.declare_parameter(p.name, default, p.descriptor())
            except InvalidParameterTypeException as exc:
                raise ConfigError(
                    f'parameter {p.name} must be {_TYPE_NAMES.get(type(default), "")} '
                    f'(like {default!r}); the params file gives another type '
                    f'({_first_line(exc)})') from None
            except (InvalidParameterValueException, ParameterException) as exc:
                raise ConfigError(f'parameter {p.name}: {_first_line(exc)}') from None
        values = self.param_values()
        reason = self._check_all(values, set(values))
        if reason:
            raise ConfigError(f'invalid parameters: {reason}')
        self.add_on_set_parameters_callback(self._on_set_parameters)

    # --------------------------------------------------------------- params
    def param_values(self) -> dict[str, Any]:
        """Current values of every declared table parameter."""
        return {name: self.get_parameter(name).value for name in self._param_table}

    def p(self, name: str) -> Any:
        """Current value of parameter ``name``."""
        return self.get_parameter(name).value

    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        """Return why the candidate parameter ``values`` are invalid, or None."""
        return None

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        """Act on an accepted change (``values`` are the new values of all parameters)."""

    def _check_all(self, values: dict[str, Any], changed: set[str]) -> str | None:
        for name in sorted(changed):
            spec = self._param_table.get(name)
            if spec is not None:
                reason = spec.check(values[name])
                if reason:
                    return reason
        return self.validate_params(values, changed)

    def _on_set_parameters(self, params: list) -> SetParametersResult:
        values = self.param_values()
        changed = set()
        for prm in params:
            if prm.name in self._param_table:
                values[prm.name] = prm.value
                changed.add(prm.name)
        if not changed:
            return SetParametersResult(successful=True)
        try:
            reason = self._check_all(values, changed)
        except Exception as exc:  # noqa: BLE001 - a bad value must never kill the node
            reason = f'{type(exc).__name__}: {_first_line(exc)}'
        if reason:
            self.get_logger().warning(f'rejected parameter change '
                                      f'{", ".join(sorted(changed))}: {reason}')
            return SetParametersResult(successful=False, reason=reason)
        self.apply_params(values, changed)
        return SetParametersResult(successful=True)

    # ---------------------------------------------------------- diagnostics
    def publish_diagnostics(self, level: int, message: str,
                            values: Mapping[str, Any] | None = None) -> None:
        """Publish one DiagnosticStatus named ``hyst_id: <node name>``."""
        if self._diag_pub is None:
            self._diag_pub = self.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC,
                                                   DIAGNOSTICS_QOS)
        self._diag_pub.publish(diagnostic_array(self, f'hyst_id: {self.get_name()}', level,
                                                message, values))


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
