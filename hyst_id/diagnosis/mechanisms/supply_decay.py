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

Direction: a supply running down lowers every pressure and flow above
ambient, so a direct-reading sensor's readings fall toward the reading of
zero (the level the gain leaves unchanged). A fit that puts that level above
most readings has them rise as the supply falls, which needs a sensor whose
reading falls as the quantity rises; in a tie such a fit steps back
(:meth:`SupplyDecay.doubt`). Blind #157 (a sensitivity growing 4.6 % about a
zero below the travel) had been named ``supply_decay`` about a zero 13 spans
above it, tied with ``gain_drift`` and ``offset_drift``.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain

__all__ = ['SupplyDecay', 'MECHANISM']


def _rising(zero: float, middle: float) -> str:
    """Words for an unchanged reading ``zero`` above the readings' ``middle`` ('' if not)."""
    if not zero > middle:
        return ''
    return (f'the reading it leaves unchanged ({zero:.4g}) lies above the middle of the '
            f'readings ({middle:.4g}), so most readings would rise as the supply runs down, '
            'which a sensor whose reading rises with the pressure or flow does not do')


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

    def doubt(self, theta, coef, labels, readings) -> str:
        """Readings that rise as the supply falls: the unchanged reading above their median."""
        return _rising(self.unchanged_reading({'coef': coef, 'labels': list(labels)}),
                       float(np.median(readings)))

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Time constant and the gain lost over the record."""
        lam = float(theta[0])
        loss = 1.0 - np.exp(-lam * ctx.duration_s)
        per_min = 100.0 * (1.0 - np.exp(-60.0 * lam))
        values = self.with_pivot({
            'time_constant_s': Quantity(1.0 / lam, 's', 'e-folding time of the gain'),
            'gain_loss_percent': Quantity(100.0 * loss, '%',
                                          'gain lost from the start to the end of the record'),
            'gain_loss_percent_per_min': Quantity(per_min, '%/min', 'gain lost per minute')},
            info, ctx)
        middle = info.get('readings_median')
        if middle is not None and _rising(values['unchanged_reading'].value, middle):
            values['middle_reading'] = Quantity(
                middle, ctx.meas_unit, "the middle of the training part's readings, below the "
                'unchanged one: most readings rise as the gain falls')
        return values

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        return (f'The plant gain falls with time: {values["gain_loss_percent"].value:.1f} % '
                f'over the {ctx.duration_s:.0f} s record (time constant '
                f'{values["time_constant_s"].value:.0f} s), as when the supply vessels empty '
                f'without pressure regulation: the same valve opening gives less {ctx.channel} '
                'later in the run.' + self.pivot_words(values, grows=False)
                + ' Regulate the supply pressure, or schedule the gain on the '
                'measured supply pressure; an identification from an early run will '
                'over-predict later ones.' + (
                    ' But ' + _rising(values['unchanged_reading'].value,
                                      values['middle_reading'].value)
                    + ': a judgement call against a gain growing or an offset drifting.'
                    if 'middle_reading' in values else ''))


MECHANISM = SupplyDecay()
