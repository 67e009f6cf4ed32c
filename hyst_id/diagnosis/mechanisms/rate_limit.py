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
"""``rate_limit``: the actuator follows the command no faster than a maximum rate.

Placement: on the command, before H. A positioner or drive that moves at
most ``R`` command units per second (a motor's top speed, the air a
pneumatic actuator's restrictor lets through, a slew limit in the
positioner's firmware) turns a step of the command into a ramp of slope
``R``; slower commands pass unchanged. The block applies that limit sample
by sample (each sample's change clipped to ``R`` times its interval), so it
is the identity wherever the command moves slower than ``R``.

It is searched as the *slowness* ``1 / R`` (seconds per command unit of the
model): 0 is the identity, and the cost changes smoothly with it.

It differs from :mod:`.dead_time` (a shift of every move by the same time),
:mod:`.sensor_lag` (an exponential approach whose time does not depend on the
size of the move) and :mod:`.actuator_dynamics` (overshoot and ringing): a
limited rate makes a large step take longer than a small one, with straight
ramps. Before the block a slew-limited actuator (from a simulator written
apart, ``test/diagnosis/test_rate_limit.py``) was named ``actuator_dynamics``,
``rate_dependence`` or ``supply_decay`` with 7-35 x the noise floor left
(``bench/rate_limit_spread.py --without``).

Signature in the residual: correlated with the command rate, only where the
command moves faster than ``R``.
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity, rate_correlation

__all__ = ['MECHANISM', 'RateLimit', 'slew_limited']

#: The longest traverse of the training command span the search allows, as a share of
#: the training part's duration (a limit slower than that leaves little record to see).
_LONGEST_TRAVERSE = 0.2


@njit(cache=True)
def _slew(t_s: np.ndarray, v: np.ndarray, slowness: float) -> np.ndarray:  # pragma: no cover
    out = np.empty_like(v)
    out[0] = v[0]
    for k in range(1, v.size):
        step = (t_s[k] - t_s[k - 1]) / slowness
        change = v[k] - out[k - 1]
        if change > step:
            change = step
        elif change < -step:
            change = -step
        out[k] = out[k - 1] + change
    return out


def slew_limited(t_s: np.ndarray, v: np.ndarray, slowness_s_per_unit: float) -> np.ndarray:
    """The command ``v`` followed at most at ``1 / slowness_s_per_unit`` units per second.

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times, seconds (increasing).
    v : numpy.ndarray
        The command.
    slowness_s_per_unit : float
        Seconds per command unit at the limit; 0 (or less) is no limit.

    Returns
    -------
    numpy.ndarray
        The limited command, starting at ``v[0]``.
    """
    v = np.ascontiguousarray(v, dtype=float)
    if slowness_s_per_unit <= 0.0 or v.size < 2:
        return v
    return _slew(np.ascontiguousarray(t_s, dtype=float), v, float(slowness_s_per_unit))


def _span(ctx: Context) -> float:
    """The training command's span in model units (the driver's model: 4)."""
    return float(ctx.extra.get('command_span', 4.0)) or 4.0


def _fastest_traverse_s(ctx: Context) -> float:
    """Time to traverse the span at the training command's fastest rate: the identity below."""
    fastest = float(ctx.extra.get('command_rate_max', _span(ctx) / ctx.dt_s))
    return _span(ctx) / max(fastest, 1e-300)


class RateLimit(Mechanism):
    """A maximum rate of the actuator's travel, on the command before H."""

    id = 'rate_limit'  # noqa: A003
    title = 'rate limit: the actuator moves no faster than a maximum rate'
    stage = 'command'
    compensation = 'not in-line'
    placement = 'command -> actuator, before the hysteresis H: each change clipped to R x dt'
    physics = ('the actuator cannot follow the command faster than a maximum rate (a '
               "motor's top speed, a pneumatic actuator's restrictor, a positioner's slew "
               'limit): a step becomes a ramp')
    names = ('slowness_s_per_unit',)
    units = ('s/cmd-model',)

    def bounds(self, ctx: Context) -> np.ndarray:
        """From no limit to a traverse of the span in a fifth of the training time."""
        hi = _LONGEST_TRAVERSE * ctx.train_duration_s / _span(ctx)
        return np.array([[0.0, max(hi, 2.0 * _fastest_traverse_s(ctx) / _span(ctx))]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Traverse times 1.5 to 100 x the fastest command's (those under the bound)."""
        hi = self.bounds(ctx)[0, 1]
        base = _fastest_traverse_s(ctx) / _span(ctx)
        return [np.array([k * base]) for k in (1.5, 3.0, 10.0, 30.0, 100.0) if k * base < hi]

    def null(self, ctx: Context) -> np.ndarray:
        """No limit."""
        return np.zeros(1)

    def command(self, theta: np.ndarray, t_s: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The command as the actuator can follow it."""
        return slew_limited(t_s, v, float(theta[0]))

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """The rate in the command's units per second, and the span's traverse time."""
        slowness = float(theta[0])
        a = abs(ctx.command_scale[0])
        rate = a / slowness if slowness > 0.0 else float('inf')
        return {'max_rate': Quantity(rate, f'{ctx.cmd_unit}/s',
                                     'the fastest the actuator follows the command'),
                'traverse_s': Quantity(slowness * _span(ctx), 's',
                                       "time to cross the training command's range at "
                                       'that rate')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        rate, traverse = values['max_rate'].value, values['traverse_s'].value
        return (f'The actuator follows the command no faster than {rate:.3g} {ctx.cmd_unit}/s '
                f'(the command range of the record in {traverse:.3g} s): faster command '
                'changes become ramps of that slope, a large step taking longer than a small '
                "one. A rate limit: a motor's top speed, the air a pneumatic actuator's "
                "restrictor lets through, or a slew limit in the positioner's settings. "
                'The chain of the paper has none. Keep the desired value slower than this, '
                'or raise the limit if it is a setting.')

    def evidence(self, loc) -> tuple[float, dict]:
        """A residual correlated with the command rate."""
        return 0.5 * float(loc.ccf_rate['significant']), rate_correlation(loc)

    def compensation_note(self, values, ctx) -> str:
        """H^-1 is static: a rate it cannot reach stays."""
        return ('not compensated in-line: no command makes the actuator move faster than '
                f'{values["max_rate"].value:.3g} {ctx.cmd_unit}/s; limit the rate of the '
                'desired value before the compensator (a setpoint ramp) so that the command '
                'H⁻¹ computes is one the actuator can follow')


MECHANISM = RateLimit()
