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

"""Scalar streams (command, desired output, flow): ``std_msgs/Float64`` or stamped.

A scalar stream's message type is a read-only parameter
(``topics.command_type``, ``topics.desired_type``, ``topics.flow_type``,
excitation's ``topics.output_type``): ``std_msgs/msg/Float64`` (no header:
its time is when it was sent or received) or
``hyst_id_interfaces/msg/StampedValue`` (``header.stamp`` is the time the
value stands for, so replays, queues and clocks do not move it). A
:class:`ScalarStream` builds and reads either.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

from hyst_id.errors import ConfigError
from hyst_id.io.interface_types import FLOAT64_TYPE, SCALAR_TYPES, STAMPED_VALUE_TYPE
from hyst_id.nodes.support.ros import message_class, stamp_ns

__all__ = ['CommandClock', 'ScalarStream']


@dataclass(frozen=True)
class ScalarStream:
    """Build and read the messages of one scalar stream.

    Parameters
    ----------
    type_name : str
        One of :data:`~hyst_id.io.interface_types.SCALAR_TYPES`.
    """

    type_name: str
    cls: type = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.type_name not in SCALAR_TYPES:
            raise ConfigError(f'scalar stream type {self.type_name!r} is not one of '
                              + ', '.join(SCALAR_TYPES))
        try:
            cls = message_class(self.type_name)
        except ConfigError:
            raise ConfigError(
                f'{self.type_name} is not installed: build the interfaces package '
                '(colcon build --base-paths . interfaces; ./run does it) and source '
                f'install/local_setup.bash, or use {FLOAT64_TYPE}') from None
        object.__setattr__(self, 'cls', cls)

    @property
    def stamped(self) -> bool:
        """Whether the messages carry a header stamp."""
        return self.type_name == STAMPED_VALUE_TYPE

    def make(self, value: float, stamp: Any = None) -> Any:
        """A message holding ``value``; ``stamp`` (``builtin_interfaces/Time``) if stamped."""
        if not self.stamped:
            return self.cls(data=float(value))
        msg = self.cls(value=float(value))
        if stamp is not None:
            msg.header.stamp = stamp
        return msg

    @staticmethod
    def value(msg: Any) -> float:
        """The value of a message of either type."""
        return float(msg.value if hasattr(msg, 'header') else msg.data)

    @staticmethod
    def stamp(msg: Any) -> Any:
        """The header stamp of a stamped message with a non-zero stamp, else None."""
        header = getattr(msg, 'header', None)
        if header is None or not stamp_ns(header.stamp):
            return None
        return header.stamp

    def acts_at_ns(self, msg: Any, info: Mapping[str, Any], node: Any) -> int:
        """When a command takes effect (ns): its stamp, else when it arrived.

        The middleware's receive timestamp (free of executor delays), else now.
        """
        stamp = self.stamp(msg)
        if stamp is not None:
            return stamp_ns(stamp)
        return int(info.get('received_timestamp') or 0) or node.get_clock().now().nanoseconds


class CommandClock:
    """Time between successive commands of a simulated plant, never negative.

    A command stamped before the previous one (a bag replayed again, a stale
    message) applies with no time elapsed, with a warning, and the clock does
    not go back.
    """

    def __init__(self) -> None:
        self.last_ns: int | None = None

    def advance(self, ns: int, logger: Any) -> tuple[int, float]:
        """The sample's time (ns) and the seconds since the previous command."""
        dt_s = 0.0 if self.last_ns is None else (ns - self.last_ns) * 1e-9
        if dt_s < 0.0:
            logger.warning(f'command stamped {-dt_s:.3g} s before the previous one: applied '
                           'with no time elapsed', throttle_duration_sec=5.0)
            dt_s, ns = 0.0, self.last_ns
        self.last_ns = ns
        return ns, dt_s
