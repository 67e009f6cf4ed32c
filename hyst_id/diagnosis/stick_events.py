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

"""Stick-slip fitted from its events: plateaus, slips, and the demand between them.

Why not least squares on the simulated output? A stick-slip staircase is
phase sensitive: once one slip happens a sample early or late, the
simulated steps stay out of step with the measured ones for the rest of the
record (every later slip is decided relative to the position where the
actuator last stuck), so the simulation error is flat and high everywhere
except in a hole around the exact parameters, of about 0.3 % in the band
and in every chain parameter. Neither a grid nor local least squares finds
that hole from the baseline.

The events make it a smooth problem instead. With the measurement cut into
plateaus at its jumps (:func:`plateaus`), the two-band stick-slip model
``|x - x_stuck| <= band: stay; else slip to x`` says, for the demanded
position ``x = B(H(v))`` of the chain:

* at every slip the actuator lands on the demand: plateau level ``L_k = a
  x(e_k) + b`` (the calibration ``a, b`` is profiled);
* while stuck the demand stays within the band of the stuck position, and at
  the next slip it is beyond it: ``|x(j) - x(e_k)| <= band`` inside plateau
  ``k``, ``|x(e_{k+1}) - x(e_k)| > band`` (one-sided, hinge residuals);
* the first plateau's stuck position is the unknown initial state.

These residuals are continuous in the chain's parameters (the slip samples
are measured, not simulated), so bounded least squares converges. A chain
and band that satisfy every condition reproduce the measured slip samples
exactly when simulated (by induction over the slips), which is what lines
the staircase up. Band and initial state are finally set to the middle of
the interval the conditions leave, for margin on held-out data.

The dynamic band of the common two-parameter model (the actuator slips to
``dynamic`` short of the demand) is exactly equivalent to a wider backlash
ahead of a zero dynamic band, so it is not identifiable from the record and
the chain's backlash carries it; the band fitted here is the slip jump.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from numba import njit
import numpy as np
from scipy.optimize import least_squares

from hyst_id.diagnosis.plateaus import Plateaus, plateaus
from hyst_id.identification.chains import ChainSpec

__all__ = ['StickSlipFit', 'bands_from_demand', 'fit_stick_slip_events', 'stick_intervals']


@njit(cache=True)
def _hinge(x: np.ndarray, edges: np.ndarray, band: float, stuck0: float, margin: float,
           out: np.ndarray) -> int:
    """Violations of the stick and slip conditions (by less than ``margin``, too).

    Returns how many entries of ``out`` were written.
    """
    m = 0
    n_seg = edges.shape[0] - 1
    for k in range(n_seg):
        a = edges[k]
        b = edges[k + 1]
        ref = stuck0 if k == 0 else x[a]
        for j in range(a + 1, b):
            g = abs(x[j] - ref)
            out[m] = g - band + margin if g > band - margin else 0.0
            m += 1
        if k + 1 < n_seg:
            g = abs(x[b] - ref)
            out[m] = band + margin - g if g < band + margin else 0.0
            m += 1
    return m


def stick_intervals(x: np.ndarray, edges: np.ndarray, levels: np.ndarray,
                    gain: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Band and initial stuck position that the stick and slip conditions allow.

    Parameters
    ----------
    x : numpy.ndarray
        Demanded position ``B(H(v))``.
    edges, levels : numpy.ndarray
        Plateaus of the measurement (:class:`Plateaus`).
    gain : float
        Measurement per position (its sign gives the direction of the first slip).

    Returns
    -------
    tuple
        ``((band_lo, band_hi), (stuck0_lo, stuck0_hi))`` in position units; an
        interval is empty (lo > hi) when the conditions conflict.
    """
    band_lo, band_hi = 0.0, np.inf
    for k in range(1, levels.size):
        lo_, hi_ = edges[k], edges[k + 1]
        ref = x[lo_]
        if hi_ - lo_ > 1:
            band_lo = max(band_lo, float(np.max(np.abs(x[lo_ + 1:hi_] - ref))))
        if k + 1 < levels.size:
            band_hi = min(band_hi, float(abs(x[hi_] - ref)))
    band = 0.5 * (band_lo + band_hi) if band_lo < band_hi else band_lo
    held = x[1:edges[1]] if edges[1] > 1 else x[:1]
    lo0, hi0 = float(np.max(held)) - band, float(np.min(held)) + band
    if levels.size > 1:
        slip = float(x[edges[1]])
        if (levels[1] - levels[0]) * gain > 0:
            hi0 = min(hi0, slip - band)
        else:
            lo0 = max(lo0, slip + band)
    return (band_lo, band_hi), (lo0, hi0)


