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

"""``gain_drift``: the sensitivity grows slowly over the run (temperature, warm-up).

Placement: on the sensed quantity, before the sensor's additive offset:
``y = g(t) (k s + b0) + b1``, ``g(t) = 1 + r (t - t0)`` with ``r > 0``. A
strain-gauge or piezo-resistive sensor warming up, a magnet cooling, an
amplifier's gain settling: the same travel reads a little more later in
the run. On pressure and flow a *falling* gain is :mod:`.supply_decay`'s
(exponential, the supply running down), so the two do not compete for one
record; on the position reading no block takes a falling gain (a growth
``r`` near zero with a distant zero ``b0`` would be an offset drift, so ``r``
keeps a lower bound). ``b0`` is a linear parameter, the block adds one
searched parameter ``r``.

Signature: a residual trend over time whose size scales with the output
level (the loop grows), unlike an offset drift, which shifts every level
alike.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain

__all__ = ['GainDrift', 'MECHANISM']


class GainDrift(TimeGain):
    """Linearly growing gain on the sensed quantity."""

    id = 'gain_drift'  # noqa: A003
    title = 'plant or sensor gain growing over time'
    physics = ('the sensitivity rises during the run (a sensor or amplifier warming up, '
               'temperature), so the same travel gives a larger reading later in the run')
    gain_law = 'linear'
    names = ('growth_per_s',)
    units = ('1/s',)
    rate_range = (0.001, 2.0)         # 0.1 % to 200 % over the training part
    start_changes = (0.01, 0.05, 0.2)

    def gain(self, rate: float, elapsed_s: np.ndarray) -> np.ndarray:
        """Linear growth ``1 + rate t``."""
        return 1.0 + rate * elapsed_s

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Growth rate and the gain gained over the record."""
        r = float(theta[0])
        return self.with_pivot({
            'growth_percent_per_s': Quantity(100.0 * r, '%/s', 'gain growth rate'),
            'gain_growth_percent': Quantity(100.0 * r * ctx.duration_s, '%',
                                            'gain gained from the start to the end of the '
                                            'record')}, info, ctx)

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        return (f'The gain grows with time: {values["gain_growth_percent"].value:.1f} % over '
                f'the {ctx.duration_s:.0f} s record '
                f'({values["growth_percent_per_s"].value:.3g} %/s): the same travel gives a '
                'larger change of reading later in the run, as when a sensor or its amplifier '
                'warms up.' + self.pivot_words(values, grows=True)
                + ' Let the sensor warm up before identifying, calibrate at operating '
                'temperature, or track the gain online (tracking in the compensator).')


MECHANISM = GainDrift()
