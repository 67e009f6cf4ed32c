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

"""``gain_loss``: the position reading's sensitivity falls slowly over the run.

Placement: on the sensed quantity, before the sensor's additive offset:
``y = g(t) (k s + b0) + b1``, ``g(t) = 1 - r (t - t0)`` with ``r > 0``, on the
position channel only. A voltage-driven solenoid or voice coil warming up
(its resistance rises, the current and the stroke per volt fall), a
Hall or LVDT sensor's magnet or coil warming, a strain gauge's bond
creeping: the same command reads a little less travel later in the run. On
pressure and flow a falling gain is :mod:`.supply_decay`'s (the supply
running down), so this block is not offered there; a growing gain is
:mod:`.gain_drift`'s. As there, a fall ``r`` near zero about a distant zero
``b0`` would be an offset drift, so ``r`` keeps a lower bound and a fit at it
is refused (:meth:`TimeGain.implausible`). ``b0`` is a linear parameter,
the block adds one searched parameter ``r``.

Signature: a residual trend over time whose size scales with the output
level (the loop shrinks), unlike an offset drift, which shifts every level
alike.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain

__all__ = ['GainLoss', 'MECHANISM']


class GainLoss(TimeGain):
    """Linearly falling gain on the position reading."""

    id = 'gain_loss'  # noqa: A003
    title = 'actuator or sensor gain falling over time'
    physics = ('the stroke per command or the sensitivity falls during the run (a coil or '
               'magnet warming, a gauge bond creeping), so the same command reads less '
               'travel later in the run')
    gain_law = 'linear'
    channels = ('position',)          # on pressure and flow a falling gain is supply_decay's
    names = ('loss_per_s',)
    units = ('1/s',)
    #: 0.1 % to 60 % over the training part: the gain stays positive over a record
    #: whose held-out part is shorter than two thirds of its training part (at the
    #: default 70/30 split it ends at 14 % or more).
    rate_range = (0.001, 0.6)
    start_changes = (0.01, 0.05, 0.2)

    def gain(self, rate: float, elapsed_s: np.ndarray) -> np.ndarray:
        """Linear fall ``1 - rate t``."""
        return 1.0 - rate * elapsed_s

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Loss rate and the gain lost over the record."""
        r = float(theta[0])
        return self.with_pivot({
            'loss_percent_per_s': Quantity(100.0 * r, '%/s', 'gain loss rate'),
            'gain_loss_percent': Quantity(100.0 * r * ctx.duration_s, '%',
                                          'gain lost from the start to the end of the '
                                          'record')}, info, ctx)

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        return (f'The gain falls with time: {values["gain_loss_percent"].value:.1f} % over '
                f'the {ctx.duration_s:.0f} s record '
                f'({values["loss_percent_per_s"].value:.3g} %/s): the same command moves the '
                f'{ctx.quantity} reading less later in the run, as when a voltage-driven '
                "coil warms up (its current falls) or a sensor's magnet or gauge drifts."
                + self.pivot_words(values, grows=False)
                + ' Let the actuator and sensor warm up before identifying, drive the coil by '
                'current, or track the gain online (tracking in the compensator).')

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """The linear schedule ``1 + rate t`` with the rate negative."""
        out = super().correction(theta, coef, info, ctx)
        out['augment.gain_rate_per_s'] = -float(theta[0])
        return out


MECHANISM = GainLoss()
