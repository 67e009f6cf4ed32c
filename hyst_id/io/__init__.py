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

"""Recordings in and out: the Recording value object, readers, bags, params files.

========================  ===================================================
:mod:`.recording`         :class:`Recording`, its validation, the round-off probe
:mod:`.readers`           :func:`read_recording` (CSV or MCAP by path)
:mod:`.csv_reader`,       the two readers; :mod:`.topics` says which topics,
:mod:`.mcap_reader`       types and fields hold a channel
:mod:`.streams`           two stamped streams into one recording (pairing)
:mod:`.bag`,              rosbag2 MCAP writing (chunked, crash safe) and
:mod:`.mcap_recover`      reading, recovery of a killed recorder's file
:mod:`.messages`          building ROS messages for bags without rclpy
:mod:`.params_file`       reading YAML with one-line errors
:mod:`.jsonable`          result objects to JSON
:mod:`.outputs`           where outputs go (figure file or folder), folders made
========================  ===================================================

May import: :mod:`hyst_id.signals`, rosbags, mcap; never rclpy.
"""

__all__: list[str] = []
