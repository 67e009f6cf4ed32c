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

"""The smooth hysteresis family ``smooth``: a Prandtl-Ishlinskii operator behind a saturating map.

Curved loops (piezo stacks, soft magnetic B(H) loops, valves with soft seals)
as a weighted sum of play operators on a fixed threshold grid, fed through a
saturating input map::

    g(v)  = v_s * tanh((v - v_c) / v_s)                  (saturation, command units)
    z_k   = play of threshold r_k = r_max * k / (N - 1) on g, k = 0 .. N - 1
    u     = c_o + w_l (v - v_c) + sum_k w_k z_k

with the play ``z_k <- max(g - r_k, min(g + r_k, z_k))``. ``k = 0`` has a
zero threshold (the loop's reversible part), the others open the loop; the
branches bend from the reversal points as more plays engage (the
Prandtl-Ishlinskii shape), and ``g`` flattens them at the ends of the travel
so that the branches of a wide loop close as a B(H) loop does (``v_s`` large:
no saturation). ``w_l`` is a reversible slope on the raw command that the
saturation leaves (a B(H) loop keeps rising past the knee; ``w_l = 0``: the
output saturates). :data:`N_PLAYS` plays.

Exact inverse. With ``w_0 > 0`` and ``w_k, w_l >= 0`` every branch is
strictly increasing in ``v`` (``g`` is), so for a desired output the play sum
is a piecewise-linear increasing function of ``g`` from the present state: the
segment holding the target is found by walking the breakpoints, then
``v = v_c + v_s atanh(g / v_s)`` in closed form (``w_l = 0``) or a bracketed
Newton solve of one monotone scalar equation on that segment (``w_l > 0``),
both to round-off (:class:`SmoothInverse`). With ``w_l = 0`` outputs beyond
the saturation are not reachable: the inverse returns the nearest reachable command.

Conventions as every family (:mod:`hyst_id.models.family`): the state starts
on the rising boundary at the first command (``z_k = g(v_0) - r_k``).
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from hyst_id.errors import InvalidParametersError
from hyst_id.models.family import HysteresisFamily, HysteresisInverse, LoopBox

__all__ = ['FAMILY', 'N_PLAYS', 'SMOOTH_NAMES', 'Smooth', 'SmoothInverse', 'smooth_feasible']

#: Number of play operators (thresholds ``r_max * k / (N_PLAYS - 1)``).
N_PLAYS = 6
WEIGHT_NAMES = tuple(f'w_{k}' for k in range(N_PLAYS))
SMOOTH_NAMES = WEIGHT_NAMES + ('w_l', 'r_max', 'v_s', 'v_c', 'c_o')
UNITS = {**dict.fromkeys(WEIGHT_NAMES, 'out/cmd'), 'w_l': 'out/cmd', 'r_max': 'cmd',
         'v_s': 'cmd', 'v_c': 'cmd', 'c_o': 'out'}
# vector positions after the play weights
_WL, _RMAX, _VS, _VC, _CO = range(N_PLAYS, N_PLAYS + 5)
#: Largest |g / v_s| the inverse aims at (atanh stays finite).
_G_EDGE = 1.0 - 1e-12


@njit(cache=True)
def smooth_feasible(p):
    """True when ``p`` is a valid set: ``w_0 > 0``, ``w_k, w_l, r_max >= 0``, ``v_s > 0``."""
    for i in range(p.shape[0]):
        if not np.isfinite(p[i]):
            return False
    if not p[0] > 0.0:
        return False
    for k in range(1, N_PLAYS + 1):
        if p[k] < 0.0:
            return False
    return p[_RMAX] >= 0.0 and p[_VS] > 0.0


@njit(cache=True)
def _feasible_rows(pop):
    ok = np.empty(pop.shape[0], dtype=np.bool_)
    for i in range(pop.shape[0]):
        ok[i] = smooth_feasible(pop[i])
    return ok


@njit(cache=True)
def _simulate_rows(pop, v, ok, out):
    n = v.shape[0]
    z = np.empty(N_PLAYS)
    r = np.empty(N_PLAYS)
    for i in range(pop.shape[0]):
        if not ok[i]:
            continue
        w_l, r_max, v_s = pop[i, _WL], pop[i, _RMAX], pop[i, _VS]
        v_c, c_o = pop[i, _VC], pop[i, _CO]
        for k in range(N_PLAYS):
            r[k] = r_max * k / (N_PLAYS - 1)
        g = v_s * math.tanh((v[0] - v_c) / v_s)
        for k in range(N_PLAYS):
            z[k] = g - r[k]                            # rising boundary
        for j in range(n):
            g = v_s * math.tanh((v[j] - v_c) / v_s)
            acc = c_o + w_l * (v[j] - v_c)
            for k in range(N_PLAYS):
                zk = min(g + r[k], z[k])
                zk = max(g - r[k], zk)
                z[k] = zk
                acc += pop[i, k] * zk
            out[i, j] = acc


def _solve_command(w: np.ndarray, r: np.ndarray, z: np.ndarray, v0: float, g0: float,
                   shape: tuple[float, float, float], target: float) -> float:
    """The command from ``v0`` where ``w_l (v - v_c) + sum_k w_k play_k(g(v)) = target``.

    ``shape`` is ``(w_l, v_s, v_c)``. The play sum is piecewise linear in ``g``;
    walk its breakpoints from the present state to the segment holding the
    target, then solve on that segment (closed form with ``w_l = 0``, else a
    bracketed Newton iteration on a strictly increasing function).
    """
    w_l, v_s, v_c = shape
    s_now = float(w @ z)
    if target == s_now + w_l * (v0 - v_c):
        return v0
    up = target > s_now + w_l * (v0 - v_c)
    # play k starts moving once g passes its breakpoint: z_k + r_k (up) or z_k - r_k (down)
    brk = z + r if up else z - r
    order = np.argsort(brk) if up else np.argsort(-brk)
    engaged = (brk <= g0) if up else (brk >= g0)
    g, v, value, slope = g0, v0, s_now, float(w[engaged].sum())
    v_end = math.inf if up else -math.inf
    for k in order:
        if engaged[k]:
            continue
        b = float(brk[k])
        if abs(b) >= v_s:          # g never gets there
            break
        v_b = _v_of_g(b, v_s, v_c)
        reach = value + slope * (b - g)
        if (up and reach + w_l * (v_b - v_c) >= target) or \
                (not up and reach + w_l * (v_b - v_c) <= target):
            v_end = v_b
            break
        g, v, value = b, v_b, reach
        slope += float(w[k])
    if w_l == 0.0:
        return _v_of_g(g + (target - value) / slope, v_s, v_c)
    return _newton_on_segment(g, v, value, slope, (w_l, v_s, v_c), target, v_end)


def _v_of_g(g: float, v_s: float, v_c: float) -> float:
    x = min(max(g / v_s, -_G_EDGE), _G_EDGE)
    return v_c + v_s * math.atanh(x)


def _newton_on_segment(g0: float, v0: float, value: float, slope: float,
                       shape: tuple[float, float, float], target: float,
                       v_end: float) -> float:
    """Root of ``value + slope (g(v) - g0) + w_l (v - v_c) - target`` between v0 and v_end."""
    w_l, v_s, v_c = shape

    def f(v: float) -> float:
        return value + slope * (v_s * math.tanh((v - v_c) / v_s) - g0) + w_l * (v - v_c) - target

    f0 = f(v0)
    up = v_end > v0
    if (f0 >= 0.0) if up else (f0 <= 0.0):
        return v0                  # there already, to round-off
    # the slope is at least w_l, so the root lies within |f0| / w_l of v0
    lo, hi = (v0, min(v_end, v0 - f0 / w_l)) if up else (max(v_end, v0 - f0 / w_l), v0)
    x = 0.5 * (lo + hi)
    for _ in range(100):
        fx = f(x)
        if fx == 0.0:
            return x
        if fx < 0:
            lo = x
        else:
            hi = x
        th = math.tanh((x - v_c) / v_s)
        step = fx / (slope * (1.0 - th * th) + w_l)
        x_new = x - step
        if not lo < x_new < hi:
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= 4e-16 * max(1.0, abs(x)) or hi - lo <= 4e-16 * max(1.0, abs(x)):
            return x_new
        x = x_new
    return x


class SmoothInverse(HysteresisInverse):
    """Exact inverse of the smooth family with its own play states (see the module doc)."""

    def __init__(self, params: np.ndarray):
        p = np.asarray(params, dtype=float)
        self.w = p[:N_PLAYS].copy()
        self.w_l, self.r_max, self.v_s, self.v_c, self.c_o = (float(x) for x in p[N_PLAYS:])
        self.r = self.r_max * np.arange(N_PLAYS) / (N_PLAYS - 1)
        self.z = np.zeros(N_PLAYS)
        self.reset(0.0)

    def _g(self, v: float) -> float:
        return self.v_s * math.tanh((v - self.v_c) / self.v_s)

    def reset(self, v0: float, u0: float | None = None) -> None:
        """State at command ``v0``: rising boundary, or the fraction of the loop nearest ``u0``."""
        self.v = float(v0)
        self.g = self._g(self.v)
        self.z = self.g - self.r
        if u0 is not None:
            span = float(self.w @ (2.0 * self.r))
            if span > 0.0:
                lam = (float(u0) - self.output) / span
                self.z = self.g - self.r + min(max(lam, 0.0), 1.0) * 2.0 * self.r

    @property
    def command(self) -> float:
        """Last command of the state."""
        return self.v

    @property
    def output(self) -> float:
        """H's output in the state."""
        return self.c_o + self.w_l * (self.v - self.v_c) + float(self.w @ self.z)

    def command_for(self, u_d: float) -> float:
        """Command that makes H output ``u_d`` next (nearest reachable beyond saturation)."""
        if not math.isfinite(u_d):
            return self.v
        return _solve_command(self.w, self.r, self.z, self.v, self.g,
                              (self.w_l, self.v_s, self.v_c), float(u_d) - self.c_o)

    def advance(self, v: float) -> float:
        """Move the state with command ``v``; return H's output."""
        self.v = float(v)
        self.g = self._g(self.v)
        self.z = np.maximum(self.g - self.r, np.minimum(self.g + self.r, self.z))
        return self.output


