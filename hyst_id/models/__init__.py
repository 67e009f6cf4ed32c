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

"""Models of the actuator chain: hysteresis families, backlash B, sensor dynamics.

========================  ===================================================
:mod:`.family`            the interface every hysteresis family implements
:mod:`.registry`          the families by id (one line per family module)
:mod:`.tk`, :mod:`.tk_lines`  the paper's loop (family ``tk``) and its line
                          analysis
:mod:`.backlash`          B and its inverse
:mod:`.sensors`           first- and second-order sensors, exact on any sampling
========================  ===================================================

May import: :mod:`hyst_id.signals`, :mod:`hyst_id.io`, numpy, numba.
"""

__all__: list[str] = []
