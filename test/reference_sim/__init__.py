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

"""Reference simulator written apart from hyst_id; imports nothing from hyst_id.

Plain numpy and Python loops straight from the seed paper (Eq. 1-3, 8-10) as
corrected by ``shared/docs/model-notes.md``. Its modelling choices (initial
state, zero-order hold, calibration) are listed in :mod:`reference_sim.sim`.
"""

from __future__ import annotations

from .sim import (
    backlash,
    first_order_sensor,
    hysteresis,
    loop_corners,
    paper_constraints_ok,
    second_order_sensor,
    simulate,
)

__all__ = ['backlash', 'first_order_sensor', 'hysteresis', 'loop_corners',
           'paper_constraints_ok', 'second_order_sensor', 'simulate']
