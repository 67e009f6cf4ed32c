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

"""``friction``: a sliding-friction force in the measured quantity, reversing with the motion.

Placement: a term of the sensed quantity, after B, through the sensor:
``q = x + F z``, with ``F`` a linear coefficient in the measurement's units
(the friction force, half the height of the band between rising and falling
motion) and ``z`` in ``[-1, 1]`` the friction's state after Dahl's model in
the travel, ``dz/dx = (1 - z sign(dx)) / l`` (``l`` the presliding travel over
which the force turns round after a reversal; exact exponential steps, so
the block is rate-independent, as Coulomb friction is). A force measured at
a drive that moves something through a seal or a guide (a load cell on a
cylinder moved from outside, the force on a valve stem) reads the friction
*with* the direction of motion: higher while the travel rises, lower while
it falls, whatever the force's own slope over the travel.

Every loop the chain makes runs the other way: H and B make the output lag
the motion (counter-clockwise against the command for a rising reading),
and so do a lag, a delay and a second order. A band that lags is therefore
not claimed as friction while the reading has a clear slope of its own
(:meth:`Friction.implausible`): that is the hysteresis's own loop (backlash,
curved branches: :mod:`.loop_shape`; stick-slip: :mod:`.stiction`). On a
reading that is nearly flat over the travel (a force held by a pressure),
the band is the loop, and its sense needs no comparison.

Signature: a residual whose mean differs between rising and falling motion,
steady over the travel.
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity
from hyst_id.diagnosis.mechanisms.static_nonlinearity import curve_change

__all__ = ['Friction', 'MECHANISM', 'dahl_state']

#: Presliding travel bounds, as fractions of the training travel.
_LENGTH = (0.002, 0.3)


@njit(cache=True)
def _dahl(x, length):
    n = x.shape[0]
    z = np.zeros(n)
    zk = 0.0
    for k in range(1, n):
        dx = x[k] - x[k - 1]
        if dx > 0.0:
            zk = 1.0 - (1.0 - zk) * np.exp(-dx / length)
        elif dx < 0.0:
            zk = -1.0 + (1.0 + zk) * np.exp(dx / length)
        z[k] = zk
    return z


def dahl_state(x: np.ndarray, length: float) -> np.ndarray:
    """Dahl's friction state along the path ``x`` (starting at 0), in ``[-1, 1]``.

    Parameters
    ----------
    x : numpy.ndarray
        The travel, in any unit.
    length : float
        Presliding travel (same unit as ``x``, > 0): after a reversal the
        state closes the gap to its new sign by a factor ``e`` per ``length``
        travelled.
    """
    return _dahl(np.ascontiguousarray(x, dtype=float), float(length))


def _open_ends(chain: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A paper-loop chain whose top and bottom lines lie beyond the commanded range.

    The data-built loops bend onto flat inner lines inside the range's ends,
    where the travel then hardly moves: a friction state driven by it would
    turn round far too slowly at the reversals. Here the inner lines (slope
    0.3 of the sides) meet the sides 15 % of the range beyond its ends.
    """
    out = np.array(chain, dtype=float)
    m_l, m_r, c_l, c_r = out[0], out[1], out[4], out[5]
    lo, hi = float(np.min(v)), float(np.max(v))
    v1, v2 = hi + 0.15 * (hi - lo), lo - 0.15 * (hi - lo)
    m_t = 0.3 * min(m_l, m_r)
    out[2] = out[3] = m_t
    out[6] = m_r * (v1 - c_r) - m_t * v1
    out[7] = m_l * (v2 - c_l) - m_t * v2
    return out