class Smooth(HysteresisFamily):
    """Prandtl-Ishlinskii plays behind a saturating map (see the module doc)."""

    id = 'smooth'  # noqa: A003
    title = (f'smooth: Prandtl-Ishlinskii, {N_PLAYS} plays on a threshold grid, '
             'tanh saturation')
    names = SMOOTH_NAMES
    units = UNITS
    descriptions = {**{n: f'weight of play {k} (threshold r_max * {k} / {N_PLAYS - 1})'
                       for k, n in enumerate(WEIGHT_NAMES)},
                    'w_l': 'reversible slope on the raw command (past saturation)',
                    'r_max': 'widest play threshold', 'v_s': 'saturation reach of the '
                    'input map', 'v_c': 'centre of the input map', 'c_o': 'output offset'}

    def check(self, params: np.ndarray) -> np.ndarray:
        """Validate a set (finite; ``w_0 > 0``, ``w_k, w_l, r_max >= 0``, ``v_s > 0``)."""
        p = np.asarray(params, dtype=np.float64).ravel()
        if p.shape[0] != len(SMOOTH_NAMES):
            raise InvalidParametersError(f'the smooth family needs {len(SMOOTH_NAMES)} '
                                         f'parameters {SMOOTH_NAMES}, got {p.shape[0]}')
        if not np.all(np.isfinite(p)):
            raise InvalidParametersError('smooth parameters must be finite')
        if not p[0] > 0:
            raise InvalidParametersError('w_0 must be > 0 (strictly increasing branches)')
        if np.any(p[1:N_PLAYS] < 0):
            raise InvalidParametersError('play weights w_k must be >= 0')
        if p[_WL] < 0:
            raise InvalidParametersError('w_l must be >= 0')
        if p[_RMAX] < 0:
            raise InvalidParametersError('r_max must be >= 0')
        if not p[_VS] > 0:
            raise InvalidParametersError('v_s must be > 0')
        return np.ascontiguousarray(p)

    def feasible_rows(self, pop: np.ndarray) -> np.ndarray:
        """Validity per row."""
        return _feasible_rows(np.ascontiguousarray(pop, dtype=np.float64))

    def simulate_rows(self, pop: np.ndarray, v: np.ndarray, ok: np.ndarray,
                      out: np.ndarray) -> None:
        """H's output of every valid row (numba kernel)."""
        _simulate_rows(np.ascontiguousarray(pop, dtype=np.float64),
                       np.ascontiguousarray(v, dtype=np.float64), ok, out)

    def map_output(self, params: np.ndarray, alpha: float, delta: float) -> np.ndarray:
        """Parameters of ``alpha * H + delta``: weights scale, the offset maps."""
        p = np.array(params, dtype=np.float64)
        p[:_WL + 1] *= alpha
        p[_CO] = alpha * p[_CO] + delta
        return p

    def map_input(self, params: np.ndarray, a: float, b: float) -> np.ndarray:
        """The loop for ``v = a v_m + b``: command-unit parameters scale, weights divide.

        ``r_max, v_s`` times ``a``, ``v_c -> a v_c + b``, the weights (per
        command unit) over ``a``: a play is positively homogeneous.
        """
        p = np.array(params, dtype=np.float64)
        p[:_WL + 1] /= a
        p[_RMAX] *= a
        p[_VS] *= a
        p[_VC] = a * p[_VC] + b
        return p

    def domains(self, box: LoopBox) -> dict[str, tuple[float, float]]:
        """Weights to the steepest slope, thresholds to the span, saturation 0.01-20 spans."""
        span_v = max(box.span_v, 1e-12)
        w_hi = box.steep * box.slope
        out = {n: (0.0, w_hi) for n in WEIGHT_NAMES + ('w_l',)}
        out.update({'r_max': (0.0, span_v), 'v_s': (0.01 * span_v, 20.0 * span_v),
                    'v_c': (box.v_min, box.v_max),
                    'c_o': (box.u_lo - box.span_u, box.u_hi + box.span_u)})
        return out

    def starts(self, box: LoopBox, width: float | None = None) -> list[np.ndarray]:
        """Loops of width ``width`` (default the measured one) centred in the box.

        Equal or falling weights, each with a linear and a saturating map.
        """
        span_v = max(box.span_v, 1e-12)
        w_loop = box.loop_width if width is None else width
        v_mid = 0.5 * (box.v_min + box.v_max)
        u_mid = 0.5 * (box.u_lo + box.u_hi)
        out = []
        for profile in (np.ones(N_PLAYS), np.linspace(2.0, 0.2, N_PLAYS)):
            w = box.slope * profile / profile.sum()
            for v_s in (20.0 * span_v, 0.5 * span_v):
                out.append(np.concatenate([w, [0.0, max(w_loop, 1e-9 * span_v), v_s, v_mid,
                                               u_mid]]))
        return out

    def inverse(self, params: np.ndarray) -> SmoothInverse:
        """A fresh exact inverse (state on the rising boundary at command 0)."""
        return SmoothInverse(self.check(params))

    def describe(self, params: np.ndarray) -> dict[str, float]:
        """Loop width of the plays in the linear limit, and the saturation's reach."""
        p = self.check(params)
        r = p[_RMAX] * np.arange(N_PLAYS) / (N_PLAYS - 1)
        total = float(p[:N_PLAYS].sum())
        return {'loop_width_cmd': float(2.0 * (p[:N_PLAYS] @ r) / total) if total else 0.0,
                'total_slope': total + float(p[_WL]), 'saturation_cmd': float(p[_VS]),
                'slope_past_saturation': float(p[_WL])}


#: The family the registry lists.
FAMILY = Smooth()
