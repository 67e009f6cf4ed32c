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

"""Gauge freedom of the chain and its canonical form.

``H -> B -> sensor -> (k, b)`` is over-parameterised: the signal between H
and B can be scaled by any ``alpha > 0`` and shifted by any ``delta`` (H's
output lines absorb it, B's slope and crossings undo it), and the same
holds between B and the affine calibration. Different parameter vectors on
one such *gauge orbit* give bit-for-bit the same chain output, so raw
optimiser results are not comparable (or averageable) across seeds.

The canonical form used for every report, average and compensator:

* backlash with unit slope, centred on zero: ``m_bl = 1``,
  ``c_bl = -w``, ``c_br = +w`` (``w`` = half the dead band);
* calibration ``k = sign, b = 0`` with ``sign = +1``: the hysteresis output is
  expressed directly in the measurement's units. A sensor whose reading
  falls as the actuator opens (negative gain, e.g. upstream pressure) gets
  ``sign = -1``: H is then expressed in the *negated* measurement's units,
  because a hysteresis loop with positive slopes cannot fall.

Sensor dynamics have unit DC gain, so they commute with the affine map.
"""

from __future__ import annotations

import numpy as np

from hyst_id.models.family import HysteresisFamily
from hyst_id.models.registry import get_family

__all__ = ['affine_map_output', 'canonical_gauge', 'output_sign']


def affine_map_output(params: np.ndarray, alpha: float, delta: float,
                      family: str | HysteresisFamily | None = None) -> np.ndarray:
    """Re-express the chain with its H/B output replaced by ``alpha * out + delta``.

    Parameters
    ----------
    params : numpy.ndarray
        Chain parameters (H's, backlash 3, then sensor parameters).
    alpha : float
        Positive scale applied after the backlash.
    delta : float
        Offset applied after the scale.
    family : str or HysteresisFamily, optional
        H's family (default ``tk``).

    Returns
    -------
    numpy.ndarray
        Parameters whose chain output equals ``alpha * old_output + delta``.
    """
    if not alpha > 0:
        raise ValueError('alpha must be positive')
    fam = get_family(family)
    nh = fam.n_params
    p = np.array(params, dtype=np.float64)
    m_bl = p[nh]
    # alpha*m_bl*(u - c) + delta = m_bl*(u' - c') with u' = alpha*u + delta/m_bl
    # and c' = alpha*c: the map moves into H's output and B's crossings.
    p[:nh] = fam.map_output(p[:nh], alpha, delta / m_bl)
    p[nh + 1] *= alpha
    p[nh + 2] *= alpha
    return p


def output_sign(calibration: tuple[float, float]) -> float:
    """Sign of the canonical calibration: ``+1.0`` or ``-1.0`` (``+1`` for ``k = 0``)."""
    return -1.0 if calibration[0] < 0 else 1.0


def canonical_gauge(params: np.ndarray, calibration: tuple[float, float] = (1.0, 0.0),
                    family: str | HysteresisFamily | None = None) -> np.ndarray:
    """Return the canonical representative of a parameter vector's gauge orbit.

    Parameters
    ----------
    params : numpy.ndarray
        Chain parameters in search space.
    calibration : tuple of float
        ``(k, b)`` applied after the sensor; ``k`` must be non-zero.
    family : str or HysteresisFamily, optional
        H's family (default ``tk``).

    Returns
    -------
    numpy.ndarray
        Equivalent parameters with ``m_bl = 1``, backlash centred on 0, whose
        chain output ``s`` gives the measurement as ``output_sign * s``
        (calibration ``(output_sign(calibration), 0)``).
    """
    k, b = calibration
    if k == 0 or not np.isfinite(k):
        raise ValueError('calibration gain must be finite and non-zero')
    fam = get_family(family)
    nh = fam.n_params
    sign = output_sign(calibration)
    k, b = sign * k, sign * b       # y = sign * (|k| s + sign b)
    p = np.array(params, dtype=np.float64)
    m_bl, c_bl, c_br = p[nh], p[nh + 1], p[nh + 2]
    # B output y = m_bl (u - c); write it as y = (u' - c') with u' = m_bl u.
    p[:nh] = fam.map_output(p[:nh], m_bl, 0.0)
    p[nh], p[nh + 1], p[nh + 2] = 1.0, m_bl * c_bl, m_bl * c_br
    # Centre the backlash: shift u' and c' by -centre (output unchanged).
    centre = 0.5 * (p[nh + 1] + p[nh + 2])
    p[:nh] = fam.map_output(p[:nh], 1.0, -centre)
    p[nh + 1] -= centre
    p[nh + 2] -= centre
    # Calibration: y_meas = k y + b; fold into H's output (B has unit slope).
    return affine_map_output(p, k, b, fam)
