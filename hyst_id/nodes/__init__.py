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
* commands (command, desired): reliable, volatile, **keep all**: a
  subscriber that falls behind never loses a command silently. Its unread
  samples wait in its reader cache (Fast DDS: up to 5000, i.e. a 5 s stall
  at 1 kHz); beyond that the publisher blocks for up to the writer's
  ``max_blocking_time`` (100 ms) and then ``publish`` fails with an error
  (:func:`try_publish` turns that into a count the node reports). A
  keep-last queue would instead overwrite the oldest unread command without
  telling anyone (a depth-100 queue lost 280 of 5000 commands at 1 kHz);
* identified parameters: reliable, transient local, depth 1 (latched);
* ``/diagnostics``: reliable, depth 10.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib
import math
import sys
import time
from typing import Any, Iterable, Mapping, Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                SetParametersResult)
from rcl_interfaces.srv import SetParametersAtomically
import rclpy
from rclpy.exceptions import (InvalidParameterTypeException, InvalidParameterValueException,
                              ParameterException)
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, qos_profile_sensor_data, QoSProfile,
                       ReliabilityPolicy)

from hyst_id.errors import ConfigError, HystIdError
from hyst_id.io.readers import TopicConfig
from hyst_id.io.recording import CHANNELS

__all__ = [
    'spin_node',
    'COMMAND_QOS', 'DESIRED_TOPIC', 'DIAGNOSTICS_QOS', 'DIAGNOSTICS_TOPIC', 'HystNode',
    'IDENTIFIED_PARAMS_TOPIC', 'LATCHED_QOS', 'Param', 'ParameterPusher', 'SENSOR_QOS',
    'TOPIC_KEYS',
    'diagnostic_array', 'field_params', 'init_ros', 'message_class', 'source_time_ns',
    'stamp_ns', 'topic_params', 'try_publish',
]

#: Desired output fed to the compensator (std_msgs/Float64).
DESIRED_TOPIC = '/hyst_id/desired'
#: Latched JSON of the last identification (std_msgs/String).
IDENTIFIED_PARAMS_TOPIC = '/hyst_id/identified_params'
#: Standard diagnostics topic (diagnostic_msgs/DiagnosticArray).
DIAGNOSTICS_TOPIC = '/diagnostics'

SENSOR_QOS = qos_profile_sensor_data
COMMAND_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
DIAGNOSTICS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE)

_RCLError = _rclpy.RCLError
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


def field_params() -> list[Param]:
    """Read-only ``topics.command_field`` and ``topics.<channel>_type`` / ``_field``."""
    out = [Param('topics.command_field', TopicConfig().command_field,
                 'field of the command message', read_only=True)]
    for ch in CHANNELS:
        cfg = TopicConfig.for_channel(ch)
        out += [Param(f'topics.{ch}_type', cfg.measurement_type, f'message type of {ch}',
                      read_only=True),
                Param(f'topics.{ch}_field', cfg.measurement_field, f'field of the {ch} message',
                      read_only=True)]
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


def try_publish(publisher: Any, msg: Any) -> bool:
    """Publish ``msg``; return False instead of raising when the middleware refuses it.

    With :data:`COMMAND_QOS` (reliable, keep all) ``publish`` blocks while a
    subscriber's reader cache is full and fails after the writer's
    ``max_blocking_time``; the caller counts and reports the failure (or
    retries) instead of dying in a callback.
    """
    try:
        publisher.publish(msg)
    except _RCLError:
        return False
    return True


def source_time_ns(node: Node, info: Mapping[str, Any]) -> int:
    """A message's source timestamp (from the middleware), else its receive time, else now."""
    return int(info.get('source_timestamp') or 0) or int(
        info.get('received_timestamp') or 0) or node.get_clock().now().nanoseconds


def spin_node(node_class: type, name: str, args: list[str] | None = None) -> int:
    """Init, spin and shut down one node: the body of every node's ``main()``.

    The demo_nodes_py pattern: Ctrl-C and an external shutdown (SIGTERM) end
    the spin quietly; a :class:`~hyst_id.errors.HystIdError` raised while the
    node is built (a bad params file) is logged in one line with exit code 2;
    the node is always destroyed and the context shut down.
    """
    if not init_ros(args, name):
        return 2
    node = None
    try:
        node = node_class()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except HystIdError as exc:
        rclpy.logging.get_logger(name).error(str(exc))
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


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
        #: Parameter changes rejected since the start.
        self.rejected_updates = 0
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
            self.rejected_updates += 1
            self.get_logger().warning(f'rejected parameter change '
                                      f'{", ".join(sorted(changed))}: {reason}')
            return SetParametersResult(successful=False, reason=reason)
        self.apply_params(values, changed)
        return SetParametersResult(successful=True)

    # ---------------------------------------------------------- diagnostics
    def publish_diagnostics(self, level: int, message: str,
                            values: Mapping[str, Any] | None = None,
                            extra: Sequence[DiagnosticStatus] = ()) -> None:
        """Publish a DiagnosticStatus named ``hyst_id: <node name>`` (then ``extra``)."""
        if self._diag_pub is None:
            self._diag_pub = self.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC,
                                                   DIAGNOSTICS_QOS)
        arr = diagnostic_array(self, f'hyst_id: {self.get_name()}', level, message, values)
        arr.status.extend(extra)
        try_publish(self._diag_pub, arr)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


class ParameterPusher:
    """Send a parameter list to another node's ``set_parameters_atomically``.

    :meth:`push` queues one request (replacing a pending one); :meth:`poll`,
    called from a timer of ``node``, sends it once the service is up, or
    drops it with a warning after ``timeout_s``. The answer is logged
    (rejections with the target's reason); nothing ever blocks the executor.
    """

    def __init__(self, node: Node) -> None:
        self.node = node
        self._client = None
        self._pending: tuple[str, list[Parameter], float] | None = None

    def push(self, target_node: str, params: list[Parameter], timeout_s: float) -> None:
        """Queue ``params`` for ``<target_node>/set_parameters_atomically``."""
        name = target_node.rstrip('/') + '/set_parameters_atomically'
        self._pending = (name, params, time.monotonic() + timeout_s)

    def poll(self) -> None:
        """Send the pending request if its service is ready (call from a timer)."""
        if self._pending is None:
            return
        name, params, deadline = self._pending
        if self._client is None or self._client.srv_name != name:
            if self._client is not None:
                self.node.destroy_client(self._client)
            self._client = self.node.create_client(SetParametersAtomically, name)
        if not self._client.service_is_ready():
            if time.monotonic() > deadline:
                self.node.get_logger().warning(
                    f'{name} not available: parameters not pushed (they are on the latched '
                    'topic and in the params file)')
                self._pending = None
            return
        self._pending = None
        future = self._client.call_async(SetParametersAtomically.Request(
            parameters=[p.to_parameter_msg() for p in params]))
        future.add_done_callback(lambda f, n=name: self._done(f, n))

    def _done(self, future: Any, name: str) -> None:
        log = self.node.get_logger()
        try:
            result = future.result().result
        except Exception as exc:  # noqa: BLE001 - a failed call is logged, not raised
            log.warning(f'{name} failed: {exc}')
            return
        if result.successful:
            log.info(f'pushed the parameters to {name}')
        else:
            log.warning(f'{name} rejected the parameters: {result.reason}')
