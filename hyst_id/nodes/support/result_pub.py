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

"""The identifier's result publisher: the JSON document and the typed message.

The JSON document (``std_msgs/String``) on ``topics.identified_params_topic``
is what compensators follow; the same result goes out typed
(``hyst_id_interfaces/msg/IdentifiedParams``: header, channel, family,
names, values, %e_r, noise floor, warnings, gate) on
``topics.identified_typed_topic`` for stacks that read fields instead of
parsing JSON. Both latched.
"""

from __future__ import annotations

import datetime
import json
import math
from typing import Any

from builtin_interfaces.msg import Time
from rclpy.node import Node
from rclpy.qos import QoSProfile
from std_msgs.msg import String

from hyst_id.errors import ConfigError
from hyst_id.io.interface_types import IDENTIFIED_PARAMS_TYPE
from hyst_id.nodes.support.ros import message_class

__all__ = ['ResultPublisher', 'finished_ns', 'identified_params_message']


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


def _or_nan(value: Any) -> float:
    number = _number(value)
    return math.nan if number is None else number


def finished_ns(doc: dict) -> int:
    """When the document's identification finished (``identified_at``), ns; 0 if unknown."""
    try:
        when = datetime.datetime.fromisoformat(str(doc['identified_at']))
    except (KeyError, ValueError):
        return 0        # e.g. a set recovered from a params file
    return int(round(when.timestamp() * 1e9))


def identified_params_message(cls: type, doc: dict, stamp: Any) -> Any:
    """An ``IdentifiedParams`` of class ``cls`` holding the result document ``doc``.

    ``stamp`` (``builtin_interfaces/Time``) is when the identification finished;
    zero when that is not known (a set recovered from a params file).
    """
    params = {k: _number(v) for k, v in (doc.get('params') or {}).items()}
    params = {k: v for k, v in params.items() if v is not None}
    gate = doc.get('gate') or {}
    msg = cls(channel=str(doc.get('channel', '')), family=str(doc.get('family', '')),
              names=list(params), values=list(params.values()),
              er_percent=_or_nan(doc.get('er_percent')),
              noise_floor_percent=_or_nan(doc.get('noise_floor_percent')),
              warnings=[str(w) for w in doc.get('warnings') or ()],
              handed_over=doc.get('compensator_params') is not None,
              gate_reasons=[str(r) for r in gate.get('reasons') or ()],
              detail_json=json.dumps(doc))
    msg.header.stamp = stamp
    return msg


class ResultPublisher:
    """Publish a result document as JSON and, when the interfaces are built, typed.

    Parameters
    ----------
    node : rclpy Node
        The publishing node.
    json_topic, typed_topic : str
        Topics of the JSON document and of the typed message ('' = no typed message).
    qos : QoSProfile
        QoS of both (latched).
    """

    def __init__(self, node: Node, json_topic: str, typed_topic: str, qos: QoSProfile) -> None:
        self._node = node
        self._json = node.create_publisher(String, json_topic, qos)
        self._cls: type | None = None
        self._typed = None
        if typed_topic:
            try:
                self._cls = message_class(IDENTIFIED_PARAMS_TYPE)
            except ConfigError:
                node.get_logger().warning(
                    f'{IDENTIFIED_PARAMS_TYPE} is not installed: results go out as JSON only '
                    '(build interfaces/hyst_id_interfaces with colcon; ./run does it)')
            else:
                self._typed = node.create_publisher(self._cls, typed_topic, qos)

    @property
    def topic_name(self) -> str:
        """The resolved topic of the JSON document."""
        return self._json.topic_name

    @property
    def typed_topic_name(self) -> str:
        """The resolved topic of the typed message ('' when not published)."""
        return self._typed.topic_name if self._typed is not None else ''

    def publish(self, doc: dict) -> None:
        """Publish ``doc`` on both topics."""
        self._json.publish(String(data=json.dumps(doc)))
        if self._typed is not None:
            sec, nanosec = divmod(finished_ns(doc), 1_000_000_000)
            stamp = Time(sec=sec, nanosec=nanosec)
            self._typed.publish(identified_params_message(self._cls, doc, stamp))
