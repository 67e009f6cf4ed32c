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

"""Eight random chains under the paper's constraints only (stop 65's reviewer's draw).

The reviewer's generator (seed 6565), kept in memory instead of CSV files:
chains drawn under the paper's constraints alone (``m_l`` and ``m_r`` often quite
different, the corners in any order), excitations of four kinds, 1,000-2,000
samples at 0.1 s, Gaussian noise 0.3-2 % of the span, simulated by
:mod:`sim` (rising start, sensor hold ``after``).
"""

import numpy as np
import sim

PLAN = [  # name, channel, excitation, n
    ('r1', 'position', 'decaying_sine', 1500),
    ('r2', 'pressure', 'sweep', 1200),
    ('r3', 'flow', 'random_steps', 2000),
    ('r4', 'position', 'multisine', 1000),
    ('r5', 'pressure', 'decaying_sine', 1800),
    ('r6', 'flow', 'sweep', 1500),
    ('r7', 'position', 'random_steps', 1600),
    ('r8', 'pressure', 'multisine', 2000),
]
DT = 0.1


def draw_h(rng):
    """A loop under the paper's constraints whose corners lie in 5-19 mA."""
    while True:
        if rng.random() < 0.6:   # often quite different side slopes
            m_l = np.exp(rng.uniform(np.log(0.4), np.log(2.5)))
            m_r = m_l * np.exp(rng.choice([-1, 1]) * rng.uniform(np.log(1.5), np.log(3.0)))
        else:
            m_l, m_r = np.exp(rng.uniform(np.log(0.4), np.log(2.5), 2))
        mn = min(m_l, m_r)
        m_t, m_b = rng.uniform(0.03, 0.6, 2) * mn
        c_l, c_r = np.sort(rng.uniform(-5, 5, 2))
        c_b, c_t = np.sort(rng.uniform(4, 20, 2))
        h = [m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b]
        if not sim.paper_ok(h):
            continue
        cs = sim.corners(h)
        if min(cs) < 5 or max(cs) > 19 or max(cs) - min(cs) < 3:
            continue
        return h


def excitation(rng, kind, n, lo, hi):
    t = np.arange(n) * DT
    T = t[-1]
    mid, amp = (lo + hi) / 2, (hi - lo) / 2
    if kind == 'decaying_sine':
        per = rng.uniform(12, 25)
        v = mid + amp * np.exp(-1.2 * t / T) * np.sin(2 * np.pi * t / per)
    elif kind == 'sweep':   # triangle sweeps: full, then nested minor loops, then full again
        per = rng.uniform(15, 30)
        ph = (t / per) % 1.0
        tri = 2 * np.abs(2 * ph - 1) - 1          # starts at +1 ... use -tri to start low
        env = np.where(t < T / 3, 1.0, np.where(
            t < 2 * T / 3, 0.35 + 0.3 * np.cos(2 * np.pi * t / (3 * per)) ** 2, 1.0))
        v = mid - amp * env * tri + 0.15 * amp * np.sin(2 * np.pi * t / 7.3) * (env < 1)
    elif kind == 'random_steps':
        v = np.empty(n)
        j = 0
        while j < n:
            L = rng.integers(15, 60)
            v[j:j + L] = rng.uniform(lo, hi)
            j += L
        # make sure extremes are visited
        q = n // 4
        v[q:q + 30] = lo
        v[2 * q:2 * q + 30] = hi
        v[3 * q:3 * q + 30] = lo + 0.1 * (hi - lo)
    elif kind == 'multisine':
        fs = rng.uniform(1 / 40, 1 / 4, 4)
        fs[0] = 1 / rng.uniform(20, 35)
        a = np.array([1.0, 0.35, 0.25, 0.15])
        ph = rng.uniform(0, 2 * np.pi, 4)
        s = sum(a[i] * np.sin(2 * np.pi * fs[i] * t + ph[i]) for i in range(4))
        v = mid + amp * s / np.abs(s).max()
    return t, v


def loop_usage(v, H):
    """Fraction of samples whose H output lies on the left/right/top/bottom line."""
    u = sim.sim_H(v, np.asarray(H, float), False)
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = H
    tol = 1e-9 * (1 + np.abs(u))
    return {k: float(np.mean(np.abs(u - f) < tol)) for k, f in
            (('left', m_l * (v - c_l)), ('right', m_r * (v - c_r)),
             ('top', m_t * v + c_t), ('bottom', m_b * v + c_b))}


def draw_all(seed=6565) -> list[dict]:
    """The eight recordings: name, channel, excitation, t, command, measurement, truth.

    ``seed`` 6565 is the reviewer's draw; other seeds draw eight more the same way.
    """
    rng = np.random.default_rng(seed)
    cases = []
    for name, ch, kind, n in PLAN:
        while True:
            h = draw_h(rng)
            cs = sim.corners(h)
            lo = max(3.5, min(cs) - rng.uniform(0.5, 2.0))
            hi = min(20.5, max(cs) + rng.uniform(0.5, 2.0))
            t, v = excitation(rng, kind, n, lo, hi)
            use = loop_usage(v, h)
            if use['left'] > 0.03 and use['right'] > 0.03:
                break
        u = sim.sim_H(v, np.asarray(h), False)
        span_u = u.max() - u.min()
        m_bl = float(np.exp(rng.uniform(np.log(0.5), np.log(2.0))))
        c_bl = float(rng.uniform(-3, 3))
        c_br = float(c_bl + rng.uniform(0.02, 0.12) * span_u)
        sens = []
        if ch == 'pressure':
            sens = [float(rng.uniform(0.2, 2.0))]
        elif ch == 'flow':
            sens = [float(rng.uniform(0.3, 0.9)), float(rng.uniform(1.0, 5.0))]
        k, b = ((1.0, 0.0) if ch == 'position'
                else (float(rng.uniform(0.5, 5)), float(rng.uniform(-20, 20))))
        y0 = sim.simulate(v, t, h, [m_bl, c_bl, c_br], ch, sens, falling=False, after=True,
                          k=k, b=b)
        frac = float(rng.uniform(0.003, 0.02))
        sigma = frac * (y0.max() - y0.min())
        y = y0 + rng.normal(0, sigma, n)
        cases.append({'name': name, 'channel': ch, 'excitation': kind, 't': t, 'command': v,
                      'measurement': y, 'sigma': float(sigma), 'noise_frac': frac,
                      'proper': sim.proper(h), 'H': h, 'B': [m_bl, c_bl, c_br],
                      'sensor': sens})
    return cases
