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

"""The chain ``v -> H -> B -> sensor -> gain * s + offset``, sample by sample.

Written from the seed paper (Eq. 1-3, 8-10) as corrected by the model notes
(``shared/docs/model-notes.md``, which win where the two differ), with plain
numpy and Python loops. Nothing here comes from ``hyst_id``.

Modelling choices where the paper and the notes leave room, stated once:

Hysteresis H (notes, section 1)
    One step rule for every sample ``j >= 1``::

        rising  v(j) > v(j-1):  u = min(max(m_b v + c_u, m_r (v - c_r)), m_t v + c_t)
        falling v(j) < v(j-1):  u = max(min(m_t v + c_d, m_l (v - c_l)), m_b v + c_b)
        equal:                  u = u(j-1)

    with ``c_u = u(j-1) - m_b v(j-1)`` and ``c_d = u(j-1) - m_t v(j-1)``: inside
    the loop the output moves parallel to the bottom line while the command
    rises and parallel to the top line while it falls, until it meets the right
    (rising) or left (falling) line; the top line caps it and the bottom line
    floors it. Equality of consecutive commands is exact (no tolerance).

Initial state (the paper gives none)
    ``initial='rising'``: at ``v(0)`` H sits on the *rising* boundary of its
    major loop, i.e. where a command coming monotonically from far below would
    have left it: ``u(0) = min(max(m_b v0 + c_b, m_r (v0 - c_r)), m_t v0 + c_t)``
    (bottom line, then right line, then top line). ``initial='falling'``: on the
    falling boundary, ``u(0) = max(min(m_t v0 + c_t, m_l (v0 - c_l)), m_b v0 + c_b)``
    (top, then left, then bottom line). B starts on the edge of the same
    direction: ``y(0) = m_bl (u(0) - c_br)`` for rising, ``m_bl (u(0) - c_bl)``
    for falling. :func:`simulate` uses the same ``initial`` for both.

Backlash B (Eq. 10, notes section 2)
    ``y(j) = min(max(y(j-1), m_bl (u(j) - c_br)), m_bl (u(j) - c_bl))``.

Sensors (Eq. 8-9, notes section 3)
    ``1 / (tau_s s + 1)`` and ``omega_n^2 / (s^2 + 2 zeta omega_n s + omega_n^2)``
    (DC gain 1, ``omega_n`` in rad/s, ``tau_s`` in s), discretised exactly with
    a zero-order hold on the given, possibly non-uniform, sample times: the
    input sample ``x(j-1)`` is held constant on ``[t(j-1), t(j))`` and the
    output sample ``s(j)`` is the continuous sensor output at ``t(j)``. Hence
    ``s(j)`` depends on ``x(0..j-1)`` only (strictly proper: no direct feed-
    through of ``x(j)``). The sensors start at steady state on ``x(0)`` (the
    second-order one at rest: derivative 0). Repeated time stamps
    (``t(j) = t(j-1)``) leave the output unchanged; decreasing ones are an error.
    ``tau_s = 0`` is taken as its limit (``s(j) = x(j-1)``).

Calibration (notes, section 4)
    ``y = gain * s + offset`` after the sensor (also applied to position).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
from scipy.linalg import expm

__all__ = ['backlash', 'first_order_sensor', 'hysteresis', 'loop_corners',
           'paper_constraints_ok', 'second_order_sensor', 'simulate']

#: Parameter names of H, in the order :func:`hysteresis` takes them.
H_KEYS = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')
#: Parameter names of B, in the order :func:`backlash` takes them.
B_KEYS = ('m_bl', 'c_bl', 'c_br')
#: Accepted spellings of the sensor parameters (first one preferred).
_ALIASES = {'tau_s': ('tau_s', 'tau'), 'zeta': ('zeta',), 'omega_n': ('omega_n', 'wn')}
_INITIALS = ('rising', 'falling')


def _check_initial(initial: str) -> None:
    if initial not in _INITIALS:
        raise ValueError(f"initial must be 'rising' or 'falling', not {initial!r}")


def _times(t_s: np.ndarray, n: int) -> np.ndarray:
    t = np.asarray(t_s, dtype=float).ravel()
    if t.size != n:
        raise ValueError(f'{t.size} sample times for {n} samples')
    if np.any(np.diff(t) < 0):
        raise ValueError('sample times must be non-decreasing')
    return t


def _get(params: Mapping[str, float], key: str) -> float:
    for name in _ALIASES.get(key, (key,)):
        if name in params:
            return float(params[name])
    raise KeyError(key)


def loop_corners(params: Mapping[str, float]) -> dict[str, float]:
    """Corner commands of the major loop of H.

    Parameters
    ----------
    params : Mapping[str, float]
        At least ``m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b``.

    Returns
    -------
    dict[str, float]
        ``v1``: right line meets top line (Eq. 2); ``v2``: left line meets
        bottom line (Eq. 2); ``v3``: right line meets bottom line; ``v4``: left
        line meets top line.
    """
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = (float(params[k]) for k in H_KEYS)
    return {'v1': (c_t + m_r * c_r) / (m_r - m_t),
            'v2': (c_b + m_l * c_l) / (m_l - m_b),
            'v3': (c_b + m_r * c_r) / (m_r - m_b),
            'v4': (c_t + m_l * c_l) / (m_l - m_t)}


def paper_constraints_ok(params: Mapping[str, float], proper_loop: bool = False) -> bool:
    """Whether the parameters satisfy the paper's constraints on H and B.

    Parameters
    ----------
    params : Mapping[str, float]
        ``m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b`` and, if present, the
        backlash's ``m_bl, c_bl, c_br`` (all three or none). Sensor parameters
        are ignored.
    proper_loop : bool, optional
        Also require the major loop to have all four sides in order:
        ``v3 < v1`` (the rising boundary runs bottom, right, top),
        ``v2 < v4`` (the falling boundary runs top, left, bottom) and the left
        line left of the right line at the loop's lowest and highest outputs.
        The paper's inequalities alone do not guarantee this. Default False.

    Returns
    -------
    bool
        H (Eq. 1): ``m_l > 0``, ``m_r > 0``, ``min(m_l, m_r) > m_t > 0``,
        ``min(m_l, m_r) > m_b > 0``, ``c_l < c_r``, ``c_t > c_b``;
        B (Eq. 10): ``m_bl > 0``, ``c_bl < c_br`` (strict, as printed).
    """
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = (float(params[k]) for k in H_KEYS)
    m_min = min(m_l, m_r)
    ok = (m_l > 0 and m_r > 0 and m_min > m_t > 0 and m_min > m_b > 0
          and c_l < c_r and c_t > c_b)
    present = [k in params for k in B_KEYS]
    if any(present):
        if not all(present):
            raise KeyError(f'backlash needs all of {B_KEYS}')
        ok = ok and float(params['m_bl']) > 0 and float(params['c_bl']) < float(params['c_br'])
    if ok and proper_loop:
        v = loop_corners(params)
        u_low = m_b * v['v2'] + c_b
        u_high = m_t * v['v1'] + c_t
        ok = (v['v3'] < v['v1'] and v['v2'] < v['v4']
              and all(u / m_l + c_l < u / m_r + c_r for u in (u_low, u_high)))
    return bool(ok)


def hysteresis(v: np.ndarray, m_l: float, m_r: float, m_t: float, m_b: float, c_l: float,
               c_r: float, c_t: float, c_b: float, initial: str = 'rising') -> np.ndarray:
    """Krasnosel'skii / Tao-Kokotovic hysteresis H (Eq. 1-3 as corrected by the notes).

    Parameters
    ----------
    v : numpy.ndarray
        Command samples ``v(0), v(1), ...`` (1-D).
    m_l, m_r, m_t, m_b : float
        Slopes of the left, right, top and bottom lines.
    c_l, c_r, c_t, c_b : float
        Crossings: left ``u = m_l (v - c_l)``, right ``u = m_r (v - c_r)``,
        top ``u = m_t v + c_t``, bottom ``u = m_b v + c_b``.
    initial : {'rising', 'falling'}, optional
        Boundary of the major loop the state starts on at ``v(0)`` (module
        docstring). Default ``'rising'``.

    Returns
    -------
    numpy.ndarray
        Output ``u``, same length as ``v``.
    """
    _check_initial(initial)
    cmd = [float(x) for x in np.asarray(v, dtype=float).ravel()]
    m_l, m_r, m_t, m_b = float(m_l), float(m_r), float(m_t), float(m_b)
    c_l, c_r, c_t, c_b = float(c_l), float(c_r), float(c_t), float(c_b)
    out = [0.0] * len(cmd)
    if not cmd:
        return np.empty(0)
    x = cmd[0]
    if initial == 'rising':
        out[0] = min(max(m_b * x + c_b, m_r * (x - c_r)), m_t * x + c_t)
    else:
        out[0] = max(min(m_t * x + c_t, m_l * (x - c_l)), m_b * x + c_b)
    for j in range(1, len(cmd)):
        x, x_prev, u_prev = cmd[j], cmd[j - 1], out[j - 1]
        if x > x_prev:
            c_u = u_prev - m_b * x_prev
            out[j] = min(max(m_b * x + c_u, m_r * (x - c_r)), m_t * x + c_t)
        elif x < x_prev:
            c_d = u_prev - m_t * x_prev
            out[j] = max(min(m_t * x + c_d, m_l * (x - c_l)), m_b * x + c_b)
        else:
            out[j] = u_prev
    return np.array(out)


def backlash(u: np.ndarray, m_bl: float, c_bl: float, c_br: float,
             initial: str = 'rising') -> np.ndarray:
    """Backlash B of Eq. 10 (notes, section 2).

    Parameters
    ----------
    u : numpy.ndarray
        Input samples (the output of H), 1-D.
    m_bl : float
        Slope of both edges (the paper's ``m_b`` of B).
    c_bl, c_br : float
        Zero crossings of the left (falling) edge ``y = m_bl (u - c_bl)`` and
        the right (rising) edge ``y = m_bl (u - c_br)``.
    initial : {'rising', 'falling'}, optional
        Edge the output starts on at ``u(0)``: rising -> ``m_bl (u(0) - c_br)``,
        falling -> ``m_bl (u(0) - c_bl)``. Default ``'rising'``.

    Returns
    -------
    numpy.ndarray
        ``y(j) = min(max(y(j-1), m_bl (u(j) - c_br)), m_bl (u(j) - c_bl))``.
    """
    _check_initial(initial)
    inp = [float(x) for x in np.asarray(u, dtype=float).ravel()]
    if not inp:
        return np.empty(0)
    m, c_bl, c_br = float(m_bl), float(c_bl), float(c_br)
    out = [0.0] * len(inp)
    out[0] = m * (inp[0] - (c_br if initial == 'rising' else c_bl))
    for j in range(1, len(inp)):
        out[j] = min(max(out[j - 1], m * (inp[j] - c_br)), m * (inp[j] - c_bl))
    return np.array(out)


def first_order_sensor(t_s: np.ndarray, x: np.ndarray, tau_s: float,
                       x0: float | None = None) -> np.ndarray:
    """First-order lag ``1 / (tau_s s + 1)`` (Eq. 8), exact zero-order hold.

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times in s, non-decreasing, possibly non-uniform.
    x : numpy.ndarray
        Sensor input samples; ``x(j-1)`` is held on ``[t(j-1), t(j))``.
    tau_s : float
        Time constant in s (``>= 0``; 0 is the limit ``s(j) = x(j-1)``).
    x0 : float, optional
        Sensor output at ``t(0)``; default ``x(0)`` (steady state).

    Returns
    -------
    numpy.ndarray
        ``s(j) = a s(j-1) + (1 - a) x(j-1)``, ``a = exp(-(t(j) - t(j-1)) / tau_s)``.
    """
    inp = [float(z) for z in np.asarray(x, dtype=float).ravel()]
    t = _times(t_s, len(inp))
    tau = float(tau_s)
    if tau < 0:
        raise ValueError('tau_s must be >= 0')
    if not inp:
        return np.empty(0)
    out = [0.0] * len(inp)
    out[0] = inp[0] if x0 is None else float(x0)
    for j in range(1, len(inp)):
        dt = float(t[j] - t[j - 1])
        if dt == 0.0:
            a = 1.0
        elif tau == 0.0:
            a = 0.0
        else:
            a = float(np.exp(-dt / tau))
        out[j] = a * out[j - 1] + (1.0 - a) * inp[j - 1]
    return np.array(out)


def second_order_sensor(t_s: np.ndarray, x: np.ndarray, zeta: float, omega_n: float,
                        x0: float | None = None) -> np.ndarray:
    """Second order ``omega_n^2 / (s^2 + 2 zeta omega_n s + omega_n^2)`` (Eq. 9), exact ZOH.

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times in s, non-decreasing, possibly non-uniform.
    x : numpy.ndarray
        Sensor input samples; ``x(j-1)`` is held on ``[t(j-1), t(j))``.
    zeta : float
        Damping ratio (the paper's range is ``0 < zeta < 1``; any ``zeta >= 0``
        works here).
    omega_n : float
        Natural frequency in rad/s (``>= 0``).
    x0 : float, optional
        Output at ``t(0)``, at rest (zero derivative); default ``x(0)``
        (steady state).

    Returns
    -------
    numpy.ndarray
        Output samples. State ``(s, ds/dt)``, ``A = [[0, 1], [-wn^2, -2 zeta wn]]``,
        ``B = [0, wn^2]``; each step is ``exp([[A, B], [0, 0]] dt)`` applied to
        ``(state, x(j-1))`` (exact for the held input).
    """
    inp = [float(z) for z in np.asarray(x, dtype=float).ravel()]
    t = _times(t_s, len(inp))
    zeta, wn = float(zeta), float(omega_n)
    if zeta < 0 or wn < 0:
        raise ValueError('zeta and omega_n must be >= 0')
    if not inp:
        return np.empty(0)
    aug = np.zeros((3, 3))
    aug[0, 1] = 1.0
    aug[1, 0] = -wn * wn
    aug[1, 1] = -2.0 * zeta * wn
    aug[1, 2] = wn * wn
    cache: dict[float, np.ndarray] = {}
    pos = inp[0] if x0 is None else float(x0)
    vel = 0.0
    out = [0.0] * len(inp)
    out[0] = pos
    for j in range(1, len(inp)):
        dt = float(t[j] - t[j - 1])
        if dt not in cache:
            cache[dt] = expm(aug * dt)
        e = cache[dt]
        u = inp[j - 1]
        pos, vel = (e[0, 0] * pos + e[0, 1] * vel + e[0, 2] * u,
                    e[1, 0] * pos + e[1, 1] * vel + e[1, 2] * u)
        out[j] = pos
    return np.array(out)


def simulate(channel: str, params: Mapping[str, float], t_s: np.ndarray,
             command: np.ndarray, gain: float = 1.0, offset: float = 0.0,
             initial: str = 'rising') -> np.ndarray:
    """Noise-free output of one sensor channel of the Fig. 1 chain.

    Parameters
    ----------
    channel : {'position', 'pressure', 'flow'}
        ``'position'``: ``B(H(v))``; ``'pressure'``: the first-order sensor of
        it; ``'flow'``: the second-order sensor of it.
    params : Mapping[str, float]
        ``m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b`` (H), ``m_bl, c_bl, c_br`` (B),
        ``tau_s`` (alias ``tau``) for pressure, ``zeta`` and ``omega_n`` (alias
        ``wn``, rad/s) for flow. Extra keys are ignored.
    t_s : numpy.ndarray
        Sample times in s (non-decreasing; used by the sensors only).
    command : numpy.ndarray
        Command ``v`` (the paper's actuator current, mA).
    gain, offset : float, optional
        Affine calibration ``gain * s + offset`` after the sensor.
    initial : {'rising', 'falling'}, optional
        Initial state of both H and B (module docstring). Default ``'rising'``.

    Returns
    -------
    numpy.ndarray
        The calibrated channel output, one sample per command sample.
    """
    v = np.asarray(command, dtype=float).ravel()
    t = _times(t_s, v.size)
    u = hysteresis(v, *(float(params[k]) for k in H_KEYS), initial=initial)
    y = backlash(u, *(float(params[k]) for k in B_KEYS), initial=initial)
    if channel == 'pressure':
        y = first_order_sensor(t, y, _get(params, 'tau_s'))
    elif channel == 'flow':
        y = second_order_sensor(t, y, _get(params, 'zeta'), _get(params, 'omega_n'))
    elif channel != 'position':
        raise ValueError(f'unknown channel {channel!r}')
    return float(gain) * y + float(offset)
