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

"""A plain IPOP CMA-ES fit with :mod:`sim` (stop 65's reviewer's, unchanged in substance).

Gauge-fixed search (the chain's exact scale and offset freedoms removed):
``m_l = 1``, ``c_l = 0``, a backlash of unit slope centred on zero (half-width
``hw``), the output calibration ``y = k s + b`` profiled by least squares.
Searched: ``m_r``, ``m_t``, ``m_b`` (as fractions of ``min(m_l, m_r)``), the left
line's bottom and top corners (giving ``c_b``, ``c_t``), ``c_r``, ``hw`` and the
sensor (``tau`` or ``zeta``, ``omega_n``). ``c_t > c_b`` by penalty; ``c_l < c_r``
is not imposed (it depends on the gauge). The generator's conventions.
"""

import time

from cmaes import CMA
import numpy as np
import sim


def unpack(z, lo, hi, ch):
    """The chain of a point of the unit box."""
    x = lo + z * (hi - lo)
    m_r = np.exp(x[0])
    mn = min(1.0, m_r)
    m_t, m_b = x[1] * mn, x[2] * mn
    v_a, v_d, c_r, hw = x[3], x[4], x[5], x[6]
    c_b = v_a * (1 - m_b)
    c_t = v_d * (1 - m_t)
    h = np.array([1.0, m_r, m_t, m_b, 0.0, c_r, c_t, c_b])
    if ch == 'pressure':
        sens = (np.exp(x[7]),)
    elif ch == 'flow':
        sens = (x[7], np.exp(x[8]))
    else:
        sens = ()
    return h, (1.0, -hw, hw), sens


def make_cost(t, v, y, ch):
    """The mean squared residual of a unit-box point, calibration profiled."""
    def cost(z, lo, hi, full=False):
        h, b, sens = unpack(z, lo, hi, ch)
        if h[6] <= h[7]:
            pen = 1e3 * (1 + h[7] - h[6])
            return pen * np.var(y) + np.var(y) * 10
        s = sim.simulate(v, t, h, b, ch, sens)
        a = np.column_stack([s, np.ones_like(s)])
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        r = y - a @ coef
        if full:
            return r, h, b, sens, coef
        return float(np.mean(r * r))
    return cost


def fit(case: dict, budget: int = 300000, seed: int = 0) -> dict:
    """IPOP CMA-ES on one recording of :func:`draw.draw_all`: RMS residual over the noise."""
    ch = case['channel']
    t, v, y = case['t'], case['command'], case['measurement']
    vmin, vmax = v.min(), v.max()
    sp = vmax - vmin
    lo = [np.log(0.05), 0.001, 0.001, vmin - sp, vmin - sp, vmin - 2 * sp, 0.0]
    hi = [np.log(20.0), 0.999, 0.999, vmax + sp, vmax + sp, vmax + 2 * sp, sp]
    if ch == 'pressure':
        lo += [np.log(0.01)]
        hi += [np.log(20.0)]
    if ch == 'flow':
        lo += [0.01, np.log(0.1)]
        hi += [1.5, np.log(30.0)]
    lo, hi = np.array(lo), np.array(hi)
    d = len(lo)
    cost = make_cost(t, v, y, ch)
    rng = np.random.default_rng(seed)
    best, bestz, nfev, pop, restarts = np.inf, None, 0, 4 + int(3 * np.log(d)), 0
    t0 = time.time()
    while nfev < budget:
        opt = CMA(mean=rng.uniform(0.2, 0.8, d), sigma=0.3, bounds=np.array([[0, 1]] * d),
                  population_size=pop, seed=int(rng.integers(1 << 30)))
        while not opt.should_stop() and nfev < budget:
            sols = []
            for _ in range(opt.population_size):
                z = opt.ask()
                f = cost(z, lo, hi)
                nfev += 1
                sols.append((z, f))
                if f < best:
                    best, bestz = f, z.copy()
            opt.tell(sols)
        restarts += 1
        pop *= 2
    r, h, b, sens, coef = cost(bestz, lo, hi, full=True)
    rms = float(np.sqrt(np.mean(r * r)))
    return {'ratio': rms / case['sigma'], 'nfev': nfev, 'restarts': restarts,
            'seconds': time.time() - t0, 'proper': sim.proper(h)}
