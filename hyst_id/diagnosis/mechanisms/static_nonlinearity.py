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

"""``static_nonlinearity``: a nonlinear map from actuator position to the sensed quantity.

Placement: between the actuator position and the sensor dynamics:
``q = f(x)``, with ``f(z) = z + a2 z^2 + a3 z^3`` on the position normalised to
``z in [-1, 1]`` over the training travel (the scale and offset are the
calibration's). A valve characteristic (equal-percentage or quick-opening
trim), the flow/pressure map of the pneumatics, or a nonlinear transducer.
The sensor dynamics being linear, the three terms pass through them
separately, so ``a2, a3`` are *linear* parameters: the block needs no
search.

Signature: the residual's mean depends on the command level the same way
in both directions and does not change over time.
"""

from __future__ import annotations

import numpy as np

from hyst_id.compensation.augment import cubic_is_monotone, POLY_RANGE
from hyst_id.diagnosis.mechanisms.base import Mechanism, Quantity

__all__ = ['StaticNonlinearity', 'MECHANISM', 'curve_change']


def curve_change(linear: float, cubic: float) -> float:
    """The curve's change from the bottom (``z = -1``) to the top (``z = 1``) of the travel.

    ``linear`` and ``cubic`` are the coefficients of ``z`` and ``z^3`` in the
    basis ``z, z^2, z^3`` of :meth:`StaticNonlinearity.quantity` (``z^2``
    is the same at both ends).
    """
    return 2.0 * (linear + cubic)


class StaticNonlinearity(Mechanism):
    """Cubic map from position to the sensed quantity."""

    id = 'static_nonlinearity'  # noqa: A003
    title = 'nonlinear map from position to the sensed quantity'
    stage = 'quantity'
    compensation = 'in-line'
    placement = 'between the actuator position and the sensor dynamics'
    physics = ('the sensed quantity is not proportional to the actuator position (valve '
               'characteristic, pneumatic pressure/flow map, nonlinear transducer)')
    n_linear = 2
    maps_travel = True

    def quantity(self, theta, x, span) -> list[np.ndarray]:
        """Basis ``z, z^2, z^3`` of the normalised position."""
        lo, hi = span
        z = 2.0 * (x - lo) / (hi - lo) - 1.0
        return [z, z * z, z * z * z]

    def describe(self, theta, coef, info, ctx) -> dict[str, Quantity]:
        """Shape of the map: slope ratio, largest deviation from a straight line."""
        labels = info['labels']
        c1 = float(info['coef'][labels.index('sensor')])
        c2 = float(info['coef'][labels.index('quantity:1')])
        c3 = float(info['coef'][labels.index('quantity:2')])
        z = np.linspace(-1.0, 1.0, 201)
        dev = c2 * (z * z - 1.0) + c3 * (z ** 3 - z)
        k = int(np.argmax(np.abs(dev)))
        slope = c1 + 2 * c2 * z + 3 * c3 * z * z
        top, bottom = c1 + 2 * c2 + 3 * c3, c1 - 2 * c2 + 3 * c3
        span_meas = curve_change(c1, c3)
        out = {'a2': Quantity(c2 / c1 if c1 else np.nan, '1', 'quadratic term per linear term'),
               'a3': Quantity(c3 / c1 if c1 else np.nan, '1', 'cubic term per linear term'),
               'gain_ratio_top_bottom': Quantity(top / bottom if bottom else np.inf, '1',
                                                 'sensitivity at the top of the travel over '
                                                 'that at the bottom'),
               'max_deviation': Quantity(float(dev[k]), ctx.meas_unit,
                                         'largest departure from a straight line over the '
                                         'travel'),
               'max_deviation_percent': Quantity(100.0 * abs(dev[k]) / abs(span_meas)
                                                 if span_meas else np.nan, '%',
                                                 'the same, as a share of the measured span'),
               'monotone': Quantity(float(np.all(slope > 0) or np.all(slope < 0)), 'bool',
                                    '1 if the fitted map is monotone over the travel')}
        return out

    def explain(self, values, where, ctx) -> str:
        """Words for a control engineer."""
        r = values['gain_ratio_top_bottom'].value
        dev = values['max_deviation']
        shape = ('rises faster towards the top of the travel' if abs(r) > 1 else
                 'flattens towards the top of the travel')
        return (f'The measured {ctx.quantity} is not proportional to the actuator position: '
                f'its sensitivity {shape} (top/bottom ratio {r:.2f}; up to {abs(dev.value):.3g} '
                f'{dev.unit} = {values["max_deviation_percent"].value:.1f} % of the span away '
                'from a straight line). A nonlinear valve characteristic (e.g. '
                'equal-percentage trim) or the own pressure/flow map of the pneumatics. Linearise '
                'with the inverse characteristic before the hysteresis compensator, or '
                'schedule the loop gain on the opening.')

    def evidence(self, loc) -> tuple[float, dict]:
        """Mean residual depending on the command level, steady in time."""
        f = loc.features
        score = float(np.clip((f['level_mean_t'] - 3.0) / 5.0, 0.0, 1.0))
        score *= float(np.clip(1.0 - (abs(f['trend_t']) - 3.0) / 5.0, 0.2, 1.0))
        lv = loc.regimes.get('level', [])
        return score, {'command_levels': [{'level': b['label'], 'mean': b['mean']}
                                          for b in lv if b['flagged']]}

    def compensation_note(self, values, ctx) -> str:
        """Inverted in-line with the diagnosis's own set."""
        return ("in-line with the diagnosis's own set (hyst-id diagnose --params-out, "
                'augment.poly_c0..c3): the compensator maps the desired value back through '
                'the inverse of the fitted curve (monotone over the travel, or refused) before '
                'B and H; with a set from hyst-id identify it is not applied (the curve is '
                "written in the diagnosis's travel units)")

    def correction(self, theta, coef, info, ctx) -> dict[str, float | str]:
        """The curve as a cubic of the travel normalised to [-1, 1] (``z``), at the start.

        ``y = c0 + c1 z + c2 z^2 + c3 z^3``: ``c1..c3`` are the fitted basis
        coefficients and ``c0`` the reading at ``z = 0`` (the calibration's
        offset at the record's start). An empty dict when the curve is not
        monotone over the travel (no inverse).
        """
        labels, c = info['labels'], info['coef']
        lo, hi = info['span']
        c0 = float(info['to_meas'](np.array([0.5 * (lo + hi)]))[0])
        out = {'augment.poly_c0': c0, 'augment.poly_c1': float(c[labels.index('sensor')]),
               'augment.poly_c2': float(c[labels.index('quantity:1')]),
               'augment.poly_c3': float(c[labels.index('quantity:2')])}
        poly = tuple(out[f'augment.poly_c{i}'] for i in range(4))
        return out if cubic_is_monotone(poly, POLY_RANGE) else {}


MECHANISM = StaticNonlinearity()
