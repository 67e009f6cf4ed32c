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

"""The paper's section 4 experiment on the simulated rig, end to end.

:mod:`.result` (settings and result objects, JSON form), :mod:`.run`
(identify from each sensor, compensate, score %ε_c), :mod:`.report`
(tables and figures of ``docs/RESULTS.md``).

May import: everything below it (:mod:`hyst_id.rig`, :mod:`hyst_id.identification`,
:mod:`hyst_id.compensation`, ...); nothing imports it but the CLI.
"""

from hyst_id.experiment.result import CHANNELS, ExperimentConfig, ExperimentResult, MODES
from hyst_id.experiment.run import run_experiment

__all__ = ['CHANNELS', 'MODES', 'ExperimentConfig', 'ExperimentResult', 'run_experiment']
