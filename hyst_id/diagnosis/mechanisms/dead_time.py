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

"""``dead_time``: transport delay between the command and the actuator.

Placement: on the command, before H. The actuator acts on the command it
received ``delay_s`` ago (D/A conversion, a field bus, the positioner's scan,
a pneumatic signal line). The delayed command is interpolated linearly
between samples, so the fit is smooth in the delay and fractions of a
sample are resolved.

Signature in the residual: correlated with the command *rate* (to first
order a delay is ``-delay * dv/dt`` on the input), concentrated just after
reversals, where the model turns round before the actuator does.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity, rate_correlation

__all__ = ['DeadTime', 'MECHANISM', 'MIN_DELAY_SAMPLES']

#: Fewest sample intervals a delay must span to be claimed as a transport delay.
MIN_DELAY_SAMPLES = 0.8


class DeadTime(Mechanism):
    """Pure delay of the command."""

    id = 'dead_time'  # noqa: A003
    title = 'transport delay between the command and the actuator'
    stage = 'command'
    compensation = 'in-line'
    placement = 'command -> actuator, before the hysteresis H'
    physics = ('the actuator acts on the command it received some time ago (D/A, field bus, '
               'positioner scan, pneumatic signal line)')
    names = ('delay_s',)
    units = ('s',)

    def bounds(self, ctx: Context) -> np.ndarray:
        """Delay from 0 to a quarter loop period (at most a tenth of the training time)."""
        hi = min(0.25 * ctx.period_s, 0.1 * ctx.train_duration_s)
        return np.array([[0.0, max(2 * ctx.dt_s, hi)]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Delays of 0.5 to 16 samples."""
        hi = self.bounds(ctx)[0, 1]
        return [np.array([k * ctx.dt_s]) for k in (0.5, 1.0, 2.0, 4.0, 8.0, 16.0)
                if k * ctx.dt_s < hi]

    def null(self, ctx: Context) -> np.ndarray:
        """No delay."""
        return np.zeros(1)

    def command(self, theta: np.ndarray, t_s: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Command seen by the actuator: ``v(t - delay)``, held at ``v(0)`` before the start."""
        d = float(theta[0])
        if d <= 0.0:
            return v
        return np.interp(t_s - d, t_s, v)

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """A delay under :data:`MIN_DELAY_SAMPLES` of a sample interval is not resolved.

        Interpolated between samples, such a delay averages each command with the
        one before: a smoothing that soaks up misfit (a sum of plays behind a curved
        map under a chirp fitted 0.5 samples; a new user's review), not a delay the
        record shows. True one-sample delays of the reference chain fit 0.99-1.06
        intervals, half samples 0.49-0.56 (``python bench/dead_time_samples.py``).
        """
        if ctx is None or not ctx.dt_s > 0.0:
            return ''
        samples = float(theta[0]) / ctx.dt_s
        if samples < MIN_DELAY_SAMPLES:
            return (f'a delay of {samples:.2f} sample intervals: under one interval it '
                    'averages neighbouring commands (a smoothing), not a transport delay '
                    'the record resolves')
        return ''

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Delay in seconds and in samples."""
        d = float(theta[0])
        return {'delay_s': Quantity(d, 's', 'command -> actuator transport delay'),
                'delay_samples': Quantity(d / ctx.dt_s, 'samples',
                                          'the delay in sample periods')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        d = values['delay_s'].value
        return (f'The actuator responds {d:.3g} s ({values["delay_samples"].value:.1f} samples) '
                'after the command: a transport delay between the command and the actuator '
                '(D/A, field bus, positioner scan or signal line) that the chain of the paper '
                'does not have. The hysteresis compensator acts too early by that much: predict '
                f'{d:.3g} s ahead (Smith predictor) or shorten the signal path.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Rate-correlated residual concentrated right after reversals."""
        f = loc.features
        score = 0.5 * float(loc.ccf_rate['significant'])
        score += 0.5 * float(np.clip((f['early_late_ratio'] - 1.0) / 2.0, 0.0, 1.0))
        return score, rate_correlation(loc)

    def compensation_note(self, values, ctx) -> str:
        """Predicted ahead from the desired value's slope."""
        d = values['delay_s'].value
        return (f'in-line (augment.dead_time_s {d:.3g}): the compensator computes each command '
                f'for the desired value {d:.3g} s ahead, extrapolated from its recent slope; '
                'exact for ramps, late at a reversal of the desired value by the delay. A '
                'desired value known ahead (a planned trajectory) or a Smith predictor in the '
                'controller does better')

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """Predict the desired value ahead by the delay."""
        return {'augment.dead_time_s': float(theta[0])}


MECHANISM = DeadTime()
