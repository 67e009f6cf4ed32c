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

"""``loop_shape``: the loop's branches are curved, not the paper's straight lines.

Placement: H itself. Unlike the other blocks this one is not inserted after
H: it swaps H's family for the smooth one (:mod:`hyst_id.models.smooth`,
Prandtl-Ishlinskii plays behind a saturating input map, exact inverse) and
refits the chain, so the driver runs it through :attr:`swap_family`. Piezo
stacks, magnetic cores and soft-seal valves have curved branches: right
after a reversal the output moves slowly, then faster as more of the loop
opens, and it bends over towards the ends of the travel.

Signature: the residual of the piecewise-linear loop depends on the command
level *and* on the time since the last reversal (the curvature is largest
right after a reversal), harmonics of the excitation rather than slow drift.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Mechanism, Quantity

__all__ = ['LoopShape', 'MECHANISM']


class LoopShape(Mechanism):
    """Curved branches: H refitted with the smooth family."""

    id = 'loop_shape'  # noqa: A003
    title = 'curved loop branches (smooth hysteresis)'
    stage = 'actuator'
    compensation = 'family'
    placement = 'H itself: the hysteresis loop of the actuator'
    physics = ('the hysteresis loop bends (piezo stack, magnetic core, soft seals): its '
               "branches are curves, not the straight lines of the paper's loop")
    #: The hysteresis family the block swaps in (the driver refits the whole chain with it).
    swap_family = 'smooth'

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """The smooth loop's width, saturation and slope past it, in command units."""
        from hyst_id.models.registry import get_family
        fam = get_family(self.swap_family)
        h = np.asarray(info['x_chain'][:fam.n_params], dtype=float)
        d = fam.describe(h)
        a = abs(ctx.command_scale[0])
        return {
            'loop_width': Quantity(d['loop_width_cmd'] * a, ctx.cmd_unit,
                                   'width of the loop in the linear limit'),
            'saturation_reach': Quantity(d['saturation_cmd'] * a, ctx.cmd_unit,
                                         'command distance over which the branches bend '
                                         'over towards the ends of the travel'),
            'er_holdout_piecewise_linear': Quantity(info.get('er_before', np.nan), '%',
                                                    "held-out %e_r of the paper's loop"),
            'er_holdout_smooth': Quantity(info.get('er_after', np.nan), '%',
                                          'held-out %e_r of the smooth loop'),
        }

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        smooth = values['er_holdout_smooth'].value
        linear = values['er_holdout_piecewise_linear'].value
        width = values['loop_width'].value
        return ("The loop's branches are curved: the smooth hysteresis family predicts the "
                f'held-out part with %e_r {smooth:.3g} against {linear:.3g} for the '
                f"paper's piecewise-linear loop (loop width about {width:.3g} {ctx.cmd_unit}). "
                'The curvature belongs to the hysteresis itself, not to a block after it: '
                'identify with `hyst-id identify --model smooth` (or `auto`) and compensate '
                'with that family.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Residual structured by command level and largest right after reversals."""
        f = loc.features
        level = float(np.clip((f['level_mean_t'] - 3.0) / 5.0, 0.0, 1.0))
        early = float(np.clip((f['early_late_ratio'] - 1.0) / 1.0, 0.0, 1.0))
        periodic = float(np.clip(f['harmonic_fraction'] / 0.5, 0.0, 1.0))
        score = max(level, early) * (0.5 + 0.5 * periodic)
        return score, {'early_late_ratio': f['early_late_ratio'],
                       'harmonic_fraction': f['harmonic_fraction']}

    def compensation_note(self, values, ctx) -> str:
        """Identify with the smooth family; the compensator inverts it."""
        return ('by the H family: identify with --model smooth (or auto) and hand that set to '
                'the compensator, which inverts either family (family: smooth)')


MECHANISM = LoopShape()
