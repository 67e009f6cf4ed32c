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

"""``saturation``: travel end stops that clip the actuator position.

Placement: on the actuator position, after B (and after stiction), before
the sensed quantity: ``x -> min(max(x, x_lo), x_hi)``. A mechanical stop,
a positioner's travel limit or a valve seat. The stops are searched as the
fractions of the (unclipped) training travel they cut off at the bottom and
at the top, which makes them independent of the chain's gauge; either can be
0 (no stop on that side).

Signature: residual concentrated at the extreme command levels, where the
measurement stays flat while the model keeps moving.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity

__all__ = ['Saturation', 'MECHANISM']


class Saturation(Mechanism):
    """Clip of the actuator position at two stops."""

    id = 'saturation'  # noqa: A003
    title = 'travel end stop'
    stage = 'position'
    compensation = 'limits'
    placement = 'on the actuator position, after the backlash B, before the sensor'
    physics = 'the actuator hits a mechanical stop or travel limit and cannot follow the command'
    names = ('cut_low_fraction', 'cut_high_fraction')
    units = ('1', '1')

    def bounds(self, ctx: Context) -> np.ndarray:
        """Each stop may cut up to 45 % of the training travel."""
        return np.array([[0.0, 0.45], [0.0, 0.45]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """One-sided and two-sided stops cutting 5 to 25 % of the travel."""
        return [np.array(s) for s in ((0.05, 0.05), (0.15, 0.0), (0.0, 0.15), (0.15, 0.15),
                                      (0.3, 0.0), (0.0, 0.3), (0.3, 0.3))]

    def null(self, ctx: Context) -> np.ndarray:
        """No stop."""
        return np.zeros(2)

    def position(self, theta, x, span) -> np.ndarray:
        """Clip the position at the stops."""
        lo, hi = span
        w = hi - lo
        return np.clip(x, lo + float(theta[0]) * w, hi - float(theta[1]) * w)

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Stops in measurement units and the command levels beyond which nothing moves."""
        lo, hi = info['span']
        w = hi - lo
        out = {}
        raw, cmd = info['travel_raw'], info['command']
        to_meas = info['to_meas']
        for side, frac in (('low', float(theta[0])), ('high', float(theta[1]))):
            out[f'cut_{side}_percent'] = Quantity(100.0 * frac, '%',
                                                  f'share of the travel cut by the {side} stop')
            if frac < 0.005:
                continue
            x_stop = lo + frac * w if side == 'low' else hi - frac * w
            out[f'stop_{side}'] = Quantity(float(to_meas(np.array([x_stop]))[0]),
                                           ctx.meas_unit, f'{side} stop, as measured')
            beyond = raw < x_stop if side == 'low' else raw > x_stop
            if beyond.any():
                level = float(np.max(cmd[beyond]) if side == 'low' else np.min(cmd[beyond]))
                out[f'command_at_{side}_stop'] = Quantity(
                    level, ctx.cmd_unit, f'command {"below" if side == "low" else "above"} '
                    'which the actuator rests on the stop')
        return out

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        parts = []
        for side, word in (('high', 'above'), ('low', 'below')):
            if f'stop_{side}' in values:
                s = values[f'stop_{side}']
                c = values.get(f'command_at_{side}_stop')
                cmd = f' (command {word} {c.value:.3g} {c.unit})' if c else ''
                parts.append(f'at {s.value:.4g} {s.unit}{cmd}')
        where_words = ' and '.join(parts) if parts else 'at the ends of the travel'
        return (f'The actuator hits a travel end stop {where_words}: the measurement stays flat '
                'while the command keeps moving, which no hysteresis loop reproduces. Keep the '
                'command inside the usable travel (limit the setpoint, anti-windup on any '
                'integrator) or move the stop.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Residual at the extreme levels with a flat measurement there."""
        f = loc.features
        score = 0.6 * float(np.clip((f['extreme_ratio'] - 1.0) / 2.0, 0.0, 1.0))
        score += 0.4 * float(np.clip(f['clip_fraction'] / 0.1, 0.0, 1.0))
        lv = loc.regimes.get('level', [])
        return score, {'command_levels': [b['label'] for b in (lv[:1] + lv[-1:])
                                          if b['flagged']]}

    def compensation_note(self, values, ctx) -> str:
        """The stops bound what any command can reach: set the command limits there."""
        cmds = [f'{side} {values[f"command_at_{side}_stop"].value:.4g} {ctx.cmd_unit}'
                for side in ('low', 'high') if f'command_at_{side}_stop' in values]
        where = (': set min_command/max_command of the compensator at the commands where the '
                 'actuator meets its stops (' + ', '.join(cmds) + ')') if cmds else ''
        return ('by the command limits: a desired value beyond the stops cannot be reached, '
                'and commands beyond them only wind the loop up' + where)

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """Command limits where the actuator meets its stops (in the command's units)."""
        values = self.describe(theta, coef, info, ctx)
        out: dict[str, float | str] = {}
        for side, key in (('low', 'augment.min_command'), ('high', 'augment.max_command')):
            q = values.get(f'command_at_{side}_stop')
            if q is not None:
                out[key] = float(q.value)
        return out if out.get('augment.min_command', -np.inf) < out.get(
            'augment.max_command', np.inf) else {}


MECHANISM = Saturation()
