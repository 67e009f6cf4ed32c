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

"""``creep``: part of the response arrives slowly after the fast part (relaxation).

Placement: on the actuator's travel, ``x_creep = (1 - c) x + c L_tau(x)``
with ``L_tau`` a first-order lag of time constant ``tau``: a piezo stack's
or an elastomer seal's travel keeps moving for seconds after the command
has stopped, a spring-loaded diaphragm settles. Both the sensor dynamics
and the calibration are linear, so the block is evaluated on the sensor's
output: ``y = k1 s + k2 L_tau(s) + b``, with ``k1 = k (1 - c)`` and
``k2 = k c`` linear parameters. The block adds one searched parameter
(``tau``) and one linear one.

It differs from :mod:`.sensor_lag` (all of the response lagged, usually
faster than a loop period) in that only a share of the travel is slow and
its time constant is of the order of loop periods or longer; and from the
time gains (:mod:`.supply_decay`, :mod:`.gain_drift`) in that it depends on
the command's history, not on the clock: a hold after a move is followed by
a relaxation, however late in the run.

Signature: after every reversal the residual relaxes with the same slow
time constant (the early/late ratio of the since-reversal regimes) and the
residual correlates with the low-passed command rate.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity, rate_correlation
from hyst_id.models.sensors import simulate_first_order

__all__ = ['Creep', 'MECHANISM']


class Creep(Mechanism):
    """A slow first-order share of the actuator's travel."""

    id = 'creep'  # noqa: A003
    title = 'creep: part of the travel follows slowly'
    stage = 'output'
    compensation = 'not in-line'
    placement = ('on the actuator travel after H and B (evaluated after the linear sensor, '
                 'where it is the same): a slow share c with time constant tau')
    physics = ('part of the travel keeps moving for seconds after the command stops: creep '
               'of a piezo stack or of an elastomer seal, a settling diaphragm or spring')
    names = ('tau_creep_s',)
    units = ('s',)
    n_linear = 1

    def bounds(self, ctx: Context) -> np.ndarray:
        """From a fifth of a loop period to a quarter of the training duration.

        A slower "creep" cannot be told from a trend over the record: with the
        bound at twice the training duration it took three of nine supply
        decays from ``supply_decay`` in ``bench/diagnosis_sweep.py``.
        """
        lo = max(2.0 * ctx.dt_s, 0.2 * ctx.period_s)
        hi = max(lo * 2.0, 0.25 * ctx.train_duration_s)
        return np.array([[lo, hi]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Log-spaced from half a loop period to the upper bound."""
        lo, hi = self.bounds(ctx)[0]
        return [np.array([x]) for x in np.geomspace(max(lo, 0.5 * ctx.period_s), hi, 4)]

    def null(self, ctx: Context) -> np.ndarray:
        """The slowest lag (its share then acts almost as an offset)."""
        return self.bounds(ctx)[:, 1].copy()

    def output(self, theta, t_s, columns, ctx) -> list[np.ndarray]:
        """The lagged sensor column as one more regressor."""
        slow = simulate_first_order(columns[0], t_s, float(theta[0]))
        return columns[:-1] + [slow, columns[-1]]

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """A slow share above the whole travel is a lag of the whole response, not creep.

        With ``c > 1`` the fast part ``k (1 - c)`` moves against the command
        and the slow part overshoots it: a travel that first goes the wrong
        way. On the blind family's #128 (second-order actuator dynamics and a
        sensor lag, no creep) the block took round 1 with a 133 % share and
        the sensor lag's time constant (bench/blind_family.py). Relaxing back by
        more than the whole travel (``c < -1``) is refused too: a new user's
        rate-independent Bouc-Wen record was given ``creep`` relaxing back by
        110 % of the travel in 16.5 s (found by an independent review).
        """
        share = _share(coef, labels)
        if share > 1.0:
            return (f'slow share {100.0 * share:.0f} % is more than the whole travel: the fast '
                    'part would move against the command; a lag of the whole response, not creep')
        if share < -1.0:
            return (f'slow share {100.0 * share:.0f} %: the travel would first overshoot to '
                    f'{100.0 * (1.0 - share):.0f} % of its final value and relax back by more '
                    'than the whole travel; not creep')
        return ''

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Time constant and the slow share of the travel."""
        share = _share(info['coef'], info['labels'])
        return {'tau_creep_s': Quantity(float(theta[0]), 's', 'time constant of the slow part'),
                'creep_share_percent': Quantity(100.0 * share, '%',
                                                'share of the final travel that arrives '
                                                'slowly (negative: relaxes back)')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        share = values['creep_share_percent'].value
        tau = values['tau_creep_s'].value
        way = 'keeps moving on' if share >= 0 else 'relaxes back'
        return (f'Creep: after each move {abs(share):.1f} % of the travel {way} with a time '
                f'constant of {tau:.3g} s, so the reading depends on how long ago the command '
                'changed, not only on its path: piezo or seal creep, a settling diaphragm. '
                'Hold tests (step and wait several time constants) show it directly; a '
                'controller needs integral action or a creep model to remove it.')

    def evidence(self, loc) -> tuple[float, dict]:
        """A slow relaxation after reversals: a residual correlated with the command rate."""
        f = loc.features
        score = 0.5 * float(loc.ccf_rate['significant'])
        score += 0.5 * float(np.clip(f['low_fraction'], 0.0, 1.0))
        return score, rate_correlation(loc)

    def compensation_note(self, values, ctx) -> str:
        """H^-1 does not invert a history-dependent slow part."""
        return ('not compensated in-line: H⁻¹ inverts the rate-independent loop, and the slow '
                f'{values["creep_share_percent"].value:.1f} % share follows the command '
                'history; feedback with integral action or a creep operator removes it')


def _share(coef, labels) -> float:
    """The slow share ``k_slow / (k_fast + k_slow)`` (NaN when the labels are not known)."""
    if labels is None or 'creep:0' not in labels or 'sensor' not in labels:
        return float('nan')
    k_fast = float(coef[list(labels).index('sensor')])
    k_slow = float(coef[list(labels).index('creep:0')])
    total = k_fast + k_slow
    return k_slow / total if abs(total) > 1e-300 else float('nan')


MECHANISM = Creep()
