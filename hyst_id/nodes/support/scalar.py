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
from typing import Any

from hyst_id.errors import ConfigError
from hyst_id.io.interface_types import FLOAT64_TYPE, SCALAR_TYPES, STAMPED_VALUE_TYPE
from hyst_id.nodes.support.ros import message_class, stamp_ns

__all__ = ['ScalarStream']


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

    @property
    def value_field(self) -> str:
        """The field path of the value (``data`` or ``value``)."""
        return 'value' if self.stamped else 'data'

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
