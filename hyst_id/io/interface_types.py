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

"""The typed messages of ``interfaces/hyst_id_interfaces``, for bags and readers.

The ROS-free core writes and reads bags with rosbags, which needs each
message's definition; this module holds them (the ``.msg`` files of the
interfaces package, which a test keeps equal) and registers them in a
rosbags typestore. The nodes use the generated Python classes instead
(built by colcon: ``./run`` does it).
"""

from __future__ import annotations

from rosbags.typesys import get_types_from_msg
from rosbags.typesys.store import Typestore

__all__ = ['IDENTIFIED_PARAMS_TYPE', 'INTERFACE_MSGS', 'SCALAR_TYPES', 'STAMPED_VALUE_TYPE',
           'FLOAT64_TYPE', 'register_interface_types']

#: A stamped scalar sample (command, desired output, flow): header + value.
STAMPED_VALUE_TYPE = 'hyst_id_interfaces/msg/StampedValue'
#: An identified parameter set (names, values, %e_r, noise floor, warnings, gate).
IDENTIFIED_PARAMS_TYPE = 'hyst_id_interfaces/msg/IdentifiedParams'
#: The standard, unstamped scalar: its time is when it was received or logged.
FLOAT64_TYPE = 'std_msgs/msg/Float64'
#: Message types a scalar stream (command, desired output, flow) may use.
SCALAR_TYPES = (FLOAT64_TYPE, STAMPED_VALUE_TYPE)

#: Definitions of the interfaces package (comments dropped), by full type name.
INTERFACE_MSGS = {
    STAMPED_VALUE_TYPE: (
        'std_msgs/Header header\n'
        'float64 value\n'),
    IDENTIFIED_PARAMS_TYPE: (
        'std_msgs/Header header\n'
        'string channel\n'
        'string family\n'
        'string[] names\n'
        'float64[] values\n'
        'float64 er_percent\n'
        'float64 noise_floor_percent\n'
        'string[] warnings\n'
        'bool handed_over\n'
        'string[] gate_reasons\n'
        'string detail_json\n'),
}


def register_interface_types(typestore: Typestore) -> Typestore:
    """Add the interfaces package's message types to ``typestore`` (in place; returned)."""
    missing = {name: text for name, text in INTERFACE_MSGS.items()
               if name not in typestore.types}
    for name, text in missing.items():
        typestore.register(get_types_from_msg(text, name))
    return typestore
