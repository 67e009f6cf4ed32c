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

"""Recordings for the drift exchange (``hyst_id/diagnosis/exchange.py``), made apart from it.

:func:`forced_offset`: the reference chain (``reference_sim``) read through a
gain growing about a distant zero, or through a drifting zero, with
``offset_drift`` forced in as the final model's block. Used by
``test/diagnosis/test_drift_exchange.py`` and ``bench/drift_exchange_spread.py``.
"""

from __future__ import annotations

from lag_cases import at_truth, NAMES, TRUTH
import numpy as np
from reference_sim import simulate as reference_simulate

from hyst_id.diagnosis.mechanisms import get_mechanisms
from hyst_id.diagnosis.trial import try_all
from hyst_id.signals.excitation import multisine

__all__ = ['GROWTH', 'RAMP', 'ZERO_SPANS', 'forced_offset']

GROWTH = 0.04       # the gain's growth over the record
ZERO_SPANS = 5.0    # the sensor's zero, in spans below the travel
RAMP = 0.04         # the offset drift over the record, in spans


def forced_offset(drift: str, seed: int) -> dict:
    """The reference chain read through ``drift``; ``offset_drift`` forced in as the final."""
    t = np.arange(0.0, 120.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
    span = float(np.ptp(x))
    if drift == 'gain':
        pivot = float(np.min(x)) - ZERO_SPANS * span
        y = pivot + (x - pivot) * (1.0 + GROWTH * t / t[-1])
    else:
        y = x + RAMP * span * t / t[-1]
    data, ctx, settings, relocate, chain = at_truth(t, v, y, 0.004 * span, seed)
    offset = try_all(get_mechanisms(('offset_drift',), channel='position'), chain, data, ctx,
                     settings, relocate(chain), [])[0]
    mechs = get_mechanisms(('offset_drift', 'gain_drift', 'gain_loss'), channel='position')
    return {'current': offset.fit, 'found': ['offset_drift'], 'mechs': mechs, 'data': data,
            'ctx': ctx, 'settings': settings, 'chain_starts': [],
            'final_loc': relocate(offset.fit), 'relocate': relocate}
