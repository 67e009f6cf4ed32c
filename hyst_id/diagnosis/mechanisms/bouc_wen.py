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

"""``bouc_wen``: a hysteresis state in the travel that turns round smoothly after each reversal.

Placement: a term of the travel after B, through the sensor, ``q = x - h z``
with ``z`` in ``[-1, 1]`` the state of Dahl's model along the travel
(:func:`~hyst_id.diagnosis.mechanisms.friction.dahl_state`: after a
reversal it closes the gap to its new sign by a factor ``e`` per presliding
length ``l``, the rate-independent Bouc–Wen state with ``n = 1`` and
``beta = gamma``) and ``h`` its height in the measurement. This is the
Bouc–Wen model of a piezo stack's travel against its voltage
(``x = d V - h z``): the reading *lags* the motion, so the loop runs the
paper's way round, with branches that curve over the presliding travel and
do not end on flat lines.

The math is :mod:`.friction`'s (a Dahl state as a term of the measured
quantity); what differs is the sense, and so the physics. A band with the
motion (higher while rising) on a sloped reading is friction in the force
path; a band against it is the actuator's own hysteresis. :mod:`.friction`
refuses the second; this block refuses the first, a band below the noise, and
a band on a reading that hardly changes over the travel (there the band is the
loop, friction's to take). A delay, a lag or a second order makes a lagging
loop too, but one that grows with the command's speed, which a Dahl state in
the travel does not: on the blind family's 90 position recordings
(``bench/blind_family.py``, docs/diagnosis.md) the block took no lag, delay
or second order; it moved one verdict (#104, a second order with creep at
1.1 x the floor, ``creep`` -> ``bouc_wen``). The pressure half was not rerun
with it, so it is offered on the position reading only.

Signature: a residual that differs between rising and falling motion and
turns round over a travel after each reversal.
"""

from __future__ import annotations

from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.friction import Friction

__all__ = ['BoucWen', 'MECHANISM']


class BoucWen(Friction):
    """A Bouc–Wen (Dahl) state lagging the travel: a term of the sensed quantity."""

    id = 'bouc_wen'  # noqa: A003
    title = 'a smooth hysteresis state in the travel (Bouc-Wen: curved, lagging branches)'
    stage = 'quantity'
    compensation = 'not in-line'
    #: on the position reading only: the blind family's pressure half has not been rerun
    #: with it (docs/diagnosis.md, "Physics from simulators written apart")
    channels = ('position',)
    turns = 'state'
    #: friction's fit, judged in the other sense: a round that tries both fits once
    fits_as = 'friction'
    placement = ('a term of the travel after the backlash B, through the sensor: a state '
                 'that lags the motion and turns round smoothly after each reversal')
    physics = ("the actuator's own hysteresis as a Bouc-Wen state (a piezo stack, a "
               'magnetostrictive rod): after each reversal the travel turns round over a '
               "presliding travel instead of on the straight lines of the paper's loop")

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """The state's height in measurement units, its presliding travel in command units."""
        force, common = self._band(theta, info, ctx)
        change = common['reading_change'].value
        return {'state_height': Quantity(abs(force), ctx.meas_unit,
                                         'half the height of the band the state adds '
                                         'between rising and falling motion'),
                'height_share_percent': Quantity(
                    100.0 * abs(force) / max(abs(change), 1e-300), '%',
                    "the band's half-height as a share of the reading's change over the "
                    'travel'),
                **common}

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """A band below the noise, or one with the motion (friction's), or a flat reading."""
        if coef is None or labels is None or f'{self.id}:0' not in labels:
            return ''
        force, change = self._force_and_change(coef, labels, span)
        if abs(force) < noise_std:
            return (f'its band ({abs(force):.3g} in the measurement) is below the '
                    f'measurement noise ({noise_std:.3g})')
        if force * change > 0.0:
            return ('its band runs with the motion (higher while rising): that is a '
                    'friction force, not a state that lags the travel')
        if abs(change) <= 2.0 * abs(force):
            return ('the reading hardly changes over the travel, so a band is friction '
                    'or the loop itself, not a lagging share of the travel')
        return ''

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        h, pre = values['state_height'], values['presliding']
        share = values['height_share_percent'].value
        return (f'The travel carries a hysteresis state that lags the motion by ±{h.value:.3g} '
                f"{h.unit} ({share:.3g} % of the reading's change over the travel) and turns "
                f'round within {pre.value:.3g} {pre.unit} of travel after each reversal: the '
                "loop's branches curve (a Bouc-Wen or Dahl loop, as a piezo stack's) where "
                "the paper's loop has straight lines. Identify it with a smooth loop model "
                "(identify --model smooth) or a Bouc-Wen model; the paper's H^-1 leaves "
                'this share uncompensated.')

    def compensation_note(self, values, ctx) -> str:
        """Not in-line: the compensator inverts H and B only."""
        return ('not compensated in-line: the compensator inverts H and B; a Bouc-Wen '
                f'share of ±{values["state_height"].value:.3g} {values["state_height"].unit} '
                'needs a Bouc-Wen (or smooth-family) inverse')


MECHANISM = BoucWen()
