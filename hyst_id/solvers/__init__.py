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

"""General minimisers shaped like :func:`scipy.optimize.differential_evolution`.

:mod:`~hyst_id.solvers.gaass` is the paper's GAASS (a steppable solver and
``minimize``), :mod:`~hyst_id.solvers.gaass_ops` its pure operators and
:mod:`~hyst_id.solvers.simple_ga` the simple GA it is compared with (Fig. 2).

May import: numpy, scipy, :mod:`hyst_id.errors`.
"""

__all__: list[str] = []
