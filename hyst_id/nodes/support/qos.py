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

"""QoS of each kind of stream and the default topic names the nodes share.

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

The data streams (command, desired, position, pressure, flow) are created with
:data:`OVERRIDABLE`: history, depth, reliability and durability of each can be
changed at start from a params file, as rclpy's QoS overriding options read them
(``qos_overrides./hyst_id/command.publisher.depth: 50``, fully qualified name).
"""

from __future__ import annotations

from rclpy.qos import (
                       DurabilityPolicy,
                       HistoryPolicy,
                       qos_profile_sensor_data,
                       QoSProfile,
                       ReliabilityPolicy,
)
from rclpy.qos_overriding_options import QoSOverridingOptions

__all__ = ['COMMAND_QOS', 'DESIRED_TOPIC', 'DIAGNOSTICS_QOS', 'DIAGNOSTICS_TOPIC',
           'IDENTIFIED_PARAMS_TOPIC', 'LATCHED_QOS', 'OVERRIDABLE', 'SENSOR_QOS']

#: Desired output fed to the compensator (std_msgs/Float64); relative, so a
#: node started in a namespace (``-r __ns:=/valve1``) uses ``/valve1/hyst_id/desired``.
DESIRED_TOPIC = 'hyst_id/desired'
#: Latched JSON of the last identification (std_msgs/String); relative, as above.
IDENTIFIED_PARAMS_TOPIC = 'hyst_id/identified_params'
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
#: QoS overriding options of the data streams: read-only ``qos_overrides.<topic>.<entity>.*``
#: parameters for history, depth, reliability and durability.
OVERRIDABLE = QoSOverridingOptions.with_default_policies()
