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

"""Small ROS helpers the nodes share: init, spin, publish, stamps, message types.

:func:`spin_node` is the body of every node's ``main()`` (init, spin,
shutdown); the rest turn middleware failures and type names into values
and one-line errors.
"""

from __future__ import annotations

from contextlib import contextmanager
import importlib
import signal
import sys
import threading
import time
from typing import Any, Callable, Iterator, Mapping, Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
import rclpy
from rclpy.exceptions import ParameterNotDeclaredException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

from hyst_id.errors import ConfigError, HystIdError

__all__ = ['EXIT_SIGINT', 'check_field', 'diagnostic_array', 'exit_code_after', 'first_line',
           'init_ros',
           'input_problems', 'message_class', 'qos_mismatch', 'resolved', 'source_time_ns',
           'spin_in_background', 'spin_node', 'spin_until_stopped', 'stamp_ns', 'stop_signals',
           'try_publish', 'publisher_mismatches']

_RCLError = _rclpy.RCLError


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


def check_field(cls: type, path: tuple, param: str) -> None:
    """Raise ConfigError when the field path ``path`` (parsed) cannot be in ``cls``'s messages.

    Checks the first name of the path (indices and nested names depend on
    the message's contents); ``param`` names the parameter in the error.
    """
    fields = list(getattr(cls, 'get_fields_and_field_types', dict)())
    if path and isinstance(path[0], str) and fields and path[0] not in fields:
        raise ConfigError(f'{param}: {cls.__module__.split(".")[0]}/msg/{cls.__name__} has no '
                          f'field {path[0]!r} (fields: {", ".join(fields)})')


def init_ros(args: list[str] | None, name: str) -> bool:
    """``rclpy.init``; on bad command-line arguments print one line and return False."""
    try:
        # our own SIGINT/SIGTERM handlers (stop_signals) end the spin loop; rclpy's would
        # shut the context down under a running callback
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # noqa: BLE001 - rcl's RCLError for a malformed --ros-args
        print(f'{name}: error: {first_line(exc)}', file=sys.stderr)
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
    """When an unstamped message was sent.

    With ``use_sim_time`` (a replay publishing ``/clock``) the node's ROS
    clock, i.e. the bag's time; otherwise the middleware's source timestamp,
    else the receive time, else now.
    """
    if _uses_sim_time(node):
        return node.get_clock().now().nanoseconds
    return int(info.get('source_timestamp') or 0) or int(
        info.get('received_timestamp') or 0) or node.get_clock().now().nanoseconds


def _uses_sim_time(node: Node) -> bool:
    try:
        return bool(node.get_parameter('use_sim_time').value)
    except ParameterNotDeclaredException:   # pragma: no cover - rclpy always declares it
        return False


#: Longest wait of the spin loop between two looks at the stop flag [s].
SPIN_PERIOD_S = 0.1
#: Exit code after SIGINT (Ctrl-C), as a shell reports it; SIGTERM is a requested stop (0).
EXIT_SIGINT = 130


@contextmanager
def stop_signals() -> Iterator[dict[str, int]]:
    """SIGINT and SIGTERM only record themselves: ``{'signal': signum}`` (0 until one came).

    The spin loop (:func:`spin_until_stopped`) looks at the flag every
    :data:`SPIN_PERIOD_S`, so a stop is never lost in a wait (no timer, no
    traffic) nor raised inside a callback; the previous handlers come back
    on exit.
    """
    state = {'signal': 0}

    def handler(signum: int, frame: Any) -> None:
        state['signal'] = state['signal'] or signum

    previous = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            previous[sig] = signal.signal(sig, handler)
    try:
        yield state
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def spin_until_stopped(executor: Any, state: Mapping[str, int],
                       done: Callable[[], bool] = lambda: False) -> None:
    """Spin in :data:`SPIN_PERIOD_S` slices until a signal, ``done()`` or a shutdown."""
    while not state['signal'] and not done() and executor.context.ok():
        executor.spin_once(timeout_sec=SPIN_PERIOD_S)


def exit_code_after(state: Mapping[str, int], code: int) -> int:
    """``code``, or :data:`EXIT_SIGINT` after Ctrl-C (a SIGTERM stop keeps ``code``)."""
    return EXIT_SIGINT if state['signal'] == signal.SIGINT else code


