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

"""Diagnosis: where a recording departs from the chain, and which physics is missing.

The stage's modules, in pipeline order:

=========================  ====================================================
:mod:`.driver`             :func:`diagnose`: split, baseline, locate, test the
                           mechanism library, accept on held-out evidence
:mod:`.baseline`           the baseline fit and data-built chain starts
:mod:`.locate`             where, when and under which input the residual is
:mod:`.model`              the chain with mechanism blocks inserted
:mod:`.select`             fitting blocks and deciding which the data support
:mod:`.mechanisms`         the library: one module per mechanism, a registry
:mod:`.plateaus`,          stick-slip's own fit from measured plateaus
:mod:`.stick_events`
:mod:`.sim_compare`        ``--sim``: the rig simulator against a recording
:mod:`.result`             :class:`DiagnoseSettings`, :class:`Finding`,
                           :class:`Diagnosis`
:mod:`.report`             text report and figure
:mod:`.export`             the final model and its in-line corrections as
                           the compensator's set (``--params-out``)
=========================  ====================================================

May import: :mod:`hyst_id.signals`, :mod:`hyst_id.io`, :mod:`hyst_id.models`,
:mod:`hyst_id.solvers`, :mod:`hyst_id.identification`, :mod:`hyst_id.rig` (``--sim``),
:mod:`hyst_id.compensation` (``--params-out``).
"""

from hyst_id.diagnosis.driver import diagnose
from hyst_id.diagnosis.result import DiagnoseSettings, Diagnosis, Finding

__all__ = ['diagnose', 'DiagnoseSettings', 'Diagnosis', 'Finding']
