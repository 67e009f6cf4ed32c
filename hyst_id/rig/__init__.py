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

"""Physics simulator of the paper's pneumatic rig (issue 4); see ``docs/rig.md``.

``simulate_rig(params, t_s, command_ma, seed)`` runs a whole command profile
and returns a :class:`RigRun`; :class:`RigSimulator` runs the same physics
one sample at a time for a real-time node. Parameters live in
:class:`RigParams` and in ``params/pipeline.yaml`` / ``params/paper_rig.yaml``.

May import: :mod:`hyst_id.models`, :mod:`hyst_id.io`, :mod:`hyst_id.signals`.
"""

from __future__ import annotations

from hyst_id.rig.effects import Effects
from hyst_id.rig.params import rig_params_from_dict, rig_params_to_dict, RigParams
from hyst_id.rig.params_file import as_rig_params, load_rig_params, save_rig_params
from hyst_id.rig.simulator import RigRun, RigSample, RigSimulator, simulate_rig, TRUTH_FIELDS

__all__ = [
    'Effects',
    'as_rig_params',
    'RigParams',
    'RigRun',
    'RigSample',
    'RigSimulator',
    'TRUTH_FIELDS',
    'load_rig_params',
    'rig_params_from_dict',
    'rig_params_to_dict',
    'save_rig_params',
    'simulate_rig',
]
