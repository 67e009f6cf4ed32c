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

"""Basin hopping from the best fit: small random jumps, each polished, kept when better.

The chain is piecewise linear in the command, so its cost is a patchwork of
smooth pieces, and a polish (:func:`~hyst_id.identification.refine.refine`)
stops at the edge of the piece it started on. A fit that is close to the
truth in every parameter but one trade-off (family #163: the loop right to
within 1 %, the backlash 2.6 times too narrow, the bottom line's slope half
the truth's; 1.41 x the true floor) is such a stop, and neither GAASS nor
differential evolution over the whole box lands nearer. Jumps of a few per
cent of the box from it, each polished, cross those edges: on #163 the floor
is reached after 14 jumps, about a second.

Monotonic basin hopping (a jump is kept only when its polish does better),
with its own random stream drawn from the seed. With more than one worker the
next jumps are polished side by side in forked processes, speculatively: each
starts from the fit as it stands, and when one of them improves the fit, the
jumps after it, which started from the old fit, are dropped and made again
from the new one. Jumps are taken and judged in their order, with the same
random steps, so the answer does not depend on the number of workers; the
time does, as far as jumps fail (most do).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np
from threadpoolctl import threadpool_limits

from hyst_id.identification.chains import ChainSpec, er_percent
from hyst_id.identification.global_phase import run_from_fit
from hyst_id.identification.refine import refine
from hyst_id.identification.result import IdentifySettings, SeedRun
from hyst_id.identification.workers import forked_pool
from hyst_id.io.recording import Recording

__all__ = ['hop', 'hop_with_cost', 'HOP_FULL_SAMPLES', 'HOP_MIN', 'HOP_NFEV', 'HOP_RUN_ID',
           'HOP_SCALE']

#: A jump's standard deviation, as a share of each parameter's box width.
HOP_SCALE = 0.02

#: The seed number the hopped run reports (the global phase's are -1, -2, ...).
HOP_RUN_ID = -100

#: Residual evaluations of one jump's polish.
HOP_NFEV = 1500

#: All ``settings.hops`` jumps up to this many samples; on a longer record proportionally
#: fewer, at least :data:`HOP_MIN` (or ``settings.hops`` when that is fewer).
HOP_FULL_SAMPLES = 5000
HOP_MIN = 10


def hop(spec: ChainSpec, rec: Recording, best: SeedRun, settings: IdentifySettings,
        floor_percent: float, run_id: int = HOP_RUN_ID) -> SeedRun | None:
    """Basin hopping from ``best``: the improved run, or ``None`` when no jump did better.

    As :func:`hop_with_cost` without the evaluations spent.
    """
    return hop_with_cost(spec, rec, best, settings, floor_percent, run_id)[0]


def hop_with_cost(spec: ChainSpec, rec: Recording, best: SeedRun, settings: IdentifySettings,
                  floor_percent: float, run_id: int = HOP_RUN_ID,
                  on_jump: Callable[[int, int, float], None] | None = None,
                  n_workers: int = 1) -> tuple[SeedRun | None, int]:
    """Basin hopping from ``best``: the improved run (or ``None``) and the evaluations spent.

    Parameters
    ----------
    spec : ChainSpec
        The chain (its conventions are replaced by the best run's).
    rec : Recording
        What is identified.
    best : SeedRun
        Where to hop from.
    settings : IdentifySettings
        ``hops`` (the most jumps), ``global_factor`` (hopping stops once the
        fit is within this multiple of ``floor_percent``) and ``seeds[0]``
        (the random stream). Nothing is tried unless ``best`` is within
        ``long_runs_within`` x the floor: further off, the misfit is taken
        for physics the chain lacks.
    floor_percent : float
        The estimated noise floor (%e_r).
    run_id : int
        The seed number the run reports; its random stream is drawn from
        ``(settings.seeds[0], run_id)``.
    on_jump : callable, optional
        Called as ``on_jump(done, jumps, er_percent)`` before each jump
        (``done`` jumps made so far, the best %e_r so far) and once at the end
        with ``done == jumps``, for progress displays; it may raise to stop.
    n_workers : int
        Processes polishing jumps side by side (see the module's docstring);
        1, or no safe fork, polishes them one after the other here.

    Returns
    -------
    run : SeedRun or None
        The improved run (its ``nfev`` is every jump's polish), ``None`` when
        no jump did better or nothing was tried.
    nfev : int
        The residual evaluations of every jump's polish, also when none improved.
    """
    if not (settings.refine and settings.hops > 0 and np.isfinite(best.fun)
            and best.er_percent <= settings.long_runs_within * floor_percent):
        return None, 0
    spec = replace(spec, initial=best.initial, hold=best.hold)
    t_s, v, y = rec.t_s, rec.command, rec.measurement
    lo, hi = spec.bounds[:, 0], spec.bounds[:, 1]
    rng = np.random.default_rng([settings.seeds[0], 11, -run_id])
    x, fun = np.asarray(best.x_raw, dtype=float), float(best.fun)
    # a jump's polish costs in proportion to the samples: fewer jumps on a long record
    jumps = min(settings.hops, max(HOP_MIN, int(settings.hops * min(
        1.0, HOP_FULL_SAMPLES / rec.n_samples))))
    steps = rng.normal(0.0, HOP_SCALE, (jumps, x.size))    # one row per jump, in order
    nfev, improved, done = 0, False, 0
    with threadpool_limits(limits=1), forked_pool(n_workers) as pool:
        while done < jumps and er_percent(fun, y) > settings.global_factor * floor_percent:
            # with workers every jump left is queued: polishes differ widely in length
            # (bench/hop_workers.py: on blind #84 the five longest of 100 take about half
            # the time), and a full queue keeps every worker busy past a long one
            batch = range(done, (done + 1) if pool is None else jumps)
            starts = {k: np.clip(x + steps[k] * (hi - lo), lo, hi) for k in batch}
            starts = {k: s for k, s in starts.items() if spec.feasible(s[None, :])[0]}
            polished = ({k: pool.submit(_polish, spec, s, t_s, v, y) for k, s in starts.items()}
                        if pool is not None else {})
            for k in batch:
                if er_percent(fun, y) <= settings.global_factor * floor_percent:
                    break
                if on_jump is not None:
                    on_jump(k, jumps, float(er_percent(fun, y)))
                done = k + 1
                if k not in starts:
                    continue
                x_new, f_new, n = (pool.result(polished[k]) if pool is not None
                                   else _polish(spec, starts[k], t_s, v, y))
                nfev += n
                if f_new < fun * (1.0 - 1e-9):
                    x, fun, improved = x_new, f_new, True
                    break       # the batch's later jumps started from the old fit
            for later in polished.values():
                later.cancel()  # the queued ones; a running one ends unread
    if on_jump is not None:
        on_jump(jumps, jumps, float(er_percent(fun, y)))       # the end of hopping
    if not improved:
        return None, nfev
    run = run_from_fit(spec, rec, x, fun, run_id=run_id, nfev=nfev, nit=0,
                       message='basin hopping from the best run')
    return (run if np.isfinite(run.fun) else None), nfev


def _polish(spec: ChainSpec, start: np.ndarray, t_s: np.ndarray, v: np.ndarray,
            y: np.ndarray) -> tuple[np.ndarray, float, int]:
    """One jump's polish (module level: what a worker process runs)."""
    return refine(spec, start, t_s, v, y, max_nfev=HOP_NFEV)
