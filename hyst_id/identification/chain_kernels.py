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

"""Compiled kernels of the chain after H: backlash, sensor dynamics, calibration, costs.

:class:`~hyst_id.identification.chains.ChainSpec` runs H (its family's own
kernel) and hands H's output here. Every sum runs in sample order, so the
same inputs give the same bits on every CPU make.
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.models.backlash import backlash_step
from hyst_id.models.sensors import first_order_coefficient, second_order_coefficients

__all__ = ['fit_affine', 'sse', 'sum_squares', 'tail_costs', 'tail_feasible_rows',
           'tail_signal']


@njit(cache=True)
def tail_feasible_rows(tail):
    """Per row of ``tail`` (B's and the sensor's parameters): slope > 0, c_bl < c_br, finite."""
    ok = np.empty(tail.shape[0], dtype=np.bool_)
    for i in range(tail.shape[0]):
        good = tail[i, 0] > 0.0 and tail[i, 1] < tail[i, 2]
        for q in range(tail.shape[1]):
            if not np.isfinite(tail[i, q]):
                good = False
        ok[i] = good
    return ok


@njit(cache=True)
def tail_signal(u, tail, kind, dt_s, uniform, falling, hold_after, out):
    """Backlash and sensor dynamics after H's output ``u``, into ``out``.

    B starts on its rising edge, or on its falling one when ``falling``. The
    sensor input of sample ``j`` is B's output at ``j`` (held over the
    interval before it), or at ``j - 1`` when ``hold_after`` (held over the
    interval after it: a sample does not yet see the command of its instant).
    """
    m_bl, c_bl, c_br = tail[0], tail[1], tail[2]
    y = m_bl * (u[0] - (c_bl if falling else c_br))
    out[0] = y
    n = u.shape[0]
    if kind == 0:
        for j in range(1, n):
            y = backlash_step(u[j], y, m_bl, c_bl, c_br)
            out[j] = y
    elif kind == 1:
        tau = tail[3]
        a = first_order_coefficient(dt_s[1], tau)
        x = y
        for j in range(1, n):
            y_prev = y
            y = backlash_step(u[j], y, m_bl, c_bl, c_br)
            if not uniform:
                a = first_order_coefficient(dt_s[j], tau)
            x = a * x + (1.0 - a) * (y_prev if hold_after else y)
            out[j] = x
    else:
        zeta, omega = tail[3], tail[4]
        p11, p12, p21, p22 = second_order_coefficients(dt_s[1], zeta, omega)
        x = y
        xd = 0.0
        for j in range(1, n):
            y_prev = y
            y = backlash_step(u[j], y, m_bl, c_bl, c_br)
            if not uniform:
                p11, p12, p21, p22 = second_order_coefficients(dt_s[j], zeta, omega)
            e = x - (y_prev if hold_after else y)
            x = (y_prev if hold_after else y) + p11 * e + p12 * xd
            xd = p21 * e + p22 * xd
            out[j] = x


@njit(cache=True)
def fit_affine(s, y):
    """Least-squares ``(k, b)`` of ``y ~ k s + b`` and its residual sum of squares.

    Sums in sample order (a fixed order: the same bits on every CPU make).
    """
    n = s.shape[0]
    s_ref = s[0]
    ss = 0.0
    sss = 0.0
    sy = 0.0
    ssy = 0.0
    syy = 0.0
    for j in range(n):
        sj = s[j] - s_ref
        ss += sj
        sss += sj * sj
        sy += y[j]
        ssy += sj * y[j]
        syy += y[j] * y[j]
    var_s = sss - ss * ss / n
    cov = ssy - ss * sy / n
    var_y = syy - sy * sy / n
    if var_s <= 1e-300 * max(1.0, sss):
        return 0.0, sy / n, max(var_y, 0.0)
    k = cov / var_s
    b = (sy - k * ss) / n - k * s_ref
    return k, b, max(var_y - k * cov, 0.0)


@njit(cache=True)
def sse(s, y, k, b):
    """Sum of squares of ``y - (k s + b)`` in sample order."""
    acc = 0.0
    for j in range(s.shape[0]):
        r = y[j] - (k * s[j] + b)
        acc += r * r
    return acc


@njit(cache=True)
def tail_costs(u, tail, ok, kind, y, dt_s, uniform, falling, hold_after, profile, k_fixed,
               b_fixed, costs):
    """Cost J (Eq. 6) of every row whose H output is ``u[i]``; infeasible rows cost inf."""
    s = np.empty(y.shape[0])
    for i in range(u.shape[0]):
        if not ok[i]:
            costs[i] = np.inf
            continue
        tail_signal(u[i], tail[i], kind, dt_s, uniform, falling, hold_after, s)
        if profile:
            k, b, _ = fit_affine(s, y)
            costs[i] = sse(s, y, k, b)   # second pass: no cancellation
        else:
            costs[i] = sse(s, y, k_fixed, b_fixed)


@njit(cache=True)
def sum_squares(y):
    """Sum of ``y**2`` in sample order."""
    acc = 0.0
    for j in range(y.shape[0]):
        acc += y[j] * y[j]
    return acc
