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

"""``stiction``: stick-slip friction in the actuator.

Placement: on the actuator position, after B, before the end stops:
the position stays put while the drive's demand is within the static band
of it; once beyond, it slips to the dynamic band short of the demand (the
two-parameter stick-slip model used for control valves). A ramp becomes a
staircase with steps of ``static - dynamic``. Both bands are searched as
fractions of the training travel; because the cost is piecewise constant in
them (the staircase jumps), they are found on a dense grid and then on
finer local grids, alternating with least squares on the chain.

Signature: residual largest when the command moves slowly, saw-tooth
shaped, with power above the command's harmonics.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from hyst_id.diagnose.mechanisms.base import Context, Mechanism, Quantity

__all__ = ['Stiction', 'MECHANISM', 'stick_slip']


@njit(cache=True)
def stick_slip(x: np.ndarray, static_band: float, dynamic_band: float) -> np.ndarray:
    """Position after stick-slip friction for a demanded position ``x``."""
    out = np.empty(x.shape[0])
    out[0] = x[0]
    for j in range(1, x.shape[0]):
        d = x[j] - out[j - 1]
        if abs(d) <= static_band:
            out[j] = out[j - 1]
        else:
            out[j] = x[j] - math.copysign(dynamic_band, d)
    return out


class Stiction(Mechanism):
    """Two-parameter stick-slip on the actuator position."""

    id = 'stiction'  # noqa: A003
    title = 'stick-slip friction in the actuator'
    stage = 'position'
    placement = 'on the actuator position, after the backlash B, before the end stops'
    physics = ('static friction holds the actuator until the drive force exceeds it, then the '
               'actuator slips: a ramp becomes a staircase')
    names = ('static_band_fraction', 'dynamic_ratio')
    units = ('1', '1')
    smooth = False

    def bounds(self, ctx: Context) -> np.ndarray:
        """Static band up to 20 % of the travel; dynamic band below the static one."""
        return np.array([[0.0, 0.2], [0.0, 0.95]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Static bands 0.3 to 10 % of the travel, dynamic 0, 50 and 80 % of it."""
        return [np.array([s, d]) for s in (0.003, 0.006, 0.012, 0.025, 0.05, 0.1)
                for d in (0.0, 0.5, 0.8)]

    def grid(self, ctx: Context) -> list[np.ndarray]:
        """80 static bands (0.2 to 20 % of the travel, log-spaced) x 10 dynamic ratios."""
        return [np.array([s, d]) for s in np.geomspace(0.002, 0.2, 80)
                for d in np.linspace(0.0, 0.9, 10)]

    def null(self, ctx: Context) -> np.ndarray:
        """No stiction."""
        return np.zeros(2)

    def position(self, theta, x, span) -> np.ndarray:
        """Stick-slip on the position."""
        s = float(theta[0]) * (span[1] - span[0])
        if s <= 0.0:
            return x
        return stick_slip(np.ascontiguousarray(x), s, float(theta[1]) * s)

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Bands in measurement units, % of travel and command equivalents."""
        lo, hi = info['span']
        s_pos = float(theta[0]) * (hi - lo)
        d_pos = float(theta[1]) * s_pos
        gain = info['meas_per_pos']
        per_cmd = info['pos_per_cmd']
        out = {}
        for name, band, words in (('static_band', s_pos, 'demand needed to break away'),
                                  ('dynamic_band', d_pos, 'demand left after a slip'),
                                  ('slip_jump', s_pos - d_pos, 'size of each slip')):
            out[name] = Quantity(abs(gain) * band, ctx.meas_unit, words + ', as measured')
            if per_cmd:
                out[name + '_command'] = Quantity(band / abs(per_cmd), ctx.cmd_unit,
                                                  words + ', in command')
        out['static_band_percent'] = Quantity(100.0 * float(theta[0]), '%',
                                              'static band as a share of the travel')
        return out

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        s = values['static_band']
        j = values['slip_jump']
        cmd = values.get('static_band_command')
        cmd_words = f' (about {cmd.value:.3g} {cmd.unit} of command)' if cmd else ''
        return (f'The actuator sticks: it holds still until the demand has moved {s.value:.3g} '
                f'{s.unit}{cmd_words} away, then slips in jumps of {j.value:.3g} {j.unit}: '
                'stick-slip friction in the drive or the valve packing. Expect limit cycles '
                'under integral control; use friction compensation (knocker, dither) or '
                'service the actuator.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Measurement holding still while the model moves; residual largest at slow motion."""
        f = loc.features
        score = 0.6 * float(np.clip(f.get('stuck_fraction', 0.0) / 0.3, 0.0, 1.0))
        score += 0.4 * float(np.clip((f['slow_fast_ratio'] - 1.0) / 1.0, 0.0, 1.0))
        return score, {'stuck_fraction': f.get('stuck_fraction', 0.0),
                       'slow_motion_rms_ratio': f['slow_fast_ratio']}


MECHANISM = Stiction()
