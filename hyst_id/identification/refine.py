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

"""Local refinement after GAASS: bounded least squares from the best chromosome.

GAASS finds the basin; a derivative-based polish finds its bottom far more
cheaply than more generations would. The residual is the variable-projection
one (the affine calibration re-fitted for every evaluation when profiled),
and ``scipy.optimize.least_squares`` (trust-region reflective, box bounds =
the search domains) minimises it with finite-difference Jacobians.
Candidates that violate the loop constraints get a large constant residual,
so the trust region shrinks back into the feasible set. The chain is
piecewise linear in the command, so the residual is piecewise smooth in the
parameters: the polish is restarted once from its own end point, which gets
it past kinks where a first run stalls. The points of one finite-difference
Jacobian are evaluated together (H's kernel run once over them, through
``least_squares``'s ``workers``), with the very numbers one at a time would
give: only the Python calls per point go.
"""

from __future__ import annotations

import inspect
from typing import Callable, Iterable

import numpy as np
from scipy.optimize import least_squares

from hyst_id.identification.chains import ChainSpec

__all__ = ['refine', 'residual_scale', 'SMALL_RMS']

#: Below this RMS of the measurement the polish works on the residual divided by a power of
#: two that brings the RMS into [1, 2) (exact: the same fit in other units). least_squares
#: stops where its scaled gradient falls below an absolute ``gtol`` (1e-8), which the
#: residuals of a measurement in tiny units reach at once: a review's piezo example in metres
#: (x 1e-6, x 1e-7) ended at %e_r 5.675 and 5.760 against 5.652, and at 5.652 with it
#: (``bench/unit_scales.py``). Above it nothing changes (the documented families'
#: measurements have RMS 0.04 and more).
SMALL_RMS = 1e-2


def residual_scale(y: np.ndarray) -> float:
    """The power of two the polish divides residuals by (1.0 unless RMS < :data:`SMALL_RMS`)."""
    rms = float(np.sqrt(np.mean(np.square(y)))) if np.size(y) else 0.0
    if not 0.0 < rms < SMALL_RMS:
        return 1.0
    return float(2.0 ** np.floor(np.log2(rms)))


_TAKES_WORKERS = 'workers' in inspect.signature(least_squares).parameters


def refine(spec: ChainSpec, x0: np.ndarray, t_s: np.ndarray, command: np.ndarray,
           measurement: np.ndarray, *, max_nfev: int = 4000,
           restarts: int = 1) -> tuple[np.ndarray, float, int]:
    """Polish a parameter vector by bounded least squares.

    Parameters
    ----------
    spec : ChainSpec
        Chain to fit; its bounds are the box.
    x0 : numpy.ndarray
        Start (a feasible GAASS result).
    t_s, command, measurement : numpy.ndarray
        The recording.
    max_nfev : int
        Residual evaluations allowed in total.
    restarts : int
        Extra runs started from the previous end point.

    Returns
    -------
    x : numpy.ndarray
        Refined parameters (``x0`` when nothing better was found).
    fun : float
        Cost J at ``x``.
    nfev : int
        Residual evaluations used.
    """
    # 1.0 but for a measurement in tiny units whose calibration is profiled (a fixed one,
    # the paper frame's, is in the measurement's own units)
    scale = residual_scale(measurement) if spec.profiled else 1.0
    y = np.ascontiguousarray(measurement, dtype=np.float64) / scale
    cost = spec.cost_function(t_s, command, y)
    lo, hi = spec.bounds[:, 0], spec.bounds[:, 1]
    penalty = np.full(y.shape[0], np.sqrt(np.sum(y ** 2) / y.shape[0]) * 10.0)
    feasible_residual = spec.residual_function(t_s, command, y)
    nfev = 0

    def residual(x: np.ndarray) -> np.ndarray:
        nonlocal nfev
        nfev += 1
        if not spec.feasible(x[None, :])[0]:
            return penalty
        return feasible_residual(x)

    def jacobian_columns(_fun: Callable, steps: Iterable[np.ndarray]) -> list[np.ndarray]:
        """The finite differences' evaluations, H run once for all (scipy's ``workers``)."""
        nonlocal nfev
        pop = np.array(list(steps), dtype=np.float64)
        nfev += pop.shape[0]
        ok = spec.feasible(pop)
        return [penalty if r is None else r for r in feasible_residual.rows(pop, ok)]

    # scipy >= 1.16 hands the finite differences' points to a map-like ``workers`` at once
    batched = {'workers': jacobian_columns} if _TAKES_WORKERS else {}
    x_best = np.clip(np.asarray(x0, dtype=np.float64), lo, hi)
    f_best = float(cost(x_best[None, :])[0])
    for _ in range(1 + max(0, restarts)):
        budget = max_nfev - nfev
        if budget < 4 * (spec.n_params + 1):
            break
        try:
            sol = least_squares(residual, x_best, bounds=(lo, hi), method='trf',
                                x_scale='jac', max_nfev=budget, **batched)
        except (ValueError, np.linalg.LinAlgError):
            break
        f_new = float(cost(sol.x[None, :])[0])
        if not f_new < f_best * (1.0 - 1e-9):
            break
        x_best, f_best = sol.x, f_new
    return x_best, f_best * scale * scale, nfev      # the cost J (a sum of squares) unscaled