def spin_node(node_class: type, name: str, args: list[str] | None = None) -> int:
    """Init, spin and shut down one node: the body of every node's ``main()``.

    The demo_nodes_py pattern, with stops that cannot hang: SIGINT/SIGTERM
    set a flag (:func:`stop_signals`) that the loop reads every 0.1 s, also
    when they land while the node is being built; an ``RCLError`` from a
    context shut down under the executor ends the spin quietly; a
    :class:`~hyst_id.errors.HystIdError` raised while the node is built (a bad
    params file) is logged in one line with exit code 2; the node is always
    destroyed (its workers ended) and the context shut down. Exit code: the
    node's ``exit_code`` (e.g. the replay when its bag is unreadable), else
    0; 130 after Ctrl-C.
    """
    if not init_ros(args, name):
        return 2
    node = None
    code = 0
    with stop_signals() as state:
        try:
            # made before the node (the slow part), so a signal during construction
            # cannot leave a half-built executor behind
            executor = SingleThreadedExecutor()
            node = node_class()
            executor.add_node(node)
            spin_until_stopped(executor, state)
        except (KeyboardInterrupt, ExternalShutdownException):
            state['signal'] = state['signal'] or signal.SIGINT
        except HystIdError as exc:
            rclpy.logging.get_logger(name).error(str(exc))
            code = 2
        except _RCLError as exc:
            # a context shut down while the executor builds its wait set surfaces as
            # RCLError, not as an external shutdown
            if rclpy.ok() and not state['signal']:
                print(f'{name}: error: {first_line(exc)}', file=sys.stderr)
                code = 1
        finally:
            if node is not None:
                code = code or int(getattr(node, 'exit_code', 0) or 0)
                node.destroy_node()
            rclpy.try_shutdown()
        return exit_code_after(state, code)


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


def publisher_mismatches(node: Node, topic: str, expected: str) -> list[str]:
    """Publishers on ``topic`` this node never hears from, in words: wrong type or QoS.

    ``topic`` may be relative (the node's namespace and remaps apply);
    ``expected`` is a full type name such as ``std_msgs/msg/Float64``. A
    subscriber never receives what a publisher of another type sends, nor
    what a best-effort publisher sends to its reliable subscription, nor a
    volatile publisher to its transient-local one (the middleware does not
    match them), so without this check either is silence.
    """
    try:
        name = node.resolve_topic_name(topic)
        infos = node.get_publishers_info_by_topic(name)
        mine = [i.qos_profile for i in node.get_subscriptions_info_by_topic(name)
                if i.node_name == node.get_name()
                and i.node_namespace == node.get_namespace()]
    except Exception:  # noqa: BLE001 - a graph query must never stop the node
        return []
    out = set()
    for i in infos:
        who = i.node_namespace.rstrip('/') + '/' + i.node_name
        if i.topic_type != expected:
            out.add(f'{who} publishes {i.topic_type}')
            continue
        for sub in mine:
            why = qos_mismatch(sub, i.qos_profile)
            if why:
                out.add(f'{who} publishes {why}')
    return sorted(out)


def qos_mismatch(sub: Any, pub: Any) -> str:
    """Why a publisher's QoS ``pub`` does not reach a subscription's ``sub`` ('' if it does)."""
    if (sub.reliability == ReliabilityPolicy.RELIABLE
            and pub.reliability == ReliabilityPolicy.BEST_EFFORT):
        return ('best effort to this reliable subscription (QoS incompatible: make the '
                "publisher reliable, or override this subscription's reliability)")
    if (sub.durability == DurabilityPolicy.TRANSIENT_LOCAL
            and pub.durability == DurabilityPolicy.VOLATILE):
        return 'volatile to this transient-local (latched) subscription (QoS incompatible)'
    return ''


def input_problems(node: Node, expected: Sequence[tuple[str, str]], rx: Mapping[str, float],
                   started: float, timeout_s: float, topics: Mapping[str, str]) -> list[str]:
    """Inputs of a wrong type, or one of two inputs arriving while the other does not.

    ``expected`` holds ``(topic, type)`` pairs; ``rx`` the monotonic time each
    input (``'command'``, ``'measurement'``) was last received, ``started``
    the node's start (monotonic) and ``topics`` each input's topic.
    """
    out = []
    for topic, want in expected:
        for m in publisher_mismatches(node, topic, want):
            out.append(f'{resolved(node, topic)}: {m}, expected {want} (never received)')
    now = time.monotonic()
    if now - started > timeout_s:
        live = {k for k, t in rx.items() if now - t < timeout_s}
        for have, lack in (('command', 'measurement'), ('measurement', 'command')):
            if have in live and lack not in live:
                out.append(f'{have}s arrive on {resolved(node, topics[have])} but no '
                           f'{lack} on {resolved(node, topics[lack])} for {timeout_s:g} s')
    return out


def resolved(node: Node, topic: str) -> str:
    """``topic`` as the middleware sees it: namespace and remaps applied."""
    try:
        return node.resolve_topic_name(topic)
    except Exception:  # noqa: BLE001 - only for log lines; the name itself is checked later
        return topic


def first_line(exc: BaseException) -> str:
    """First line of an exception's message (its type name when empty)."""
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def spin_in_background(executor: Any) -> Callable[[], None]:
    """Spin ``executor`` in a daemon thread until the returned ``stop()`` is called.

    For scripts and tests that drive a graph from their own thread (benchmarks,
    load tests); ``stop()`` ends the loop and joins the thread (2 s at most).
    """
    done = threading.Event()

    def loop() -> None:
        while not done.is_set():
            executor.spin_once(timeout_sec=0.01)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()

    def stop() -> None:
        done.set()
        thread.join(2.0)
    return stop
