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

"""``sensor_lag``: an unmodelled first-order lag in the measurement path.

Placement: after the channel's modelled sensor dynamics (none for position,
the paper's first-order ``tau_s`` for pressure, second order for flow),
before the calibration: ``1/(tau_lag s + 1)``. Physically a transmitter's
filter, tubing between the pipe and the transducer, the thermal mass of a
sensor, or a slow position transducer.

Signature: residual correlated with the command rate; after a reversal it
decays exponentially with ``tau_lag`` rather than ending abruptly as a dead
time's does; the loop's corners are rounded.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity, rate_correlation
from hyst_id.models.sensors import simulate_first_order

__all__ = ['SensorLag', 'MECHANISM']


class SensorLag(Mechanism):
    """Extra first-order lag after the modelled sensor."""

    id = 'sensor_lag'  # noqa: A003
    title = 'unmodelled first-order lag in the measurement'
    stage = 'sensor'
    compensation = 'not needed'
    placement = 'after the modelled sensor dynamics, before the calibration'
    physics = ('the measurement follows the true quantity through a first-order lag: '
               'transmitter filtering, tubing to the transducer, thermal mass of the sensor')
    names = ('tau_lag_s',)
    units = ('s',)

    def bounds(self, ctx: Context) -> np.ndarray:
        """Time constant from 0 to half a loop period (at most 5 s)."""
        return np.array([[0.0, max(2 * ctx.dt_s, min(0.5 * ctx.period_s, 5.0))]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Log-spaced time constants from half a sample to a sixth of a period."""
        hi = min(self.bounds(ctx)[0, 1], ctx.period_s / 6.0)
        lo = 0.5 * ctx.dt_s
        if hi <= lo:
            return [np.array([lo])]
        return [np.array([x]) for x in np.geomspace(lo, hi, 6)]

    def null(self, ctx: Context) -> np.ndarray:
        """No lag."""
        return np.zeros(1)

    def sensor(self, theta: np.ndarray, t_s: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Lagged measurement (exact zero-order-hold discretisation)."""
        tau = float(theta[0])
        if tau <= 0.0:
            return s
        return simulate_first_order(s, t_s, tau)

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """The extra time constant (and the modelled one beside it)."""
        out = {'tau_lag_s': Quantity(float(theta[0]), 's', 'extra first-order time constant')}
        if ctx.channel == 'pressure':
            out['tau_s'] = Quantity(float(info['x_chain'][11]), 's',
                                    "the chain's own pressure-sensor time constant")
        return out

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        tau = values['tau_lag_s'].value
        extra = ''
        if 'tau_s' in values:
            extra = (f' (in series with the modelled {values["tau_s"].value:.3g} s; the two '
                     'time constants are interchangeable)')
        return (f'The measured {ctx.quantity} lags the actuator through an extra first-order '
                f'lag of {tau:.3g} s{extra}: transmitter filtering, tubing to the transducer or '
                'the thermal mass of the sensor. Feedback on this signal sees the actuator late: '
                'include the lag in the model or observer, or use a faster sensor.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Rate-correlated residual that decays after reversals rather than stopping."""
        f = loc.features
        score = 0.5 * float(loc.ccf_rate['significant'])
        score += 0.5 * float(np.clip(1.0 - abs(f['early_late_ratio'] - 1.5), 0.0, 1.0))
        return score, rate_correlation(loc)

    def compensation_note(self, values, ctx) -> str:
        """The lag is in the reading, not in the actuator."""
        tau = values['tau_lag_s'].value
        return (f'not needed for the actuator: the {tau:.3g} s lag is in the reading, so H⁻¹ '
                'places the actuator right and the reading follows later; a controller closed '
                'on this reading must allow for the lag')


MECHANISM = SensorLag()
