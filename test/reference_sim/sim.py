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

"""The chain ``v -> H -> B -> sensor -> k s + b``, sample by sample, from the model notes.

Choices where the notes leave them open, stated here:

* **Initial state** (``initial``): ``'rising'`` puts H on the rising boundary
  of its major loop at ``v[0]`` (coming from far below: bottom line, then the
  right line, capped by the top line) and B on its rising edge
  (``y = m (u - c_br)``); ``'falling'`` the mirror image (top line, left
  line, floored by the bottom line; ``y = m (u - c_bl)``).
* **Sensors, zero-order hold**: the sensor input sampled at ``t[j-1]`` is held
  until ``t[j]`` and the sample at ``t[j]`` is the sensor output then, so a
  sample does not yet respond to the command sent at the same instant. The
  sensors start at steady state on the first input. Any sample times
  (non-uniform included) are handled exactly.
* **Calibration**: ``y = gain * s + offset`` after the sensor.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

__all__ = ['backlash', 'first_order_sensor', 'hysteresis', 'paper_constraints_ok',
           'second_order_sensor', 'simulate']

H_NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')
B_NAMES = ('m_bl', 'c_bl', 'c_br')


def paper_constraints_ok(params: dict) -> bool:
    """The notes' constraints on H and B (section 1 and 2)."""
    p = params
    m_min = min(p['m_l'], p['m_r'])
    return bool(p['m_l'] > 0 and p['m_r'] > 0 and m_min > p['m_t'] > 0
                and m_min > p['m_b'] > 0 and p['c_l'] < p['c_r'] and p['c_t'] > p['c_b']
                and p.get('m_bl', 1.0) > 0 and p.get('c_bl', 0.0) <= p.get('c_br', 0.0))


def hysteresis(v: np.ndarray, m_l: float, m_r: float, m_t: float, m_b: float, c_l: float,
               c_r: float, c_t: float, c_b: float, initial: str = 'rising') -> np.ndarray:
    """H of the notes' one-step rule; see the module docstring for the initial state."""
    v = np.asarray(v, dtype=float)
    u = np.empty(v.size)
    x = v[0]
    if initial == 'rising':
        u[0] = min(max(m_b * x + c_b, m_r * (x - c_r)), m_t * x + c_t)
    else:
        u[0] = max(min(m_t * x + c_t, m_l * (x - c_l)), m_b * x + c_b)
    for j in range(1, v.size):
        x, x_prev, u_prev = v[j], v[j - 1], u[j - 1]
        if x > x_prev:
            c_u = u_prev - m_b * x_prev
            u[j] = min(max(m_b * x + c_u, m_r * (x - c_r)), m_t * x + c_t)
        elif x < x_prev:
            c_d = u_prev - m_t * x_prev
            u[j] = max(min(m_t * x + c_d, m_l * (x - c_l)), m_b * x + c_b)
        else:
            u[j] = u_prev
    return u


def backlash(u: np.ndarray, m_bl: float, c_bl: float, c_br: float,
             initial: str = 'rising') -> np.ndarray:
    """B of Eq. 10: ``y(j) = min(max(y(j-1), m (u - c_br)), m (u - c_bl))``."""
    u = np.asarray(u, dtype=float)
    y = np.empty(u.size)
    y[0] = m_bl * (u[0] - (c_br if initial == 'rising' else c_bl))
    for j in range(1, u.size):
        y[j] = min(max(y[j - 1], m_bl * (u[j] - c_br)), m_bl * (u[j] - c_bl))
    return y


def first_order_sensor(t_s: np.ndarray, x: np.ndarray, tau_s: float,
                       x0: float | None = None) -> np.ndarray:
    """``1 / (tau s + 1)``, the input held from each sample to the next."""
    t_s = np.asarray(t_s, dtype=float)
    x = np.asarray(x, dtype=float)
    s = np.empty(x.size)
    s[0] = x[0] if x0 is None else x0
    for j in range(1, x.size):
        a = np.exp(-(t_s[j] - t_s[j - 1]) / tau_s) if tau_s > 0 else 0.0
        s[j] = a * s[j - 1] + (1.0 - a) * x[j - 1]
    return s


def second_order_sensor(t_s: np.ndarray, x: np.ndarray, zeta: float, omega_n: float,
                        x0: float | None = None) -> np.ndarray:
    """``omega_n^2 / (s^2 + 2 zeta omega_n s + omega_n^2)``, exact zero-order hold."""
    t_s = np.asarray(t_s, dtype=float)
    x = np.asarray(x, dtype=float)
    a = np.array([[0.0, 1.0], [-omega_n ** 2, -2.0 * zeta * omega_n]])
    b = np.array([0.0, omega_n ** 2])
    aug = np.zeros((3, 3))
    aug[:2, :2], aug[:2, 2] = a, b
    cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    state = np.array([x[0] if x0 is None else x0, 0.0])    # at rest
    s = np.empty(x.size)
    s[0] = state[0]
    for j in range(1, x.size):
        dt = float(t_s[j] - t_s[j - 1])
        if dt not in cache:
            e = expm(aug * dt)
            cache[dt] = (e[:2, :2], e[:2, 2])
        phi, gamma = cache[dt]
        state = phi @ state + gamma * x[j - 1]
        s[j] = state[0]
    return s


def simulate(channel: str, params: dict, t_s: np.ndarray, command: np.ndarray,
             gain: float = 1.0, offset: float = 0.0, initial: str = 'rising') -> np.ndarray:
    """Noise-free output of the chain for one channel.

    Parameters
    ----------
    channel : {'position', 'pressure', 'flow'}
        Position is ``B(H(v))``; pressure adds the first-order sensor
        (``params['tau_s']``), flow the second-order one (``params['zeta']``,
        ``params['omega_n']`` in rad/s).
    params : dict
        ``m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b, m_bl, c_bl, c_br`` and the
        sensor's.
    t_s, command : numpy.ndarray
        Sample times (s) and the command.
    gain, offset : float
        Calibration after the sensor.
    initial : {'rising', 'falling'}
        Initial state of H and B.
    """
    u = hysteresis(command, *(params[n] for n in H_NAMES), initial=initial)
    y = backlash(u, *(params[n] for n in B_NAMES), initial=initial)
    if channel == 'pressure':
        y = first_order_sensor(t_s, y, params['tau_s'])
    elif channel == 'flow':
        y = second_order_sensor(t_s, y, params['zeta'], params['omega_n'])
    elif channel != 'position':
        raise ValueError(f'unknown channel {channel!r}')
    return gain * y + offset
