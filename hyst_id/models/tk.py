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

"""Hysteresis H (Krasnosel'skii hysteron, Tao & Kokotovic form) and its inverse.

Parameters are ordered ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``: slopes
and crossings of the left, right, top and bottom lines of the loop::

    left   u = m_l (v - c_l)        right  u = m_r (v - c_r)
    top    u = m_t v + c_t          bottom u = m_b v + c_b

One step rule holds the whole of the paper's Eq. 1 (see
``docs/model.md`` and the model notes)::

    rising  v > v_prev:  u = min(max(m_b v + c_u, m_r (v - c_r)), m_t v + c_t)
    falling v < v_prev:  u = max(min(m_t v + c_d, m_l (v - c_l)), m_b v + c_b)
    equal:               u = u_prev

with ``c_u = u_prev - m_b v_prev`` and ``c_d = u_prev - m_t v_prev``.

Initial state (the paper leaves it open): the output starts on the
*rising* boundary of the major loop at ``v(0)``, as if the actuator had
just been driven up to its starting command (:func:`initial_output`).
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.errors import InvalidParametersError

__all__ = [
    'HYSTERESIS_NAMES',
    'check_hysteresis',
    'hysteresis_feasible',
    'loop_corners',
    'loop_is_proper',
    'initial_output',
    'hysteresis_step',
    'hysteresis_inverse_step',
    'simulate_hysteresis',
    'invert_hysteresis',
]

HYSTERESIS_NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')


@njit(cache=True, inline='always')
def loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Return True when the parameters describe a proper loop (gauge invariant).

    Slopes ``min(m_l, m_r) > m_t, m_b > 0``, ``c_t > c_b``, and the four
    corners form a proper quadrilateral (see :func:`loop_corners`): the left
    line meets the bottom and the top lines before the right line does, and
    meets the bottom before the top. These conditions survive any positive
    rescaling and shift of the output (the gauge of ``docs/model.md``); the
    paper's ``c_l < c_r`` does not (it compares where the lines extrapolate
    to zero output) and is therefore only a search-space constraint
    (:func:`hysteresis_feasible`).
    """
    m_min = min(m_l, m_r)
    if not (m_l > 0.0 and m_r > 0.0 and 0.0 < m_t < m_min and 0.0 < m_b < m_min
            and c_t > c_b):
        return False
    v_a = (c_b + m_l * c_l) / (m_l - m_b)
    v_b = (c_b + m_r * c_r) / (m_r - m_b)
    v_c = (c_t + m_r * c_r) / (m_r - m_t)
    v_d = (c_t + m_l * c_l) / (m_l - m_t)
    return v_a < v_b and v_d < v_c and v_a < v_d and v_b < v_c


