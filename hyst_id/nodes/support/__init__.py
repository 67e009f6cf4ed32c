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

"""What the nodes share: QoS and topic names, the parameter table, HystNode, helpers.

Nodes import from here; the core never does (it does not import rclpy).
"""

from hyst_id.nodes.support.hyst_node import HystNode
from hyst_id.nodes.support.params import (
                                          field_params,
                                          Param,
                                          scalar_type_param,
                                          TOPIC_KEYS,
                                          topic_params,
)
from hyst_id.nodes.support.pusher import ParameterPusher
from hyst_id.nodes.support.qos import (
                                       COMMAND_QOS,
                                       DESIRED_TOPIC,
                                       DIAGNOSTICS_QOS,
                                       DIAGNOSTICS_TOPIC,
                                       IDENTIFIED_PARAMS_TOPIC,
                                       LATCHED_QOS,
                                       OVERRIDABLE,
                                       SENSOR_QOS,
)
from hyst_id.nodes.support.ros import (
                                       check_field,
                                       diagnostic_array,
                                       exit_code_after,
                                       EXIT_SIGINT,
                                       init_ros,
                                       input_problems,
                                       message_class,
                                       publisher_mismatches,
                                       resolved,
                                       source_time_ns,
                                       spin_in_background,
                                       spin_node,
                                       spin_until_stopped,
                                       stamp_ns,
                                       stop_signals,
                                       try_publish,
)
from hyst_id.nodes.support.scalar import CommandClock, ScalarStream

__all__ = [
    'COMMAND_QOS', 'CommandClock', 'DESIRED_TOPIC', 'check_field', 'DIAGNOSTICS_QOS',
    'DIAGNOSTICS_TOPIC', 'EXIT_SIGINT',
    'IDENTIFIED_PARAMS_TOPIC', 'LATCHED_QOS', 'OVERRIDABLE', 'SENSOR_QOS', 'TOPIC_KEYS',
    'diagnostic_array', 'exit_code_after', 'field_params', 'HystNode', 'init_ros',
    'input_problems',
    'message_class', 'Param', 'ParameterPusher', 'resolved', 'ScalarStream',
    'scalar_type_param', 'source_time_ns',
    'spin_in_background', 'spin_node', 'spin_until_stopped', 'stamp_ns', 'stop_signals',
    'topic_params', 'try_publish', 'publisher_mismatches',
]
