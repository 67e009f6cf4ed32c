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

"""A gain on the sensed quantity changing over the run (``supply_decay``, ``gain_drift``).

Placement: ``y = g(t) (k s + b0) + b1`` with ``g(t0) = 1``; ``b0`` is a linear
parameter (the offset scaled with the gain), so the block adds one searched
parameter, a rate. A subclass says how the gain changes (:meth:`TimeGain.gain`,
:attr:`TimeGain.gain_law`) and over which range of changes over the training
part its rate is searched (:attr:`TimeGain.rate_range`,
:attr:`TimeGain.start_changes`). In operation the fitted schedule is an
in-line correction of the compensator (:mod:`hyst_id.compensation.augment`,
for runs that start as the record did) and the compensator's tracking or the
identifier's sliding re-identification follow it from the measurement.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity

__all__ = ['AT_SLOWEST', 'TimeGain']

#: A fitted rate within this factor of the slowest one searched is at the bound.
AT_SLOWEST = 1.05


class TimeGain(Mechanism):
    """Base class: a time-varying gain on the sensed quantity (one rate, one linear term)."""

    stage = 'output'
    placement = 'on the sensed quantity (a gain in time), before the sensor offset'
    n_linear = 1
    compensation = 'in-line'
    #: The compensator's name for :meth:`gain` (:data:`hyst_id.compensation.augment.GAIN_LAWS`).
    gain_law = 'none'
    #: Rate bounds as changes over the training duration (per that duration).
    rate_range: tuple[float, float] = (0.01, 5.0)
    #: Starting rates, same unit.
    start_changes: tuple[float, ...] = (0.1, 0.3, 1.0)

    def gain(self, rate: float, elapsed_s: np.ndarray) -> np.ndarray:
        """``g`` at ``elapsed_s`` seconds from the record's start (``g(0) = 1``)."""
        raise NotImplementedError

    def bounds(self, ctx: Context) -> np.ndarray:
        """:attr:`rate_range` per training duration."""
        d = max(ctx.train_duration_s, 1e-9)
        return np.array([[self.rate_range[0] / d, self.rate_range[1] / d]])

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """:attr:`start_changes` per training duration."""
        d = max(ctx.train_duration_s, 1e-9)
        return [np.array([x / d]) for x in self.start_changes]

    def null(self, ctx: Context) -> np.ndarray:
        """Slowest change (the block is then nearly the identity)."""
        return self.bounds(ctx)[:, 0].copy()

    @staticmethod
    def unchanged_reading(info: dict) -> float:
        """The reading the gain leaves unchanged: the constant ``b1`` of the fit."""
        return float(info['coef'][info['labels'].index('offset')])

    def with_pivot(self, values: dict[str, Quantity], info: dict,
                   ctx: Context) -> dict[str, Quantity]:
        """``values`` and the reading the changing gain leaves unchanged (``b1``)."""
        return {**values, 'unchanged_reading': Quantity(
            self.unchanged_reading(info), ctx.meas_unit,
            'the reading the changing gain leaves unchanged (its zero)')}

    def pivot_words(self, values: dict[str, Quantity], grows: bool) -> str:
        """Which way the readings move, from where the gain leaves them unchanged.

        A gain changes every reading in proportion to its distance from that level:
        a growing gain about a zero above the travel lowers the readings, which a
        new user's report had called "a larger reading".
        """
        q = values['unchanged_reading']
        up, down = ('rise', 'fall') if grows else ('fall', 'rise')
        return (f' It acts about the reading {q.value:.4g} {q.unit}, the level the gain leaves '
                f'unchanged: readings above it {up} over the run, readings below it {down}, '
                'each in proportion to its distance from it.')

    def implausible(self, theta, coef, span, noise_std, ctx=None, labels=None) -> str:
        """A rate at the slowest end of its search is not a gain that changes.

        There the fit wanted a still smaller change of a still more distant
        gained offset ``b0``: ``g(t) b0`` is then a ramp added to the
        reading, the same at every level, which is an offset drift.
        """
        if ctx is None:
            return ''
        slowest = float(self.bounds(ctx)[0, 0])
        if float(theta[0]) <= AT_SLOWEST * slowest:
            change = 100.0 * float(theta[0]) * ctx.train_duration_s
            return (f'its rate ({change:.2g} % over the training part) sits at the slowest '
                    'end of its search, where a gain change about a distant zero is an offset '
                    'drift')
        return ''

    def output(self, theta, t_s, columns, ctx) -> list[np.ndarray]:
        """The gain on every signal column, plus the gained offset ``g(t)``."""
        g = self.gain(float(theta[0]), t_s - ctx.t_s[0])
        return [c * g for c in columns[:-1]] + [g, columns[-1]]

    def undo(self, theta, t_s, v, y, terms, ctx) -> tuple[np.ndarray, np.ndarray] | None:
        """The gain divided out about the reading it leaves unchanged (the constant ``b1``)."""
        g = self.gain(float(theta[0]), t_s - ctx.t_s[0])
        if not np.all(g > 1e-3):
            return None     # a gain through zero cannot be divided out
        b1 = float(terms['offset'][0])
        return v, (y - b1) / g + b1

    def undo_terms(self, theta, t_s, terms, ctx) -> dict[str, np.ndarray]:
        """The other blocks' fitted terms with the gain divided out of them too.

        So that a block undone after this one (an additive term of the
        quantity, as friction's) takes out what is left of it in the gain-free
        record. The constant ``b1`` is not gained and stays.
        """
        g = self.gain(float(theta[0]), t_s - ctx.t_s[0])
        return {k: c if k == 'offset' else c / g for k, c in terms.items()}

    def evidence(self, loc) -> tuple[float, dict]:
        """A time trend whose size scales with the output level."""
        f = loc.features
        score = float(np.clip((abs(f['level_trend_t']) - 3.0) / 5.0, 0.0, 1.0))
        return score, {'trend': {'slope_per_s': loc.trend['slope_per_s'],
                                 'level_t': loc.trend['level_t']}}

    def compensation_note(self, values, ctx) -> str:
        """Scheduled in-line from the run's start, and followed online."""
        return ('in-line as a schedule (augment.gain_*): the compensator scales the desired '
                'value by the fitted gain at the time since its start, which holds for runs '
                'that start as this record did and is held at its end value beyond the '
                "record's length; for runs that do not, the tracking of the compensator "
                '(tracking.enabled) follows the gain from the measurement, and the sliding '
                're-identification of the identifier (sliding.enabled) swaps in a refitted '
                'set once the change is clear on the newest samples')

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """The gain law and rate, the reading it leaves unchanged, the record's mean gain.

        ``y = g(t) (k s + b0) + b1``: the gain leaves ``b1`` unchanged. A set
        identified on the whole record without the block holds on about the
        record's mean gain, which becomes the schedule's reference.
        """
        rate = float(theta[0])
        centre = self.unchanged_reading(info)
        mean_gain = float(np.mean(self.gain(rate, ctx.t_s - ctx.t_s[0])))
        return {'augment.gain_law': self.gain_law, 'augment.gain_rate_per_s': rate,
                'augment.gain_centre': centre, 'augment.gain_reference': mean_gain}