@njit(cache=True, inline='always')
def hysteresis_feasible(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Return True for the paper's constraints (incl. ``c_l < c_r``) on a proper loop.

    This is the search-space constraint of GAASS's rejecting strategy. The
    paper's constraints alone admit loops whose left and right lines cross
    inside the band, on which H jumps and H^-1 fails, hence
    :func:`loop_is_proper` as well.
    """
    return c_l < c_r and loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)


@njit(cache=True, inline='always')
def initial_output(v0, m_r, m_t, m_b, c_r, c_t, c_b):
    """Output on the rising boundary of the major loop at command ``v0``."""
    return min(max(m_b * v0 + c_b, m_r * (v0 - c_r)), m_t * v0 + c_t)


@njit(cache=True, inline='always')
def hysteresis_step(v, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Advance H by one sample: output for command ``v`` after ``(v_prev, u_prev)``."""
    if v > v_prev:
        c_u = u_prev - m_b * v_prev
        return min(max(m_b * v + c_u, m_r * (v - c_r)), m_t * v + c_t)
    if v < v_prev:
        c_d = u_prev - m_t * v_prev
        return max(min(m_t * v + c_d, m_l * (v - c_l)), m_b * v + c_b)
    return u_prev


@njit(cache=True, inline='always')
def hysteresis_inverse_step(u_d, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Command ``v`` that makes H output ``u_d`` from state ``(v_prev, u_prev)``."""
    if u_d > u_prev:
        c_u = u_prev - m_b * v_prev
        return max(min((u_d - c_u) / m_b, u_d / m_r + c_r), (u_d - c_t) / m_t)
    if u_d < u_prev:
        c_d = u_prev - m_t * v_prev
        return min(max((u_d - c_d) / m_t, u_d / m_l + c_l), (u_d - c_b) / m_b)
    return v_prev


@njit(cache=True)
def _simulate(p, v, u0):
    n = v.shape[0]
    u = np.empty(n)
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    u[0] = u0
    for j in range(1, n):
        u[j] = hysteresis_step(v[j], v[j - 1], u[j - 1], m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
    return u


@njit(cache=True)
def _invert(p, u_d, v0, u0):
    n = u_d.shape[0]
    v = np.empty(n)
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    v_prev, u_prev = v0, u0
    for j in range(n):
        vj = hysteresis_inverse_step(u_d[j], v_prev, u_prev,
                                     m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
        u_prev = hysteresis_step(vj, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
        v_prev = vj
        v[j] = vj
    return v


def loop_corners(params: np.ndarray) -> dict[str, tuple[float, float]]:
    """Corners of the major loop as ``(v, u)``.

    ``A`` left-bottom, ``B`` right-bottom, ``C`` right-top (the paper's
    ``v_1``), ``D`` left-top; ``A`` is the paper's ``v_2``.
    """
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = np.asarray(params, dtype=float)
    v_a = (c_b + m_l * c_l) / (m_l - m_b)
    v_b = (c_b + m_r * c_r) / (m_r - m_b)
    v_c = (c_t + m_r * c_r) / (m_r - m_t)
    v_d = (c_t + m_l * c_l) / (m_l - m_t)
    return {'A': (v_a, m_b * v_a + c_b), 'B': (v_b, m_b * v_b + c_b),
            'C': (v_c, m_t * v_c + c_t), 'D': (v_d, m_t * v_d + c_t)}


def check_hysteresis(params: np.ndarray) -> np.ndarray:
    """Return ``params`` as float64, or raise if they do not describe a proper loop.

    The checks are gauge invariant (:func:`loop_is_proper`), so they hold for
    canonical parameter sets too; the paper's ``c_l < c_r`` is a search-space
    constraint only and is not required here.

    Parameters
    ----------
    params : array_like
        ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``.

    Raises
    ------
    InvalidParametersError
        Wrong length, non-finite values or a violated constraint (named).
    """
    p = np.asarray(params, dtype=np.float64).ravel()
    if p.shape[0] != 8 or not np.all(np.isfinite(p)):
        raise InvalidParametersError('hysteresis needs 8 finite parameters '
                                     f'{HYSTERESIS_NAMES}, got {p.tolist()}')
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p
    checks = (
        (m_l > 0 and m_r > 0, 'm_l, m_r > 0'),
        (0 < m_t < min(m_l, m_r), 'min(m_l, m_r) > m_t > 0'),
        (0 < m_b < min(m_l, m_r), 'min(m_l, m_r) > m_b > 0'),
        (c_t > c_b, 'c_t > c_b'),
    )
    for ok, rule in checks:
        if not ok:
            raise InvalidParametersError(f'hysteresis parameters violate {rule}')
    if not loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
        corners = {k: round(float(v[0]), 4) for k, v in loop_corners(p).items()}
        raise InvalidParametersError(
            'hysteresis loop is not proper: the left line must stay left of the right line '
            f'between the bottom and top lines (corner commands {corners} need A < B, '
            'D < C, A < D, B < C)')
    return p


def simulate_hysteresis(params: np.ndarray, command: np.ndarray,
                        u0: float | None = None) -> np.ndarray:
    """Output of H for a command sequence.

    Parameters
    ----------
    params : array_like
        ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``.
    command : numpy.ndarray
        Input ``v`` per sample.
    u0 : float, optional
        Initial output; default the rising boundary at ``command[0]``.

    Returns
    -------
    numpy.ndarray
        Output ``u`` per sample.
    """
    p = check_hysteresis(params)
    v = np.ascontiguousarray(command, dtype=np.float64)
    if u0 is None:
        u0 = initial_output(v[0], p[1], p[2], p[3], p[5], p[6], p[7])
    return _simulate(p, v, float(u0))


def invert_hysteresis(params: np.ndarray, desired: np.ndarray, v0: float,
                      u0: float | None = None) -> np.ndarray:
    """Commands that make H follow ``desired`` (Tao & Kokotovic inverse).

    Parameters
    ----------
    params : array_like
        Hysteresis parameters.
    desired : numpy.ndarray
        Desired output ``u_d`` per sample.
    v0 : float
        Command before the first sample (the model state's input).
    u0 : float, optional
        Output before the first sample; default the rising boundary at ``v0``.

    Returns
    -------
    numpy.ndarray
        Command ``v`` per sample; ``simulate_hysteresis`` of it from the
        same state reproduces ``desired`` wherever ``desired`` is reachable.
    """
    p = check_hysteresis(params)
    if u0 is None:
        u0 = initial_output(v0, p[1], p[2], p[3], p[5], p[6], p[7])
    return _invert(p, np.ascontiguousarray(desired, dtype=np.float64), float(v0), float(u0))
