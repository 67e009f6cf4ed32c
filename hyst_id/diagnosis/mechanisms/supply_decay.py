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

"""``supply_decay``: the plant's gain decays over the run (supply running down).

Placement: on the sensed quantity, before the sensor's additive offset:
``y = g(t) (k s + b0) + b1``, ``g(t) = exp(-(t - t0)/T)``. With the supply
vessels emptying through the valve without pressure regulation, the
upstream pressure and the mass flow both scale with the supply pressure,
which blows down roughly exponentially; the same valve opening then gives
less pressure and flow later in the run. ``b0`` (where the decaying
quantity is zero, unknown for a gauge or absolute sensor) is a linear
parameter, so the block adds one searched parameter ``T`` and one linear.

Signature: a residual trend over time whose size scales with the output
level (the loop shrinks), unlike an offset drift, which shifts every level
alike.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain

__all__ = ['SupplyDecay', 'MECHANISM']


class SupplyDecay(TimeGain):
    """Exponentially decaying gain on the sensed quantity."""

    id = 'supply_decay'  # noqa: A003
    title = 'plant gain decaying over time (supply running down)'
    physics = ('the supply pressure falls during the run (vessels emptying without '
               'regulation), so pressure and flow for a given opening fall with it')
    gain_law = 'exponential'
    channels = ('pressure', 'flow')   # the position sensor does not see the supply
    names = ('decay_rate_per_s',)
    units = ('1/s',)
    rate_range = (0.01, 5.0)          # a hundredth to five e-foldings
    start_changes = (0.1, 0.3, 1.0)   # a tenth, a third and one e-folding

    def gain(self, rate: float, elapsed_s: np.ndarray) -> np.ndarray:
        """Exponential decay ``exp(-rate t)``."""
        return np.exp(-rate * elapsed_s)

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Time constant and the gain lost over the record."""
        lam = float(theta[0])
        loss = 1.0 - np.exp(-lam * ctx.duration_s)
        per_min = 100.0 * (1.0 - np.exp(-60.0 * lam))
        return self.with_pivot({
            'time_constant_s': Quantity(1.0 / lam, 's', 'e-folding time of the gain'),
            'gain_loss_percent': Quantity(100.0 * loss, '%',
                                          'gain lost from the start to the end of the record'),
            'gain_loss_percent_per_min': Quantity(per_min, '%/min', 'gain lost per minute')},
            info, ctx)

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        return (f'The plant gain falls with time: {values["gain_loss_percent"].value:.1f} % '
                f'over the {ctx.duration_s:.0f} s record (time constant '
                f'{values["time_constant_s"].value:.0f} s), as when the supply vessels empty '
                f'without pressure regulation: the same valve opening gives less {ctx.channel} '
                'later in the run.' + self.pivot_words(values, grows=False)
                + ' Regulate the supply pressure, or schedule the gain on the '
                'measured supply pressure; an identification from an early run will '
                'over-predict later ones.')


MECHANISM = SupplyDecay()
