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

"""``actuator_dynamics``: the travel follows H and B through a second-order system.

Placement: between the static loop and the travel, ``x = G(s) B(H(v))`` with
``G = w^2 / (s^2 + 2 zeta w s + w^2)``: a moving mass on a spring (valve
stem and diaphragm, a piezo stack with its load) that overshoots and rings
after a fast move (underdamped only, see below). ``G`` is linear and so are
the sensor dynamics and the calibration, so the block is evaluated on the
sensor's output (the same product of transfer functions). Parameters:
``zeta`` (1) and ``omega_n_rad_s`` (rad/s).

It differs from :mod:`.sensor_lag` in its order: an underdamped system rings
after reversals, which no first-order lag does. An overdamped one is close
to a lag, so the damping is bounded at 0.7 and that case is left to the lag.
From :mod:`.dead_time`: a delay shifts the response without rounding it.

Signature: a residual correlated with the command rate that oscillates after
reversals at about ``omega_n``.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity, rate_correlation
from hyst_id.models.sensors import simulate_second_order

__all__ = ['ActuatorDynamics', 'MECHANISM']

#: Damping ratio bounds and starts: underdamped only. An overdamped second order is close
#: to a first-order lag, which is :mod:`.sensor_lag`'s (with the damping up to 2 the block
#: took two of four recordings with a 0.4 s lag from it).
_ZETA = (0.05, 0.7)
_ZETA_STARTS = (0.15, 0.3, 0.5)


class ActuatorDynamics(Mechanism):
    """Second-order dynamics between the static loop and the travel."""

    id = 'actuator_dynamics'  # noqa: A003
    title = 'second-order actuator dynamics (inertia, resonance)'
    stage = 'sensor'
    compensation = 'not in-line'
    placement = ('between H, B and the travel (evaluated after the linear sensor, where it '
                 'is the same): w^2 / (s^2 + 2 zeta w s + w^2)')
    physics = ('the travel follows the static loop through a mass on a spring: the valve '
               'stem and diaphragm, a piezo stack with its load, overshooting and ringing '
               'after a fast move')
    names = ('zeta', 'omega_n_rad_s')
    units = ('1', 'rad/s')

    def _omega_range(self, ctx: Context) -> tuple[float, float]:
        """From a quarter of the loop frequency to a fifth of the Nyquist frequency."""
        lo = 0.25 * 2.0 * np.pi / max(ctx.period_s, 1e-9)
        hi = 0.2 * np.pi / max(ctx.dt_s, 1e-12)
        return lo, max(hi, 4.0 * lo)

    def bounds(self, ctx: Context) -> np.ndarray:
        """Damping 0.05 to 0.7; natural frequency per :meth:`_omega_range`."""
        return np.array([list(_ZETA), list(self._omega_range(ctx))])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Damping ratios 0.15, 0.3, 0.5 by four log-spaced natural frequencies."""
        lo, hi = self._omega_range(ctx)
        omegas = np.geomspace(2.0 * lo, min(hi, 200.0 * lo), 4)
        return [np.array([z, w]) for z in _ZETA_STARTS for w in omegas]

    def null(self, ctx: Context) -> np.ndarray:
        """Most damped at the fastest frequency: almost the identity."""
        return np.array([_ZETA[1], self._omega_range(ctx)[1]])

    def sensor(self, theta: np.ndarray, t_s: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The sensor's output through the second-order system (exact zero-order hold)."""
        return simulate_second_order(s, t_s, float(theta[0]), float(theta[1]))

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Damping, natural frequency in rad/s and Hz, overshoot to a step."""
        zeta, omega = float(theta[0]), float(theta[1])
        overshoot = 100.0 * np.exp(-np.pi * zeta / np.sqrt(1.0 - zeta ** 2))   # zeta <= 0.7
        return {'zeta': Quantity(zeta, '1', 'damping ratio'),
                'omega_n_rad_s': Quantity(omega, 'rad/s', 'natural frequency'),
                'f_n_hz': Quantity(omega / (2.0 * np.pi), 'Hz', 'natural frequency'),
                'overshoot_percent': Quantity(float(overshoot), '%',
                                              'overshoot of the travel after a step')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        zeta = values['zeta'].value
        kind = 'rings after fast moves' if zeta < 0.5 else 'overshoots after fast moves'
        return (f'The actuator has second-order dynamics: the travel follows the static loop '
                f'with damping {zeta:.2g} at {values["f_n_hz"].value:.3g} Hz '
                f'({values["omega_n_rad_s"].value:.3g} rad/s) and '
                f'{values["overshoot_percent"].value:.1f} % overshoot, so it {kind}: a mass '
                'on a spring (stem and diaphragm, a loaded piezo stack). Keep command changes '
                'slower than this, or shape them (notch or pre-filter) before the actuator.')

    def evidence(self, loc) -> tuple[float, dict]:
        """A residual correlated with the command rate (ringing is decided held-out)."""
        return 0.5 * float(loc.ccf_rate['significant']), rate_correlation(loc)

    def compensation_note(self, values, ctx) -> str:
        """H^-1 is static: the dynamics stay."""
        return ('not compensated in-line: H⁻¹ is static and the travel still follows it '
                f'through the {values["f_n_hz"].value:.3g} Hz second-order dynamics; shape '
                'the desired trajectory (an inverse pre-filter) or close a loop on position')


MECHANISM = ActuatorDynamics()