@dataclass(frozen=True)
class StickSlipFit:
    """A chain and stick-slip band that reproduce the measured slips.

    Attributes
    ----------
    chain : numpy.ndarray
        Position chain parameters (H and B).
    band_fraction : float
        Band (slip jump) as a fraction of the training travel of ``B(H(v))``.
    offset_fraction : float
        Initial stuck position minus the initial demand, same scale.
    cost : float
        Level plus condition residual sum of squares (measurement units).
    violations : int
        Samples that break a stick or slip condition.
    """

    chain: np.ndarray
    band_fraction: float
    offset_fraction: float
    cost: float
    violations: int


class _EventResidual:
    """Residuals of the event conditions for ``q = (chain, band, offset)``."""

    def __init__(self, spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, plat: Plateaus,
                 weight: float) -> None:
        self.spec = spec
        self.t, self.v = t_s, v
        self.plat = plat
        self.w = np.sqrt(np.diff(plat.edges).astype(float))
        self.weight = weight
        self.margin = 1e-3
        self.buf = np.empty(t_s.size + 1)
        self.size = plat.levels.size + t_s.size
        self.n_chain = len(spec.names)

    def calibration(self, x: np.ndarray) -> np.ndarray:
        """``(a, b)`` of the plateau levels against the demand at the slips."""
        e = self.plat.edges[1:-1]
        w = self.w[1:]
        design = np.column_stack([x[e], np.ones(e.size)]) * w[:, None]
        coef, *_ = np.linalg.lstsq(design, self.plat.levels[1:] * w, rcond=None)
        return coef

    @property
    def median_jump(self) -> float:
        """Median step between plateau levels, measurement units."""
        return float(np.median(np.abs(np.diff(self.plat.levels))))

    def restart_band(self, q: np.ndarray) -> np.ndarray:
        """``q`` with band and initial offset re-estimated for its chain.

        Band: the median measured jump in position units; initial stuck
        position: the first plateau's level.
        """
        chain = q[:self.n_chain]
        if not self.spec.feasible(chain[None, :])[0]:
            return q
        x = self.spec.signal(chain, self.t, self.v)
        travel = float(np.ptp(x)) or 1e-12
        a, b = self.calibration(x)
        if a == 0:
            return q
        out = np.array(q, dtype=float)
        out[-2] = self.median_jump / abs(a) / travel
        out[-1] = ((self.plat.levels[0] - b) / a - x[0]) / travel
        return out

    def violations(self, q: np.ndarray) -> int:
        """Stick and slip conditions that ``q`` breaks (no margin)."""
        margin, self.margin = self.margin, 0.0
        try:
            return int(np.count_nonzero(self(q)[self.plat.levels.size:]))
        finally:
            self.margin = margin

    def __call__(self, q: np.ndarray) -> np.ndarray:
        chain = q[:self.n_chain]
        if not self.spec.feasible(chain[None, :])[0]:
            return np.full(self.size, 1e3 * max(self.plat.scatter, 1e-12))
        x = self.spec.signal(chain, self.t, self.v)
        travel = float(np.ptp(x)) or 1e-12
        a, b = self.calibration(x)
        e = self.plat.edges[1:-1]
        lv = self.plat.levels
        r_levels = (lv[1:] - a * x[e] - b) * self.w[1:]
        stuck0 = x[0] + q[-1] * travel
        r_first = (lv[0] - a * stuck0 - b) * self.w[0]
        band = q[-2] * travel
        m = _hinge(x, self.plat.edges, band, stuck0, self.margin * band, self.buf)
        out = np.zeros(self.size)
        out[0] = r_first
        out[1:lv.size] = r_levels
        out[lv.size:lv.size + m] = self.weight * abs(a) * self.buf[:m]
        return out


