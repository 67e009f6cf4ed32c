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

"""HystNode: a Node whose parameters come from a table of :class:`~.params.Param`."""

from __future__ import annotations

import math
import time
from typing import Any, Iterable, Mapping, Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType
from rclpy.exceptions import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterException,
    ParameterUninitializedException,
)
from rclpy.node import Node
from rclpy.parameter import Parameter

from hyst_id.errors import ConfigError
from hyst_id.io.topics import NODE_STREAM_KEYS, TOPIC_FILE_KEYS
from hyst_id.nodes.support.params import Param
from hyst_id.nodes.support.qos import DIAGNOSTICS_QOS, DIAGNOSTICS_TOPIC
from hyst_id.nodes.support.ros import (
    diagnostic_array,
    first_line,
    input_problems,
    resolved,
    try_publish,
)

__all__ = ['HystNode', 'unknown_overrides', 'widened_integers']

_TYPE_NAMES = {bool: 'a bool', int: 'an integer', float: 'a double', str: 'a string',
               list: 'an array'}


#: Stream-type keys a ``/**`` params file may give every node (params/stamped.yaml):
#: the nodes that carry the stream declare them, the others ignore them.
STREAM_TYPE_KEYS = tuple(sorted(f'topics.{k}' for k in NODE_STREAM_KEYS))
#: Parameters rclpy itself reads, and prefixes of parameter families it owns.
_ROS_OWN = frozenset({'use_sim_time', 'start_type_description_service'})
_ROS_OWN_PREFIXES = ('qos_overrides.',)


def widened_integers(params: Iterable[Parameter], float_names: frozenset[str]
                     ) -> list[tuple[str, Parameter]]:
    """``(name, double parameter)`` for each integer given to a double parameter.

    rclpy refuses ``max_command: 20`` for a double; the value is the same
    number, so it is taken as ``20.0``. Integer arrays stay refused.
    """
    return [(prm.name, Parameter(prm.name, Parameter.Type.DOUBLE, float(prm.value)))
            for prm in params
            if prm.name in float_names and prm.type_ == Parameter.Type.INTEGER]


