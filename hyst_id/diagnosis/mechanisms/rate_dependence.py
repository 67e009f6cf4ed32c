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

"""``rate_dependence``: a hysteresis loop that widens with the command rate.

Placement: inside H. The left and right lines move apart by
``kappa * r`` each, ``c_l -> c_l - kappa r``, ``c_r -> c_r + kappa r``, where
``r`` is the command-rate magnitude low-passed with ``tau_r`` (viscous drag and
eddy currents grow with speed; the filter is the drive's own inertia).
``kappa`` is in command units of half-width per command unit per second,
i.e. seconds, so it does not depend on the command's scale.

Signature: residual of opposite sign while rising and falling, growing with
the rate; the loop measured at high rates is wider than the fitted one.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity
from hyst_id.models.backlash import backlash_step
from hyst_id.models.tk import hysteresis_step, initial_output

__all__ = ['RateDependence', 'MECHANISM', 'rate_actuator']


@njit(cache=True)
def rate_actuator(p: np.ndarray, kappa_s: float, tau_s: float, v: np.ndarray,
                  t_s: np.ndarray) -> np.ndarray:
    """``B(H(v))`` with the left/right lines moved apart by ``kappa * filtered |dv/dt|``."""
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    m_bl, c_bl, c_br = p[8], p[9], p[10]
    n = v.shape[0]
    out = np.empty(n)
    u = initial_output(v[0], m_r, m_t, m_b, c_r, c_t, c_b)
    y = m_bl * (u - c_br)
    out[0] = y
    r = 0.0
    for j in range(1, n):
        dt = t_s[j] - t_s[j - 1]
        a = math.exp(-dt / tau_s) if tau_s > 0.0 else 0.0
        r = a * r + (1.0 - a) * abs(v[j] - v[j - 1]) / dt
        w = kappa_s * r
        u = hysteresis_step(v[j], v[j - 1], u, m_l, m_r, m_t, m_b, c_l - w, c_r + w, c_t, c_b)
        y = backlash_step(u, y, m_bl, c_bl, c_br)
        out[j] = y
    return out


class RateDependence(Mechanism):
    """Loop half-width growing with the filtered command rate."""

    id = 'rate_dependence'  # noqa: A003
    title = 'hysteresis loop widening with the command rate'
    stage = 'actuator'
    families = ('tk',)   # it rewrites the paper's loop itself
    compensation = 'not in-line'
    placement = 'inside the hysteresis H (its left and right lines)'
    physics = ('rate-dependent losses in the actuator (viscous drag, eddy currents) widen '
               'the loop when the command moves fast')
    names = ('width_per_rate_s', 'rate_filter_tau_s')
    units = ('s', 's')

    def bounds(self, ctx: Context) -> np.ndarray:
        """Width per rate up to half a loop period; rate filter up to a loop period."""
        return np.array([[0.0, 0.5 * ctx.period_s], [0.0, ctx.period_s]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Three widths, a fast and a slow rate filter."""
        p = ctx.period_s / (2 * np.pi)
        return [np.array([k * p, tau]) for k in (0.05, 0.2, 0.6)
                for tau in (ctx.dt_s, 0.1 * ctx.period_s)]

    def null(self, ctx: Context) -> np.ndarray:
        """No rate dependence."""
        return np.array([0.0, ctx.dt_s])

    def actuator(self, theta, x_chain, t_s, v) -> np.ndarray:
        """Actuator position with the rate-dependent loop."""
        return rate_actuator(np.ascontiguousarray(x_chain[:11]), float(theta[0]),
                             float(theta[1]), np.ascontiguousarray(v), t_s)

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Width per rate, filter, and the extra width at the record's typical rate."""
        kappa, tau = float(theta[0]), float(theta[1])
        cmd = info['command']
        rate = np.abs(np.gradient(cmd, ctx.t_s))
        moving = rate > 0.05 * (np.percentile(rate, 95) or 1.0)
        typical = float(np.median(rate[moving])) if moving.any() else 0.0
        return {'width_per_rate_s': Quantity(kappa, 's', f'extra half-width ({ctx.cmd_unit}) '
                                             f'per {ctx.cmd_unit}/s of command rate'),
                'rate_filter_tau_s': Quantity(tau, 's', 'time constant of the rate estimate'),
                'typical_rate': Quantity(typical, f'{ctx.cmd_unit}/s',
                                         'median command rate while moving'),
                'extra_half_width_at_typical_rate': Quantity(
                    kappa * typical, ctx.cmd_unit, 'extra half-width of the loop at that rate')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        k = values['width_per_rate_s'].value
        w = values['extra_half_width_at_typical_rate']
        r = values['typical_rate']
        return (f'The hysteresis loop widens with the command rate: {k:.3g} {ctx.cmd_unit} of '
                f'extra half-width per {ctx.cmd_unit}/s (rate filter '
                f'{values["rate_filter_tau_s"].value:.2g} s), i.e. {w.value:.3g} {w.unit} on '
                f'each side at the typical {r.value:.3g} {r.unit}. Viscous drag or eddy '
                'currents in the actuator; a rate-independent inverse (as in the paper) '
                'under-compensates fast moves: add a rate-dependent width to the inverse or '
                'limit the command rate.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Rising and falling residuals of opposite sign that grow with rate."""
        f = loc.features
        score = 0.6 * float(np.clip((abs(f['direction_split_t']) - 3.0) / 5.0, 0.0, 1.0))
        score += 0.4 * float(np.clip((1.0 / max(f['slow_fast_ratio'], 1e-9) - 1.0), 0.0, 1.0))
        return score, {'rising_vs_falling_t': f['direction_split_t']}

    def compensation_note(self, values, ctx) -> str:
        """H and its inverse are rate independent."""
        return ('not compensated: H and its inverse are rate independent, so the '
                'compensation is right only near the rates it was identified at; identify at '
                'the operating rates')


MECHANISM = RateDependence()