def _narrowed(chain: np.ndarray, jump: float, share: float) -> np.ndarray | None:
    """The chain with its backlash narrowed by ``share * jump`` (demand units) per side."""
    c = np.array(chain, dtype=float)
    h = share * jump / c[8]
    c[9] += h
    c[10] -= h
    return c if c[9] < c[10] else None


def fit_stick_slip_events(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
                          sigma: float, chains: Sequence[np.ndarray], *,
                          max_nfev: int = 3000, weight: float = 3.0,
                          shares: Sequence[float] = (0.5, 0.0),
                          keep: int = 64) -> list[StickSlipFit]:
    """Fit chain, band and initial state to the plateaus and slips of ``y``.

    Parameters
    ----------
    spec : ChainSpec
        The position chain (H and B), in the command units of ``v``.
    t_s, v, y : numpy.ndarray
        Training samples: times, command, measured position.
    sigma : float
        Measurement noise standard deviation.
    chains : sequence of numpy.ndarray
        Chain starts (the baseline fit, data-built starts). Each is tried with
        its backlash narrowed by ``shares`` of the measured slip jump (a fit
        without stiction has widened it by about half the jump).
    max_nfev : int
        Residual evaluations per least-squares run.
    weight : float
        Weight of the stick and slip conditions against the plateau levels.
    shares : sequence of float
        Backlash narrowings to start from (fractions of the slip jump).
    keep : int
        Distinct plateau-level fits (best first) carried on to the stick and
        slip conditions: the levels alone, a sparse chain fit, have several
        basins, and their cost does not tell the right one.

    Returns
    -------
    list of StickSlipFit
        Fits that break no condition first, then by cost. Empty when ``y`` is
        not a staircase of flat plateaus.
    """
    plat = plateaus(y, sigma)
    if not plat.is_staircase(sigma):
        return []
    res = _EventResidual(spec, t_s, v, plat, weight)
    lo = np.concatenate([spec.bounds[:, 0], [1e-4, -0.2]])   # as the stiction block
    hi = np.concatenate([spec.bounds[:, 1], [0.2, 0.2]])
    eps = 1e-9 * (hi - lo)
    lo, hi = lo + eps, hi - eps
    levels = []
    for q0 in _starts(spec, res, chains, shares):
        q = _least_squares(res, np.clip(q0, lo, hi), lo, hi, 0.0, max_nfev)
        if q is not None:
            levels.append((float(np.sum(res(q) ** 2)), q))
    fits = []
    for q in _distinct(levels, keep):
        q = _solve(res, np.clip(res.restart_band(q), lo, hi), lo, hi, weight, max_nfev)
        if q is not None and spec.feasible(q[None, :-2])[0]:
            fits.append(_finish(spec, res, q, t_s, v, plat))
    fits.sort(key=lambda f: (f.violations > 0, f.cost))
    return fits


def _distinct(levels: list[tuple[float, np.ndarray]], keep: int) -> list[np.ndarray]:
    """The ``keep`` best level fits, one per basin (equal costs are one basin)."""
    out: list[np.ndarray] = []
    seen: list[float] = []
    for cost, q in sorted(levels, key=lambda f: f[0]):
        if any(abs(cost - c) <= 1e-4 * max(c, 1e-300) for c in seen):
            continue
        seen.append(cost)
        out.append(q)
        if len(out) >= keep:
            break
    return out


def _starts(spec: ChainSpec, res: _EventResidual, chains: Sequence[np.ndarray],
            shares: Sequence[float]) -> list[np.ndarray]:
    """Feasible ``(chain, band, offset)`` starts: the chains with narrowed backlashes."""
    out = []
    for chain in chains:
        chain = np.asarray(chain, dtype=float)
        x0 = spec.signal(chain, res.t, res.v)
        travel = float(np.ptp(x0)) or 1.0
        jump = res.median_jump / abs(res.calibration(x0)[0] or 1.0)
        for c in (_narrowed(chain, jump, share) for share in shares):
            if c is None:
                continue
            c = np.clip(c, spec.bounds[:, 0], spec.bounds[:, 1])
            if spec.feasible(c[None, :])[0]:
                out.append(np.concatenate([c, [jump / travel, 0.0]]))
    return out