def unknown_overrides(overrides: Iterable[str], declared: Iterable[str]) -> list[str]:
    """Names given by a params file or ``-p`` that no parameter of the node matches.

    Keys of the shared ``params/topics.yaml`` (``topics.<channel>_topic`` ...,
    given to every node through ``/**``), :data:`STREAM_TYPE_KEYS` and
    rclpy's own parameters are not unknown; anything else (a typo such as
    ``max_comand``, another node's key) is.
    """
    declared = set(declared)
    shared = {f'topics.{k}' for k in TOPIC_FILE_KEYS} | set(STREAM_TYPE_KEYS)
    return sorted(n for n in overrides if n not in declared and n not in shared
                  and n not in _ROS_OWN and not n.startswith(_ROS_OWN_PREFIXES))


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
    file raises :class:`~hyst_id.errors.ConfigError`. A params-file key no
    parameter matches (:func:`unknown_overrides`) is logged as an error and
    reported every second on ``/diagnostics`` (ERROR, status
    ``hyst_id: <node>: parameters``) for the node's life: it was ignored.

    Housekeeping timers (status, discovery, end-of-run detection) are made
    with :meth:`create_steady_timer`: under ``use_sim_time`` a ROS-time timer
    stands still until ``/clock`` moves and again after a replay ends.
    """

    def __init__(self, node_name: str, params: Sequence[Param],
                 defaults: Mapping[str, Any] | None = None, report_unknown: bool = True,
                 **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self._param_table = {p.name: p for p in params}
        self._diag_pub = None
        self.non_finite_seen, self._non_finite_new = 0, False
        #: Parameter changes rejected since the start.
        self.rejected_updates = 0
        #: Words for the last input refused (a parameter set from a topic); '' once a
        #: parameter change is accepted.
        self.refused_note = ''
        defaults = dict(defaults or {})
        unknown = set(defaults) - set(self._param_table)
        if unknown:
            raise ConfigError(f'{node_name}: unknown parameter defaults {sorted(unknown)}')
        self._float_names = frozenset(
            p.name for p in params
            if isinstance(defaults.get(p.name, p.default), float))
        # a whole number for a double (``max_command: 20``, ``-p gain:=1``) is the same value
        overrides = getattr(self, '_parameter_overrides', {})
        for name, given in widened_integers(overrides.values(), self._float_names):
            overrides[name] = given
        self.add_pre_set_parameters_callback(self._widen_integers)
        for p in params:
            default = defaults.get(p.name, p.default)
            try:
                self.declare_parameter(p.name, default, p.descriptor())
            except InvalidParameterTypeException as exc:
                raise ConfigError(
                    f'parameter {p.name} must be {_TYPE_NAMES.get(type(default), "")} '
                    f'(like {default!r}); the params file or -p gives another type '
                    f'({first_line(exc)})') from None
            except (InvalidParameterValueException, ParameterException) as exc:
                raise ConfigError(f'parameter {p.name}: {first_line(exc)}') from None
            try:
                self.get_parameter(p.name)
            except ParameterUninitializedException:
                raise ConfigError(f'parameter {p.name} is given no value (an empty list [] has '
                                  f'no element type in ROS 2); give it like {default!r}'
                                  ) from None
        values = self.param_values()
        reason = self._check_all(values, set(values))
        if reason:
            raise ConfigError(f'invalid parameters: {reason}')
        self.add_on_set_parameters_callback(self._on_set_parameters)
        #: Params-file / ``-p`` names that match no parameter (ignored).
        self.unknown_parameters: list[str] = []
        if report_unknown:
            self.report_unknown_parameters()

    @property
    def status_name(self) -> str:
        """The node's name on ``/diagnostics``: ``rig1/compensator`` in ``/rig1``, else its name.

        Two valves' compensators in two namespaces report apart (both were
        ``hyst_id: compensator``; found by an independent review).
        """
        ns = self.get_namespace().strip('/')
        return f'{ns}/{self.get_name()}' if ns else self.get_name()

    def create_steady_timer(self, period_s: float, callback: Any) -> Any:
        """A timer on the steady (wall) clock, whatever ``use_sim_time`` says."""
        if not hasattr(self, '_steady_clock'):
            self._steady_clock = Clock(clock_type=ClockType.STEADY_TIME)
        return self.create_timer(period_s, callback, clock=self._steady_clock)

    def report_unknown_parameters(self, declared: Iterable[str] | None = None) -> list[str]:
        """Find, log (ERROR) and keep reporting overrides no parameter matches.

        ``declared`` defaults to this node's parameters; a process running
        several nodes (``bringup``), whose ``-p`` arguments reach every node,
        passes the names all of them declare.
        """
        names = set(self._param_table) | set(declared or ())
        self.unknown_parameters = unknown_overrides(
            getattr(self, '_parameter_overrides', {}), names)
        if self.unknown_parameters and not hasattr(self, '_unknown_message'):
            self._unknown_message = (
                f'unknown parameter(s) ignored: {", ".join(self.unknown_parameters)} (a typo, '
                f'or a key of another node?); {self.get_name()} declares: '
                + ', '.join(sorted(n for n in self._param_table if not n.startswith('topics.'))))
            self.get_logger().error(self._unknown_message)
            self.create_steady_timer(1.0, self._report_unknown)
        return self.unknown_parameters

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

    def _widen_integers(self, params: list) -> list:
        widened = dict(widened_integers(params, self._float_names))
        out = [widened.get(prm.name, prm) for prm in params]
        self._say_refusals(out)
        return out

    def _say_refusals(self, params: list) -> None:
        """Log (ERROR) what rclpy will refuse before our callback sees it, in words.

        rclpy answers an unknown name with ``Invalid access to undeclared parameter(s): []``
        and a wrong type with ``expected '3' got '4'``, and logs neither (an independent
        reviewer's ``max_comand``).
        """
        for prm in params:
            if not self.has_parameter(prm.name):
                self.get_logger().error(
                    f'set_parameters: {prm.name} refused, {self.get_name()} has no such '
                    'parameter (a typo, or a key of another node?); it declares: '
                    + ', '.join(sorted(n for n in self._param_table
                                       if not n.startswith('topics.'))))
                continue
            have = self.get_parameter(prm.name).type_
            if prm.type_ != have and prm.type_ != Parameter.Type.NOT_SET:
                self.get_logger().error(
                    f'set_parameters: {prm.name} refused, it is a {have.name.lower()} and '
                    f'was given a {prm.type_.name.lower()} ({prm.value!r})')

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
            reason = f'{type(exc).__name__}: {first_line(exc)}'
        if reason:
            self.rejected_updates += 1
            self.get_logger().warning(f'rejected parameter change '
                                      f'{", ".join(sorted(changed))}: {reason}')
            return SetParametersResult(successful=False, reason=reason)
        self.refused_note = ''          # a change accepted since: the refusal is history
        self.apply_params(values, changed)
        return SetParametersResult(successful=True)

    # ---------------------------------------------------------- diagnostics
    def _report_unknown(self) -> None:
        if self._diag_pub is None:
            self._diag_pub = self.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC,
                                                   DIAGNOSTICS_QOS)
        try_publish(self._diag_pub, diagnostic_array(
            self, f'hyst_id: {self.status_name}: parameters', 2, self._unknown_message,
            {'unknown': ', '.join(self.unknown_parameters)}))

    def publish_diagnostics(self, level: int, message: str,
                            values: Mapping[str, Any] | None = None,
                            extra: Sequence[DiagnosticStatus] = ()) -> None:
        """Publish a DiagnosticStatus named ``hyst_id: <node name>`` (then ``extra``)."""
        if self._diag_pub is None:
            self._diag_pub = self.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC,
                                                   DIAGNOSTICS_QOS)
        arr = diagnostic_array(self, f'hyst_id: {self.status_name}', level, message, values)
        arr.status.extend(extra)
        try_publish(self._diag_pub, arr)

    def note_non_finite(self, what: str) -> None:
        """Count an input value that is NaN or infinite (the caller ignores it); log it.

        The node's next ``/diagnostics`` status is an ERROR naming the count
        (:meth:`non_finite_problem`).
        """
        self.non_finite_seen += 1
        self._non_finite_new = True
        self.get_logger().warning(f'ignored a non-finite {what} ({self.non_finite_seen} so '
                                  'far)', throttle_duration_sec=5.0)

    def note_refused(self, what: str, reason: str, counted: bool = True) -> None:
        """An input refused (a set from a topic): logged, kept for the status, counted.

        ``counted=False`` where the parameter callback has counted it already.
        """
        self.rejected_updates += int(counted)
        self.refused_note = f'{what} refused: {reason}'
        self.get_logger().warning(self.refused_note)

    def non_finite_problem(self) -> str:
        """Words for non-finite inputs since the last call ('' when none came)."""
        if not self._non_finite_new:
            return ''
        self._non_finite_new = False
        return f'{self.non_finite_seen} non-finite input value(s) ignored so far (NaN or inf)'

    def watch_input_types(self, expected: Sequence[tuple[str, str]],
                          period_s: float = 1.0) -> None:
        """Publish this node's ``/diagnostics`` status every ``period_s``.

        ERROR (and a log line) while a publisher of another message type than
        expected is on one of the ``(topic, type)`` inputs (the middleware
        never delivers its messages: without this, silence); OK otherwise.
        """
        started = time.monotonic()

        def check() -> None:
            problems = input_problems(self, expected, {}, started, math.inf, {})
            problems += [w for w in [self.non_finite_problem()] if w]
            if problems:
                self.get_logger().error('; '.join(problems), throttle_duration_sec=10.0)
                self.publish_diagnostics(2, '; '.join(problems))
            else:
                self.publish_diagnostics(0, 'running: ' + ', '.join(
                    f'{resolved(self, t)} ({want})' for t, want in expected))

        self.create_steady_timer(period_s, check)
