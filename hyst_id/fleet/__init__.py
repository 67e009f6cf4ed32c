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

"""Many recordings at once: identify (and diagnose) a fleet of valves, one row each.

:func:`find_recordings` turns directories and globs into recordings (bag
directories, ``.mcap`` and CSV files); :func:`run_fleet` identifies each in
a process pool or on a Dask cluster, writes one JSON per recording, skips
recordings already done, and reports a bad recording in its row without
stopping; :func:`write_table` writes the table (CSV, and Parquet when
``pyarrow`` is installed); :func:`loop_trends` flags valves whose loop width
drifts over their recordings (the maintenance signal).

Modules: :mod:`.run` (finding, the task, the engines), :mod:`.table`
(rows, files, trends), :mod:`.width` (the identified loop's width in command
units). May import :mod:`hyst_id.io`,
:mod:`hyst_id.identification`, :mod:`hyst_id.diagnosis`; never rclpy.
"""

from hyst_id.fleet.run import find_recordings, FleetOptions, run_fleet
from hyst_id.fleet.table import loop_trends, write_table

__all__ = ['FleetOptions', 'find_recordings', 'loop_trends', 'run_fleet', 'write_table']
