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

"""What a bag records besides messages: the publishers' QoS and honest metadata.

:func:`rosbags_qos` turns a QoS profile given as rmw values into the
``offered_qos_profiles`` entry rosbags stores; :func:`fix_metadata` names
the ROS distribution in ``metadata.yaml`` and starts an empty bag at 0.
"""

from __future__ import annotations

from collections.abc import Mapping
import os
from pathlib import Path
from typing import Any

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

__all__ = ['fix_metadata', 'rosbags_qos']


def rosbags_qos(q: Mapping[str, Any]) -> Qos:
    """A rosbags ``Qos`` from rmw values (see :meth:`hyst_id.io.bag.BagWriter.add_topic`)."""
    def time(ns: Any) -> QosTime:
        ns = int(ns or 0)
        return QosTime(sec=ns // 10**9, nsec=ns % 10**9)

    return Qos(history=QosHistory(int(q.get('history', 0))), depth=int(q.get('depth', 0)),
               reliability=QosReliability(int(q.get('reliability', 0))),
               durability=QosDurability(int(q.get('durability', 0))),
               deadline=time(q.get('deadline_ns')), lifespan=time(q.get('lifespan_ns')),
               liveliness=QosLiveliness(int(q.get('liveliness', 0))),
               liveliness_lease_duration=time(q.get('liveliness_lease_duration_ns')),
               avoid_ros_namespace_conventions=bool(q.get('avoid_ros_namespace_conventions')))


def fix_metadata(path: Path) -> None:
    """Name the ROS distribution (rosbags writes ``rosbags``) and start an empty bag at 0.

    rosbags gives a bag without messages the starting time ``INT64_MAX``,
    which ``ros2 bag info`` prints as a date in 2262.
    """
    text = path.read_text()
    distro = os.environ.get('ROS_DISTRO') or 'kilted'
    text = text.replace('ros_distro: rosbags', f'ros_distro: {distro}')
    text = text.replace(f'nanoseconds_since_epoch: {2**63 - 1}', 'nanoseconds_since_epoch: 0')
    tmp = path.with_name(path.name + '.tmp')
    tmp.write_text(text)
    os.replace(tmp, path)
