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

"""Backlash B (paper Eq. 10) and its inverse.

Parameters ``(m_bl, c_bl, c_br)``: slope and left/right crossings::

    y(j) = min(max(y(j-1), m_bl (u - c_br)), m_bl (u - c_bl)),  c_bl < c_br, m_bl > 0

The paper calls the slope ``m_b``; here it is ``m_bl`` so that it does not
collide with the hysteresis bottom slope. Initial state: on the rising edge,
``y(0) = m_bl (u(0) - c_br)``.
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.errors import InvalidParametersError

__all__ = [
    'BACKLASH_NAMES',
    'backlash_step',
    'backlash_inverse_step',
    'check_backlash',
    'simulate_backlash',
    'invert_backlash',
]

BACKLASH_NAMES = ('m_bl', 'c_bl', 'c_br')


@njit(cache=True, inline='always')
def backlash_step(u, y_prev, m_bl, c_bl, c_br):
    """Advance B by one sample."""
    return min(max(y_prev, m_bl * (u - c_br)), m_bl * (u - c_bl))


@njit(cache=True, inline='always')
def backlash_inverse_step(y_d, y_prev, u_prev, m_bl, c_bl, c_br):
    """Input that moves B's output to ``y_d`` (hold the input when equal)."""
    if y_d > y_prev:
        return y_d / m_bl + c_br
    if y_d < y_prev:
        return y_d / m_bl + c_bl
    return u_prev


def check_backlash(params: np.ndarray) -> np.ndarray:
    """Return ``(m_bl, c_bl, c_br)`` as float64 or raise InvalidParametersError."""
    p = np.asarray(params, dtype=np.float64).ravel()
    if p.shape[0] != 3 or not np.all(np.isfinite(p)):
        raise InvalidParametersError(f'backlash needs 3 finite parameters {BACKLASH_NAMES}')
    if not p[0] > 0:
        raise InvalidParametersError('backlash parameters violate m_bl > 0')
    if not p[1] < p[2]:
        raise InvalidParametersError('backlash parameters violate c_bl < c_br')
    return p


@njit(cache=True)
def _simulate(p, u):
    y = np.empty(u.shape[0])
    y[0] = p[0] * (u[0] - p[2])
    for j in range(1, u.shape[0]):
        y[j] = backlash_step(u[j], y[j - 1], p[0], p[1], p[2])
    return y


def simulate_backlash(params: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Output of B for an input sequence, starting on the rising edge."""
    return _simulate(check_backlash(params), np.ascontiguousarray(u, dtype=np.float64))


def invert_backlash(params: np.ndarray, desired: np.ndarray, u0: float,
                    y0: float | None = None) -> np.ndarray:
    """Inputs that make B follow ``desired`` from state ``(u0, y0)``."""
    p = check_backlash(params)
    y_prev = p[0] * (u0 - p[2]) if y0 is None else float(y0)
    u_prev = float(u0)
    out = np.empty(len(desired))
    for j, y_d in enumerate(np.asarray(desired, dtype=np.float64)):
        u_prev = backlash_inverse_step(y_d, y_prev, u_prev, p[0], p[1], p[2])
        y_prev = backlash_step(u_prev, y_prev, p[0], p[1], p[2])
        out[j] = u_prev
    return out
