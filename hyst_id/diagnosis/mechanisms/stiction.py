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

Placement: on the actuator position, after B, before the end stops: the
position stays put while the demand ``x = B(H(v))`` is within ``band`` of
it; once beyond, it slips onto the demand. A slow ramp becomes a staircase
with steps of ``band``. The common two-parameter model also has a dynamic
band (the actuator slips to ``dynamic`` short of the demand); that is
exactly a backlash ``dynamic`` wider ahead of a zero dynamic band, so the
chain's backlash carries it and only the slip band is searched. The
initial stuck position (its offset from the initial demand) is the block's
second parameter: the staircase never forgets where it started.

Fitting: the simulated staircase lines up with the measured one only within
about 0.3 % of the exact parameters, so the block's starts come from the
measured events (:mod:`hyst_id.diagnosis.stick_events`: plateau levels,
slip samples, and the stick and slip conditions, fitted together with the
chain). A dense grid over the band remains as a fallback for records that
are not a clean staircase.

Signature: the measurement holds still while the model moves; residual
largest when the command moves slowly, saw-tooth shaped.
"""

from __future__ import annotations

from typing import Any

from numba import njit
import numpy as np

from hyst_id.diagnosis.baseline import structured_starts
from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity
from hyst_id.diagnosis.stick_events import fit_stick_slip_events

__all__ = ['Stiction', 'MECHANISM', 'STAIRCASE_SPLITS', 'stick_slip']

#: Data-built chain starts for the event fit: loop width factors x share of B.
STAIRCASE_SPLITS = tuple((f, s) for f in (0.7, 1.0, 1.4, 2.0) for s in (0.1, 0.5))


@njit(cache=True)
def stick_slip(x: np.ndarray, band: float, stuck0: float) -> np.ndarray:
    """Position after stick-slip friction for a demanded position ``x``.

    Stays while ``|x - position| <= band``, else slips onto ``x``; starts
    stuck at ``stuck0``.
    """
    out = np.empty(x.shape[0])
    out[0] = stuck0
    for j in range(1, x.shape[0]):
        if abs(x[j] - out[j - 1]) <= band:
            out[j] = out[j - 1]
        else:
            out[j] = x[j]
    return out


class Stiction(Mechanism):
    """Stick-slip on the actuator position: slip band and initial stuck offset."""

    id = 'stiction'  # noqa: A003
    title = 'stick-slip friction in the actuator'
    stage = 'position'
    families = ('tk',)   # it rewrites the paper's loop itself
    compensation = 'not in-line'
    placement = 'on the actuator position, after the backlash B, before the end stops'
    physics = ('static friction holds the actuator until the drive force exceeds it, then the '
               'actuator slips: a ramp becomes a staircase')
    names = ('band_fraction', 'initial_offset_fraction')
    units = ('1', '1')
    smooth = False

    def bounds(self, ctx: Context) -> np.ndarray:
        """Band up to 20 % of the travel; initial offset within +-20 % of it."""
        return np.array([[0.0, 0.2], [-0.2, 0.2]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Bands 0.3 to 10 % of the travel, starting on the demand."""
        return [np.array([s, 0.0]) for s in (0.003, 0.006, 0.012, 0.025, 0.05, 0.1)]

    def grid(self, ctx: Context) -> list[np.ndarray]:
        """200 bands (0.2 to 20 % of the travel, log-spaced) x 3 initial offsets."""
        return [np.array([s, f * s]) for s in np.geomspace(0.002, 0.2, 200)
                for f in (-0.5, 0.0, 0.5)]

    def data_starts(self, model: Any, data: Any, p_prev: np.ndarray,
                    chain_starts: list[np.ndarray]) -> list[np.ndarray]:
        """Chain and block from the measured plateaus and slips (position records only)."""
        if model.channel != 'position' or model.ids != (self.id,):
            return []
        n = data.n_train
        t, v, y = data.t_s[:n], data.v[:n], data.y[:n]
        spec = model.spec.with_bounds(model.bounds[:model.n_chain])
        chains = [np.asarray(p_prev[:model.n_chain])]
        chains += [np.asarray(c[:model.n_chain]) for c in chain_starts]
        # the staircase hides the loop: data-built chains over a wider range of widths
        chains += structured_starts(spec, t, v, y, np.zeros(0), splits=STAIRCASE_SPLITS)
        fits = fit_stick_slip_events(spec, t, v, y, data.noise_std, chains)
        # several chains can reproduce every training slip; the four best compete on the
        # training error of the simulated staircase
        out = []
        for f in fits[:4]:
            p = np.array(p_prev, dtype=float)
            p[:model.n_chain] = f.chain
            p[model.slices[self.id]] = (f.band_fraction, f.offset_fraction)
            out.append(p)
        return out

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """Slips below twice the noise std are not seen as slips.

        Such a block only lets the chain refit (a tiny band also acts like a
        sub-sample lag).
        """
        jump = abs(float(coef[0])) * float(theta[0]) * (span[1] - span[0])
        if jump < 2.0 * noise_std:
            return (f'slip band {jump:.3g} is below twice the noise std ({noise_std:.3g}): '
                    'no visible slips')
        return ''

    def null(self, ctx: Context) -> np.ndarray:
        """No stiction."""
        return np.zeros(2)

    def position(self, theta, x, span) -> np.ndarray:
        """Stick-slip on the position."""
        travel = span[1] - span[0]
        band = float(theta[0]) * travel
        if band <= 0.0:
            return x
        return stick_slip(np.ascontiguousarray(x), band, float(x[0] + theta[1] * travel))

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Slip band in measurement units, % of travel and command equivalent."""
        lo, hi = info['span']
        band = float(theta[0]) * (hi - lo)
        gain = info['meas_per_pos']
        per_cmd = info['pos_per_cmd']
        out = {'slip_band': Quantity(abs(gain) * band, ctx.meas_unit,
                                     'demand beyond the stuck position needed to break away '
                                     '(= size of each slip), as measured')}
        if per_cmd:
            out['slip_band_command'] = Quantity(band / abs(per_cmd), ctx.cmd_unit,
                                                'the same band in command')
        out['slip_band_percent'] = Quantity(100.0 * float(theta[0]), '%',
                                            'slip band as a share of the travel')
        out['initial_offset'] = Quantity(gain * float(theta[1]) * (hi - lo), ctx.meas_unit,
                                         'stuck position at the start minus the demand')
        return out

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        s = values['slip_band']
        cmd = values.get('slip_band_command')
        cmd_words = f' (about {cmd.value:.3g} {cmd.unit} of command)' if cmd else ''
        return (f'The actuator sticks: it holds still until the demand has moved {s.value:.3g} '
                f'{s.unit}{cmd_words} away, then slips onto it in one jump: stick-slip '
                'friction in the drive or the valve packing (any dynamic band of the friction '
                'is carried by the backlash). Expect limit cycles under integral control; use '
                'friction compensation (knocker, dither) or service the actuator.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Measurement holding still while the model moves; residual largest at slow motion."""
        f = loc.features
        score = 0.6 * float(np.clip(f.get('stuck_fraction', 0.0) / 0.3, 0.0, 1.0))
        score += 0.4 * float(np.clip((f['slow_fast_ratio'] - 1.0) / 1.0, 0.0, 1.0))
        return score, {'stuck_fraction': f.get('stuck_fraction', 0.0),
                       'slow_motion_rms_ratio': f['slow_fast_ratio']}

    def compensation_note(self, values, ctx) -> str:
        """No in-line inverse of stick-slip."""
        band = values['slip_band']
        return (f'not in-line: H⁻¹ cannot undo stick-slip (slips of {band.value:.3g} '
                f'{band.unit}); a dither on the command or a positioner with friction '
                'compensation can')


MECHANISM = Stiction()
