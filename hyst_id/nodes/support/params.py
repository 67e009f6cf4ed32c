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

"""The declarative parameter table every node declares: :class:`Param` and topic parameters."""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, Iterable

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidTopicNameException
from rclpy.validate_topic_name import validate_topic_name

from hyst_id.io.interface_types import FLOAT64_TYPE, SCALAR_TYPES, STAMPED_VALUE_TYPE
from hyst_id.io.recording import CHANNELS
from hyst_id.io.topics import TopicConfig

__all__ = ['Param', 'TOPIC_KEYS', 'field_params', 'scalar_type_param', 'topic_params']


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
        bad_topic = self._bad_topic(value)
        if bad_topic:
            return bad_topic
        if self.low is not None and isinstance(value, (int, float)) \
                and not isinstance(value, bool):
            high = math.inf if self.high is None else self.high
            if not (math.isfinite(value) and self.low <= value <= high):
                return (f'{self.name} must be in [{self.low:g}, {high:g}]'
                        f'{" " + self.unit if self.unit else ""}; got {value!r}')
        return None

    def _bad_topic(self, value: Any) -> str | None:
        """Why a topic name (``*_topic``) or a ``topics`` list entry is no ROS topic name."""
        if self.name.endswith('_topic') and isinstance(value, str):
            names = [value]
        elif self.name == 'topics' and isinstance(value, (list, tuple)):
            names = [t for t in value if isinstance(t, str) and t and t != '*']
        else:
            return None
        for name in names:
            try:
                validate_topic_name(name)
            except InvalidTopicNameException as exc:
                why = str(exc).splitlines()[0].rstrip(':').replace('Invalid topic name: ', '')
                return f'{self.name}: {name!r} is not a ROS topic name ({why})'
        return None


#: Topic-name keys of ``params/topics.yaml`` declared as ``topics.<key>``.
TOPIC_KEYS = ('command_topic',) + tuple(f'{ch}_topic' for ch in CHANNELS)


def topic_params(keys: Iterable[str] = TOPIC_KEYS) -> list[Param]:
    """Read-only ``topics.<key>`` parameters: ``params/topics.yaml``'s names, relative."""
    out = []
    for key in keys:
        if key == 'command_topic':
            default = TopicConfig().command_topic
        else:
            default = TopicConfig.for_channel(key[:-len('_topic')]).measurement_topic
        # relative, so that the node's namespace applies (a bag's names are absolute)
        out.append(Param(f'topics.{key}', default.lstrip('/'),
                         f'topic name ({key.replace("_", " ")}); relative names take the '
                         "node's namespace", read_only=True))
    return out


def scalar_type_param(name: str, what: str, default: str = FLOAT64_TYPE) -> Param:
    """The read-only ``topics.<stream>_type`` parameter of the scalar stream ``what``."""
    return Param(name, default, f'message type of the {what}: {FLOAT64_TYPE} (unstamped) or '
                 f'{STAMPED_VALUE_TYPE} (header stamp = the time the value stands for; '
                 'needs the hyst_id_interfaces package)', read_only=True, choices=SCALAR_TYPES)


def field_params() -> list[Param]:
    """Read-only ``topics.command_type`` / ``_field`` and ``topics.<channel>_type`` / ``_field``.

    ``topics.command_type`` is a scalar stream type (``std_msgs/msg/Float64``
    or ``hyst_id_interfaces/msg/StampedValue``); a channel's type may be any
    message type that holds its field.
    """
    out = [scalar_type_param('topics.command_type', 'command stream',
                             TopicConfig().command_type),
           Param('topics.command_field', TopicConfig().command_field,
                 'field of the command message (data for Float64, value for StampedValue)',
                 read_only=True)]
    for ch in CHANNELS:
        cfg = TopicConfig.for_channel(ch)
        out += [Param(f'topics.{ch}_type', cfg.measurement_type, f'message type of {ch}',
                      read_only=True),
                Param(f'topics.{ch}_field', cfg.measurement_field, f'field of the {ch} message',
                      read_only=True)]
    return out