class Friction(Mechanism):
    """A Dahl friction force: a term of the sensed quantity with its own coefficient."""

    id = 'friction'  # noqa: A003
    title = 'sliding friction in the measured force (a band reversing with the motion)'
    stage = 'quantity'
    compensation = 'not in-line'
    placement = ('a term of the sensed quantity after the backlash B, through the sensor: '
                 'a force with the sign of the motion')
    physics = ('sliding friction of a seal, guide or stem: the measured force is higher '
               'while the travel rises than while it falls, and turns round over a short '
               'presliding travel after each reversal')
    names = ('presliding_fraction',)
    units = ('1',)
    n_linear = 1
    #: what turns round after a reversal, in the words of ``presliding``
    turns = 'force'

    def bounds(self, ctx: Context) -> np.ndarray:
        """Presliding travel per :data:`_LENGTH`."""
        return np.array([list(_LENGTH)])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Sharp, moderate and slow reversals."""
        return [np.array([le]) for le in (0.005, 0.03, 0.1)]

    def null(self, ctx: Context) -> np.ndarray:
        """A moderate presliding travel (the force itself is linear, fitted from zero)."""
        return np.array([0.03])

    def data_starts(self, model, data, p_prev, chain_starts) -> list[np.ndarray]:
        """Thin loops built from the data, with the friction polished in: the best two.

        The current chain has made what it could of the band with its own loop
        (a steep, wrong-way loop on a flat reading); the force is better found
        from a chain that leaves the band to the block: the family's data-built
        loops a half, a twentieth and a two-hundredth of the measured width
        wide (paper loops with their inner lines opened beyond the commanded
        range, :func:`_open_ends`), the friction at each of its starts, a short
        least-squares polish each, and the best two polished to the end.
        """
        from hyst_id.diagnosis.select import polish
        from hyst_id.identification.starts import data_starts as built
        n, nc = data.n_train, model.n_chain
        sl = model.slices[self.id]
        chains = [_open_ends(c, data.v[:n]) if model.spec.family.id == 'tk' else c
                  for c in built(model.spec, data.t_s[:n], data.v[:n], data.y[:n],
                                 splits=((0.5, 0.5), (0.05, 0.5), (0.005, 0.5)),
                                 per_split=1)]
        chains = [c for c in chains if np.all((c >= model.bounds[:nc, 0])
                                              & (c <= model.bounds[:nc, 1]))]
        short = []
        for c in chains:
            for th in self.starts(model.ctx):
                p = np.array(p_prev, dtype=float)
                p[:nc], p[sl] = c, th
                if model.feasible(p):
                    q, f, _ = polish(model, data, p, max_nfev=4 * (model.n_params + 1))
                    short.append((f, q))
        short.sort(key=lambda z: z[0])
        return [polish(model, data, q, max_nfev=600)[0] for _, q in short[:2]]

    def quantity_terms(self, theta, x, span) -> list[np.ndarray]:
        """Dahl's state along the travel."""
        lo, hi = span
        return [dahl_state(x, float(theta[0]) * (hi - lo))]

    def undo(self, theta, t_s, v, y, terms, ctx):
        """The measurement without the fitted friction force."""
        own = [c for k, c in terms.items() if k.startswith(f'{self.id}:')]
        return v, (y - np.sum(own, axis=0)) if own else y

    def _force_and_change(self, coef, labels, span) -> tuple[float, float]:
        """The friction force and the reading's change over the travel (both measured).

        The change is the static map of the travel from its bottom to its top:
        the linear term over the travel span, or, with a cubic curve of the
        normalised travel ``z`` (:mod:`.static_nonlinearity`), the curve from
        ``z = -1`` to ``1``; a creep's slow share adds to the linear term.
        """
        labels = list(labels)
        c = dict(zip(labels, (float(x) for x in coef)))
        force = c[f'{self.id}:0']
        gain = c['sensor'] + c.get('creep:0', 0.0)
        if 'quantity:1' in c:            # the static curve's basis z, z^2, z^3
            change = curve_change(gain, c.get('quantity:2', 0.0))
        else:
            lo, hi = span
            change = gain * (hi - lo)
        return force, change

    def _band(self, theta, info, ctx) -> tuple[float, dict[str, Quantity]]:
        """The band's signed half-height, and the values every Dahl block reports.

        Those are the reading's change over the travel and the presliding
        travel in command units.
        """
        force, change = self._force_and_change(info['coef'], info['labels'], info['span'])
        lo, hi = info['span']
        presliding = float(theta[0]) * (hi - lo) / max(abs(info['pos_per_cmd']), 1e-300)
        return force, {'reading_change': Quantity(change, ctx.meas_unit,
                                                  "the reading's own change over the travel, "
                                                  'bottom to top (the static map)'),
                       'presliding': Quantity(presliding, ctx.cmd_unit,
                                              f'travel over which the {self.turns} turns '
                                              'round after a reversal (1/e of the gap left)')}

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """The force in measurement units, the presliding travel in command units."""
        force, common = self._band(theta, info, ctx)
        change = common['reading_change'].value
        return {'friction_force': Quantity(abs(force), ctx.meas_unit,
                                           'sliding friction: half the height of the band '
                                           'between rising and falling motion'),
                'higher_while_rising': Quantity(float(force > 0.0), 'bool',
                                                '1 if the reading is higher while the command '
                                                'rises (a clockwise loop against it)'),
                'leads_motion': Quantity(float(force * change > 0.0), 'bool',
                                         '1 if the band runs against the sense of the '
                                         "chain's own loop (a force with the motion)"),
                **common}

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """A band below the noise, or one running the hysteresis's way on a sloped reading.

        Sloped: the reading changes over the travel by more than the band's
        height (twice the force).
        """
        if coef is None or labels is None or f'{self.id}:0' not in labels:
            return ''
        force, change = self._force_and_change(coef, labels, span)
        if abs(force) < noise_std:
            return (f'its force ({abs(force):.3g} in the measurement) is below the '
                    f'measurement noise ({noise_std:.3g})')
        if force * change < 0.0 and abs(change) > 2.0 * abs(force):
            return ("its band lags the motion, as the hysteresis's own loop does (backlash, "
                    'curved branches), on a reading with a clear slope of its own')
        return ''

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        f = values['friction_force']
        pre = values['presliding']
        up, down = (('rises', 'falls') if values['higher_while_rising'].value
                    else ('falls', 'rises'))
        change = abs(values['reading_change'].value)
        if values['leads_motion'].value:
            sense = ("the loop this makes runs the other way round from the hysteresis's, "
                     'so it is no lag')
        elif change <= 2.0 * f.value:
            sense = 'the reading hardly changes with the travel, so the band is the loop'
        else:
            sense = ("but the band runs the hysteresis's own way round on a reading that "
                     'changes over the travel: it may be backlash rather than friction')
        return (f'The measured {ctx.quantity} carries a sliding-friction force of '
                f'±{f.value:.3g} {f.unit}: higher while the command {up} than while it '
                f'{down}, turning round within {pre.value:.3g} {pre.unit} of travel after '
                f'each reversal ({sense}). Friction of a seal, guide or stem in the force '
                'path: compensate it with a friction feed-forward (the force with the sign '
                'of the velocity), or lubricate or change the seal.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Residual mean split by the direction of motion."""
        t = loc.features['direction_split_t']
        return (float(np.clip((abs(t) - 3.0) / 5.0, 0.0, 1.0)),
                {'direction_split_t': t})

    def compensation_note(self, values, ctx) -> str:
        """Not in-line: a friction force is not in H's inverse."""
        return ('not compensated in-line: the compensator inverts H and B; add a friction '
                f'feed-forward of ±{values["friction_force"].value:.3g} '
                f'{values["friction_force"].unit} with the sign of the velocity where the '
                'force is the controlled quantity')


MECHANISM = Friction()