def _least_squares(res: _EventResidual, q: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   weight: float, max_nfev: int) -> np.ndarray | None:
    """One bounded least-squares run at a condition weight (None when it fails)."""
    saved, res.weight = res.weight, weight
    try:
        return least_squares(res, np.clip(q, lo, hi), bounds=(lo, hi), method='trf',
                             max_nfev=max_nfev).x
    except (ValueError, np.linalg.LinAlgError):
        return None
    finally:
        res.weight = saved


def _solve(res: _EventResidual, q0: np.ndarray, lo: np.ndarray, hi: np.ndarray,
           weight: float, max_nfev: int) -> np.ndarray | None:
    """The stick and slip conditions, weighted up until none is broken.

    Starts from a fit of the plateau levels alone (with many conditions
    broken at the start their hinges pull the chain every way and least
    squares stalls). One broken condition is one slip a sample early or
    late, which puts the simulated staircase out of step for good; the
    levels can give a little for it.
    """
    q = q0
    for factor in (1.0, 10.0, 100.0):
        q = _least_squares(res, q, lo, hi, weight * factor, max_nfev)
        if q is None or res.violations(q) == 0:
            break
    return q


def _finish(spec: ChainSpec, res: _EventResidual, q: np.ndarray, t_s: np.ndarray,
            v: np.ndarray, plat: Plateaus) -> StickSlipFit:
    """Band and initial state in the middle of what the conditions allow."""
    chain = q[:-2]
    r = res(q)
    x = spec.signal(chain, t_s, v)
    travel = float(np.ptp(x)) or 1e-12
    a = res.calibration(x)[0]
    (b_lo, b_hi), (s_lo, s_hi) = stick_intervals(x, plat.edges, plat.levels, a)
    band = 0.5 * (b_lo + b_hi) if b_lo < b_hi else q[-2] * travel
    stuck0 = 0.5 * (s_lo + s_hi) if s_lo <= s_hi else x[0] + q[-1] * travel
    return StickSlipFit(chain=np.array(chain), band_fraction=band / travel,
                        offset_fraction=(stuck0 - x[0]) / travel, cost=float(r @ r),
                        violations=res.violations(q))


def bands_from_demand(x: np.ndarray, y: np.ndarray, sigma: float
                      ) -> tuple[float, float] | None:
    """Static and dynamic band of stick-slip when the demanded position is known.

    For a simulator whose actuator is taken as it is (``x`` its demanded
    position, ``y`` a measured position in the same units, with an unknown
    offset): at a slip the actuator lands ``dynamic`` short of the demand,
    ``L_k = x(e_k) - sign_k dynamic + offset`` (linear least squares), and
    the static band lies between the largest demand-to-stuck gap while stuck
    and the smallest one at a slip. The backlash is fixed here, so the
    dynamic band is identifiable, unlike in :func:`fit_stick_slip_events`.

    Returns
    -------
    tuple of float or None
        ``(static_band, dynamic_band)`` in position units, or None when ``y``
        is not a staircase.
    """
    plat = plateaus(y, sigma)
    if not plat.is_staircase(sigma):
        return None
    e = plat.edges[1:-1]
    sign = np.sign(np.diff(plat.levels))
    w = np.sqrt(np.diff(plat.edges)[1:].astype(float))
    design = np.column_stack([-sign, np.ones(e.size)]) * w[:, None]
    (dynamic, offset), *_ = np.linalg.lstsq(design, (plat.levels[1:] - x[e]) * w, rcond=None)
    dynamic = max(float(dynamic), 0.0)
    stuck = np.concatenate([[x[0]], x[e] - sign * dynamic])
    lo, hi = 0.0, np.inf
    for k in range(stuck.size):
        a, b = plat.edges[k], plat.edges[k + 1]
        if b - a > 1:
            lo = max(lo, float(np.max(np.abs(x[a + 1:b] - stuck[k]))))
        if k + 1 < stuck.size:
            hi = min(hi, float(abs(x[b] - stuck[k])))
    static = 0.5 * (lo + hi) if lo < hi else lo
    if not static > dynamic:
        return None
    return static, dynamic
