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

"""The library of physical mechanisms the diagnosis can add to the paper's chain.

One module per mechanism; each exposes ``MECHANISM``, an instance of a
:class:`~hyst_id.diagnosis.mechanisms.base.Mechanism` subclass, and is listed
once in :mod:`.registry`. :data:`MECHANISMS` holds them by id.

==========================  ==========================================  ============
id                          placed                                      searched
==========================  ==========================================  ============
``dead_time``               on the command, before H                    delay_s
``sensor_lag``              after the modelled sensor dynamics          tau_lag_s
``supply_decay``            gain in time on the sensed quantity         decay rate
``offset_drift``            added to the measurement                    (linear)
``saturation``              clip of the actuator position               two stops
``stiction``                stick-slip on the actuator position         band, start
``static_nonlinearity``     position -> sensed quantity map             (linear)
``rate_dependence``         loop width inside H grows with rate         width, filter
==========================  ==========================================  ============
"""

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity
from hyst_id.diagnosis.mechanisms.registry import get_mechanisms, MECHANISM_IDS, MECHANISMS

__all__ = ['MECHANISMS', 'MECHANISM_IDS', 'Context', 'Mechanism', 'Quantity', 'get_mechanisms']
