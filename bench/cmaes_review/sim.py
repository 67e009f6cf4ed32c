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

"""A simulator of the paper's chain written apart from the package (stop 65's reviewer).

An independent reviewer wrote it from the paper and the model notes without
reading the package's code: v -> H -> B -> sensor -> y = k s + b.

Conventions (the reviewer's):

* H: the model notes' step rule; initial state ``rising`` (default):
  ``u0 = min(max(m_b v0 + c_b, m_r (v0 - c_r)), m_t v0 + c_t)``; ``falling``:
  ``u0 = max(min(m_t v0 + c_t, m_l (v0 - c_l)), m_b v0 + c_b)``.
* B: ``y = min(max(y_prev, m_bl (u - c_br)), m_bl (u - c_bl))``; initial ``rising``:
  ``y0 = m_bl (u0 - c_br)``, ``falling``: ``m_bl (u0 - c_bl)``.
* sensor: exact zero-order hold; ``after`` (default): the input of sample j-1 is
  held over (t_{j-1}, t_j] (the package's ``hold='after'``); ``before``: the input of
  sample j. The sensor starts at rest at its first input.
"""

from numba import njit
import numpy as np

HN = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')


@njit(cache=True)
def sim_H(v, p, falling):
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    n = v.shape[0]
    u = np.empty(n)
    v0 = v[0]
    if falling:
        up = max(min(m_t * v0 + c_t, m_l * (v0 - c_l)), m_b * v0 + c_b)
    else:
        up = min(max(m_b * v0 + c_b, m_r * (v0 - c_r)), m_t * v0 + c_t)
    vp = v0
    for j in range(n):
        x = v[j]
        if x > vp:
            cu = up - m_b * vp
            up = min(max(m_b * x + cu, m_r * (x - c_r)), m_t * x + c_t)
        elif x < vp:
            cd = up - m_t * vp
            up = max(min(m_t * x + cd, m_l * (x - c_l)), m_b * x + c_b)
        u[j] = up
        vp = x
    return u


@njit(cache=True)
def sim_B(u, m_bl, c_bl, c_br, falling):
    n = u.shape[0]
    y = np.empty(n)
    yp = m_bl * (u[0] - c_bl) if falling else m_bl * (u[0] - c_br)
    for j in range(n):
        yp = min(max(yp, m_bl * (u[j] - c_br)), m_bl * (u[j] - c_bl))
        y[j] = yp
    return y


@njit(cache=True)
def sens1(w, t, tau, after):
    n = w.shape[0]
    x = np.empty(n)
    x[0] = w[0]
    for j in range(1, n):
        h = w[j - 1] if after else w[j]
        if tau <= 0.0:
            x[j] = h
        else:
            a = np.exp(-(t[j] - t[j - 1]) / tau)
            x[j] = a * x[j - 1] + (1.0 - a) * h
    return x


@njit(cache=True)
def sens2(w, t, zeta, wn, after):
    n = w.shape[0]
    x = np.empty(n)
    x[0] = w[0]
    xp = w[0]
    dp = 0.0
    sg = zeta * wn
    d2 = wn * wn * (zeta * zeta - 1.0)
    for j in range(1, n):
        h = w[j - 1] if after else w[j]
        dt = t[j] - t[j - 1]
        if d2 < 0.0:
            wd = np.sqrt(-d2)
            C = np.cos(wd * dt)
            S = np.sin(wd * dt) / wd
        elif d2 > 0.0:
            wo = np.sqrt(d2)
            C = np.cosh(wo * dt)
            S = np.sinh(wo * dt) / wo
        else:
            C = 1.0
            S = dt
        E = np.exp(-sg * dt)
        e = xp - h
        e1 = E * ((C + sg * S) * e + S * dp)
        d1 = E * (-wn * wn * S * e + (C - sg * S) * dp)
        xp = h + e1
        dp = d1
        x[j] = xp
    return x


def simulate(v, t, H, B, channel, sens=(), falling=False, after=True, k=1.0, b=0.0):
    v = np.ascontiguousarray(v, float)
    t = np.ascontiguousarray(t, float)
    u = sim_H(v, np.asarray(H, float), falling)
    w = sim_B(u, float(B[0]), float(B[1]), float(B[2]), falling)
    if channel == 'position':
        s = w
    elif channel == 'pressure':
        s = sens1(w, t, float(sens[0]), after)
    elif channel == 'flow':
        s = sens2(w, t, float(sens[0]), float(sens[1]), after)
    else:
        raise ValueError(channel)
    return k * s + b


def corners(H):
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = H
    vA = (c_b + m_l * c_l) / (m_l - m_b)   # left  & bottom
    vB = (c_b + m_r * c_r) / (m_r - m_b)   # right & bottom
    vC = (c_t + m_r * c_r) / (m_r - m_t)   # right & top (paper v_1)
    vD = (c_t + m_l * c_l) / (m_l - m_t)   # left  & top
    return vA, vB, vC, vD


def proper(H):
    vA, vB, vC, vD = corners(H)
    return bool(vA < vB and vD < vC and vA < vD and vB < vC)


def paper_ok(H):
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = H
    return bool(m_l > 0 and m_r > 0 and min(m_l, m_r) > m_t > 0 and min(m_l, m_r) > m_b > 0
                and c_l < c_r and c_t > c_b)
