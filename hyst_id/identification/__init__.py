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

"""Identification: from a recording to the chain's parameters, their quality and a report.

The stage's modules, in pipeline order:

========================  =====================================================
:mod:`.chains`            chain spec per channel (parameter table, constraints,
                          the numba population kernel)
:mod:`.domains`           search domains from the data (any units) or presets
:mod:`.refine`            local least-squares polish after the global search
:mod:`.gauge`             the chain's gauge freedom and its canonical form
:mod:`.driver`            :func:`identify`: seeds, GAASS, refinement, restarts
:mod:`.incumbent`         the data-built incumbent, the initial state and sensor
                          hold conventions ranked, the search subset
:mod:`.global_phase`      differential evolution over the whole box after the
                          seeds: every convention, then longer runs
:mod:`.model_choice`      H's family chosen on held-out data (``--model auto``)
:mod:`.quality`           warnings on what the recording could not determine
:mod:`.result`            :class:`IdentifySettings`, :class:`SeedRun`,
                          :class:`Identification`
:mod:`.report`            Table 1 style text, JSON and figures
========================  =====================================================

May import: :mod:`hyst_id.signals`, :mod:`hyst_id.io`, :mod:`hyst_id.models`,
:mod:`hyst_id.solvers`, :mod:`hyst_id.errors`.
"""

from hyst_id.identification.driver import identify, run_seed
from hyst_id.identification.result import Identification, IdentifySettings, SeedRun

__all__ = ['identify', 'run_seed', 'Identification', 'IdentifySettings', 'SeedRun']
