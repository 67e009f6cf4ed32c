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

"""``gain_drift``: the sensitivity changes slowly over the run (temperature, warm-up).

Placement: on the sensed quantity, before the sensor's additive offset:
``y = g(t) (k s + b0) + b1``, ``g(t) = 1 + r (t - t0)``. A strain-gauge or
piezo-resistive sensor warming up, a magnet cooling, an amplifier's gain
settling: the same travel reads a little more (or less) later in the run.
On pressure and flow a *falling* gain is :mod:`.supply_decay`'s
(exponential, the supply running down), so there ``r > 0`` and the two do
not compete for one record; on a channel no supply reaches (the valve's
position) the gain may fall as well (``r`` down to half the gain lost over
the training part). ``b0`` is a linear parameter, the block adds one
searched parameter ``r``.

Signature: a residual trend over time whose size scales with the output
level (the loop grows or shrinks), unlike an offset drift, which shifts
every level alike.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Quantity
from hyst_id.diagnosis.mechanisms.supply_decay import SupplyDecay
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain

__all__ = ['GainDrift', 'MECHANISM']


class GainDrift(TimeGain):
    """Linearly changing gain on the sensed quantity (growing where a supply could fall)."""

    id = 'gain_drift'  # noqa: A003
    title = 'plant or sensor gain changing over time'
    physics = ('the sensitivity changes during the run (a sensor or amplifier warming up, '
               'temperature), so the same travel reads more, or less, later in the run')
    gain_law = 'linear'
    names = ('growth_per_s',)
    units = ('1/s',)
    rate_range = (0.001, 2.0)         # 0.1 % to 200 % over the training part
    start_changes = (0.01, 0.05, 0.2)
    #: Where no supply reaches: the most the gain may fall over the training part.
    fall_limit = 0.5

    @staticmethod
    def _signed(ctx: Context) -> bool:
        return ctx.channel not in SupplyDecay.channels

    def bounds(self, ctx: Context) -> np.ndarray:
        """Growth only where a supply could fall; both ways elsewhere."""
        b = super().bounds(ctx)
        if self._signed(ctx):
            b[0, 0] = -self.fall_limit / max(ctx.train_duration_s, 1e-9)
        return b

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """The growing starts, and the falling ones where the gain may fall."""
        up = super().starts(ctx)
        return up + [-x for x in up] if self._signed(ctx) else up

    def null(self, ctx: Context) -> np.ndarray:
        """No change where it may fall (inside the bounds), else the slowest growth."""
        return np.zeros(1) if self._signed(ctx) else super().null(ctx)

    def gain(self, rate: float, elapsed_s: np.ndarray) -> np.ndarray:
        """Linear change ``1 + rate t``."""
        return 1.0 + rate * elapsed_s

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Growth rate and the gain gained over the record (negative: lost)."""
        r = float(theta[0])
        return {'growth_percent_per_s': Quantity(100.0 * r, '%/s', 'gain growth rate'),
                'gain_growth_percent': Quantity(100.0 * r * ctx.duration_s, '%',
                                                'gain gained from the start to the end of '
                                                'the record')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        growth = values['gain_growth_percent'].value
        way, more = ('grows', 'more') if growth >= 0 else ('falls', 'less')
        return (f'The gain {way} with time: {abs(growth):.1f} % over '
                f'the {ctx.duration_s:.0f} s record '
                f'({values["growth_percent_per_s"].value:+.3g} %/s): the same travel reads '
                f'{more} {ctx.channel} later in the run, as when a sensor or its amplifier '
                'warms up. Let the sensor warm up before identifying, calibrate at operating '
                'temperature, or track the gain online (tracking in the compensator).')


MECHANISM = GainDrift()
