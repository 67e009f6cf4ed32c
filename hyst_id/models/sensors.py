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

"""Sensor dynamics (paper Eq. 8-9), discretised exactly from the sample times.

Discretisation: zero-order hold, exact for any sample interval. The input
sample ``u(j)`` is taken as held over ``(t(j-1), t(j)]`` (it changed right
after the previous sample), so a zero time constant reproduces the input
without delay. Sample intervals come from the recording's own timestamps,
so non-uniform sampling is handled exactly.

* first order ``1/(tau s + 1)``: ``x(j) = a x(j-1) + (1 - a) u(j)``,
  ``a = exp(-dt/tau)`` (``a = 0`` for ``tau = 0``);
* second order ``w^2/(s^2 + 2 zeta w s + w^2)``: the error ``e = x - u``
  obeys ``e'' + 2 zeta w e' + w^2 e = 0`` during a held sample, whose exact
  transition matrix :func:`second_order_coefficients` gives for under-,
  critically and over-damped cases alike.

Both start in steady state at the first input sample.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from hyst_id.errors import RecordingError

__all__ = [
    'first_order_coefficient',
    'intervals_and_uniform',
    'sample_intervals',
    'second_order_coefficients',
    'simulate_first_order',
    'simulate_second_order',
]


@njit(cache=True, inline='always')
def first_order_coefficient(dt_s, tau_s):
    """Pole ``a = exp(-dt/tau)`` of the discretised first-order lag."""
    if tau_s <= 0.0:
        return 0.0
    return math.exp(-dt_s / tau_s)


@njit(cache=True, inline='always')
def second_order_coefficients(dt_s, zeta, omega_n):
    """Exact transition ``(p11, p12, p21, p22)`` of the error state over ``dt_s``."""
    sigma = zeta * omega_n
    q = omega_n * omega_n * (1.0 - zeta * zeta)
    if q > 1e-300:
        wd = math.sqrt(q)
        c = math.cos(wd * dt_s)
        s = math.sin(wd * dt_s) / wd
    elif q < -1e-300:
        a = math.sqrt(-q)
        c = math.cosh(a * dt_s)
        s = math.sinh(a * dt_s) / a
    else:
        c = 1.0
        s = dt_s
    e = math.exp(-sigma * dt_s)
    return e * (c + sigma * s), e * s, -e * omega_n * omega_n * s, e * (c - sigma * s)


@njit(cache=True)
def _first_order(u, dt_s, tau_s):
    x = np.empty(u.shape[0])
    x[0] = u[0]
    for j in range(1, u.shape[0]):
        a = first_order_coefficient(dt_s[j], tau_s)
        x[j] = a * x[j - 1] + (1.0 - a) * u[j]
    return x


@njit(cache=True)
def _second_order(u, dt_s, zeta, omega_n):
    x = np.empty(u.shape[0])
    x[0] = u[0]
    xd = 0.0
    for j in range(1, u.shape[0]):
        p11, p12, p21, p22 = second_order_coefficients(dt_s[j], zeta, omega_n)
        e = x[j - 1] - u[j]
        x[j] = u[j] + p11 * e + p12 * xd
        xd = p21 * e + p22 * xd
    return x


@njit(cache=True)
def _interval_kernel(t):
    n = t.shape[0]
    if n < 2:
        return np.empty(0)
    dt = np.empty(n)
    for j in range(1, n):
        dt[j] = t[j] - t[j - 1]
    dt[0] = dt[1]
    return dt


def sample_intervals(t_s: np.ndarray) -> np.ndarray:
    """Interval before each sample, s (the first sample gets the first interval).

    ``t[j] - t[j-1]`` exactly as :func:`numpy.diff` (one compiled pass: the
    fits ask for it at every evaluation); empty for fewer than two samples.
    """
    return _interval_kernel(np.ascontiguousarray(t_s, dtype=np.float64))


@njit(cache=True)
def _all_equal(dt):
    for j in range(dt.shape[0]):
        if not abs(dt[j] - dt[0]) <= 1e-9 * abs(dt[0]):
            return False
    return True


def intervals_and_uniform(t_s: np.ndarray) -> tuple[np.ndarray, bool]:
    """:func:`sample_intervals` and whether they are all equal (within 1e-9 relative).

    Raises
    ------
    RecordingError
        Fewer than two samples.
    """
    dt = sample_intervals(t_s)
    if dt.shape[0] == 0:
        raise RecordingError('a chain needs at least two samples')
    return dt, bool(_all_equal(dt))


def simulate_first_order(u: np.ndarray, t_s: np.ndarray, tau_s: float) -> np.ndarray:
    """Response of ``1/(tau s + 1)`` to ``u`` sampled at ``t_s`` (seconds)."""
    return _first_order(np.ascontiguousarray(u, dtype=np.float64), sample_intervals(t_s),
                        float(tau_s))


def simulate_second_order(u: np.ndarray, t_s: np.ndarray, zeta: float,
                          omega_n_rad_s: float) -> np.ndarray:
    """Response of ``w^2/(s^2 + 2 zeta w s + w^2)`` to ``u`` sampled at ``t_s``."""
    return _second_order(np.ascontiguousarray(u, dtype=np.float64), sample_intervals(t_s),
                         float(zeta), float(omega_n_rad_s))
