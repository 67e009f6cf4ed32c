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

"""``offset_drift``: a slow additive drift of the sensor's zero.

Placement: after the calibration, added to the measurement:
``y = k s + b + rate (t - t0)``. Warm-up, temperature or a slowly leaking
reference shift the sensor's zero at a roughly constant rate. The rate is
a linear parameter (profiled), so the block costs no search.

Signature: a residual trend that is the same at every output level, with
its power below the command's fundamental frequency.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Mechanism, Quantity

__all__ = ['OffsetDrift', 'MECHANISM']


class OffsetDrift(Mechanism):
    """Linear ramp added to the measurement."""

    id = 'offset_drift'  # noqa: A003
    title = 'slow additive drift of the sensor offset'
    stage = 'output'
    compensation = 'in-line'
    placement = 'added to the measurement after the calibration'
    physics = ("the sensor's zero moves slowly (warm-up, temperature, reference drift), "
               'independently of the command')
    n_linear = 1

    def output(self, theta, t_s, columns, ctx) -> list[np.ndarray]:
        """Append the ramp ``t - t0`` before the constant column."""
        return columns[:-1] + [t_s - ctx.t_s[0], columns[-1]]

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Drift rate and the drift accumulated over the record."""
        rate = float(info['coef'][info['labels'].index('offset_drift:0')])
        return {'rate_per_s': Quantity(rate, f'{ctx.meas_unit}/s', 'drift rate of the offset'),
                'drift_over_record': Quantity(rate * ctx.duration_s, ctx.meas_unit,
                                              'offset change from start to end')}

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        r = values['rate_per_s']
        total = values['drift_over_record']
        return (f'The zero of the sensor drifts by {r.value:+.3g} {r.unit} '
                f'({total.value:+.3g} {total.unit} over the record), the same at every '
                'command level: warm-up, temperature or reference drift of the sensor, not '
                'the actuator. Re-zero or auto-zero the sensor, let it warm up, or estimate the '
                'offset online; the hysteresis itself is unaffected.')

    def evidence(self, loc) -> tuple[float, dict]:
        """A time trend that does not scale with the level."""
        f = loc.features
        score = float(np.clip((abs(f['trend_t']) - 3.0) / 5.0, 0.0, 1.0))
        score *= float(np.clip(1.0 - (abs(f['level_trend_t']) - 3.0) / 5.0, 0.0, 1.0))
        return score, {'trend': {'slope_per_s': loc.trend['slope_per_s'],
                                 't': loc.trend['t']}}

    def compensation_note(self, values, ctx) -> str:
        """Scheduled in-line from the run's start, and followed online."""
        r = values['rate_per_s']
        return (f'in-line as a ramp (augment.offset_rate_per_s {r.value:+.3g} {r.unit}): the '
                'compensator shifts the desired value by the drift since its start, which '
                "holds for runs that start as this record did and is held beyond the record's "
                'length; otherwise the tracking of the compensator (tracking.enabled) follows '
                'the offset from the measurement; a sensor re-zeroed before the run removes '
                'the cause')

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """The drift rate; the set identified without it holds at the record's mean time."""
        rate = float(info['coef'][info['labels'].index('offset_drift:0')])
        return {'augment.offset_rate_per_s': rate,
                'augment.offset_reference_s': float(np.mean(ctx.t_s - ctx.t_s[0]))}


MECHANISM = OffsetDrift()
