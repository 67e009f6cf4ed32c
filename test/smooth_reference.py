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

"""A plain-Python smooth-family loop and recordings of it, for tests that need curved loops.

Written from the formula in :mod:`hyst_id.models.smooth`'s docstring, one
sample and one play at a time, importing nothing from ``hyst_id.models``; the
backlash and sensor come from ``reference_sim`` (written apart from hyst_id).
"""

from __future__ import annotations

import math

import numpy as np
from reference_sim import backlash, first_order_sensor

from hyst_id.io.recording import Recording

__all__ = ['plain_play_sum', 'random_params', 'smooth_recording', 'N_PLAYS']

#: Number of plays of the smooth family (its parameter vector: N weights,
#: ``w_l, r_max, v_s, v_c, c_o``).
N_PLAYS = 6


def plain_play_sum(p, v):
    """The smooth family's H from its formula, one sample and one play at a time."""
    w = [float(x) for x in p[:N_PLAYS]]
    w_l, r_max, v_s, v_c, c_o = (float(x) for x in p[N_PLAYS:])
    r = [r_max * k / (N_PLAYS - 1) for k in range(N_PLAYS)]
    g = v_s * math.tanh((float(v[0]) - v_c) / v_s)
    z = [g - rk for rk in r]
    out = []
    for x in v:
        g = v_s * math.tanh((float(x) - v_c) / v_s)
        z = [max(g - rk, min(g + rk, zk)) for zk, rk in zip(z, r)]
        out.append(c_o + w_l * (float(x) - v_c) + sum(wk * zk for wk, zk in zip(w, z)))
    return np.array(out)


def random_params(rng):
    """A valid set: some weights zero, wide and narrow thresholds, weak and strong saturation."""
    w = rng.uniform(0.0, 2.0, N_PLAYS) * (rng.uniform(size=N_PLAYS) < 0.7)
    w[0] = rng.uniform(0.05, 2.0)
    w_l = rng.uniform(0.0, 1.0) * (rng.uniform() < 0.5)
    return np.concatenate([w, [w_l, rng.uniform(0.0, 3.0), math.exp(rng.uniform(-1.0, 3.0)),
                               rng.uniform(-1.0, 1.0), rng.uniform(-5.0, 5.0)]])


def smooth_recording(seed: int):
    """A pressure recording of a random smooth loop, backlash and lag; its true noise floor."""
    rng = np.random.default_rng([8, seed])
    p = random_params(rng)
    p[N_PLAYS + 3] = 0.0                   # v_c
    t = np.arange(3000) * 0.02
    v = 2.0 * np.sin(2 * np.pi * t / 12.0) * (0.4 + 0.6 * np.exp(-t / 25.0))
    v += 0.3 * np.sin(2 * np.pi * t / 2.7)
    u = plain_play_sum(p, v)
    span = np.ptp(u)
    band = rng.uniform(0.0, 0.15) * span
    y0 = first_order_sensor(t, backlash(u, 1.0, -0.5 * band, 0.5 * band), 0.3)
    sigma = 0.005 * np.ptp(y0)
    y = 40.0 * y0 + 3.0 + 40.0 * rng.normal(0.0, sigma, t.size)
    floor = float(np.sqrt(t.size * (40.0 * sigma) ** 2 / (y @ y)) * 100.0)
    return Recording(t, v, y, 'pressure', 'V', 'kPa', f'smooth #{seed}'), floor
