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

"""The global phase of :func:`~hyst_id.identification.driver.identify`.

GAASS contracts its search space around its best chromosomes, so when every
seed starts in the same wrong basin they all stay there. After the seeds,
while the best fit stays above ``settings.global_factor`` times the noise
floor, runs of scipy's differential evolution over the whole box (its large
population keeps all of it in play), each refined, leave that basin: first
one per initial state / sensor hold convention (best ranked first: the
ranking is made from data-built starts and can be wrong), then, while the
fit is within :data:`LONG_RUNS_WITHIN` of the floor, runs with other random
streams and three times the evaluations under the conventions of the best
fit so far.

The runs go in rounds of two (:data:`ROUND`), in parallel processes when
there are workers; the schedule and every run's random stream depend only on
the recording and the settings, never on the number of workers, so the
answer is the same on a machine with another core count. Measured on the
reference family (``bench/generalisation.py``, ``docs/model.md``).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np
from threadpoolctl import threadpool_limits

from hyst_id.identification.chains import ChainSpec, er_percent
from hyst_id.identification.gauge import canonical_gauge, output_sign
from hyst_id.identification.refine import refine
from hyst_id.identification.result import IdentifySettings, SeedRun
from hyst_id.identification.workers import map_in_processes, WorkersStopped
from hyst_id.io.recording import Recording

__all__ = ['global_phase', 'global_phases', 'LONG_RUNS_WITHIN', 'ROUND', 'run_from_fit']

#: Runs per round of the global phase (fixed, whatever the number of workers).
ROUND = 2

#: Evaluations of a run after the convention sweep, as a multiple of ``global_evals``.
_LONG_RUN = 3

#: The longer runs only while the best fit is within this multiple of the floor: further
#: off, what is missing is more likely physics the chain lacks than a trap (the shared real
#: recordings end at 44-108 x: bench/real_recordings.py). On the
#: reference family the traps they got out of were at 1.17-3.65 x before them (#84, #40,
#: #47, #2, #170 and #44 at 3.65 x, which 1.5 had left out:
#: docs/data/generalisation_misses_long_runs_4x.jsonl).
LONG_RUNS_WITHIN = IdentifySettings.long_runs_within   # the default; per call: the settings


def global_phase(spec: ChainSpec, rec: Recording, settings: IdentifySettings,
                 seed: int, run_id: int = -1, evals: int | None = None,
                 subset: np.ndarray | None = None,
                 should_stop: Callable[[], bool] | None = None) -> SeedRun:
    """One differential-evolution run over the whole box, refined: seed ``run_id``.

    ``evals`` (default ``settings.global_evals``) bounds its evaluations
    (popsize 15 per parameter, ``tol = 0``); the refinement adds
    ``refine_max_nfev``. Its random stream is drawn from ``(seed, run_id)``.
    On a long record the search sees the sample indices ``subset``
    (:func:`~hyst_id.identification.incumbent.search_subset`); the refinement
    and the returned cost use every sample. ``should_stop`` (in this
    process) is looked at after every generation; when it holds,
    :class:`~hyst_id.identification.workers.WorkersStopped` is raised.
    """
    from scipy.optimize import differential_evolution
    t_s, v, y = rec.t_s, rec.command, rec.measurement
    cost = spec.cost_function(*((t_s, v, y) if subset is None else
                                (t_s[subset], v[subset], y[subset])))
    popsize = 15
    evals = settings.global_evals if evals is None else int(evals)
    maxiter = max(1, evals // (popsize * spec.n_params) - 1)
    with threadpool_limits(limits=1):
        res = differential_evolution(lambda x: cost(np.ascontiguousarray(x.T)), spec.bounds,
                                     maxiter=maxiter, popsize=popsize, tol=0.0, atol=0.0,
                                     polish=False, rng=np.random.default_rng(  # -1: as before
                                         [seed, 7] if run_id == -1 else [seed, 7, -run_id]),
                                     vectorized=True, updating='deferred',
                                     callback=None if should_stop is None else
                                     _stop_callback(should_stop))
        if should_stop is not None and should_stop():
            raise WorkersStopped('stopped on request in the global phase')
        x_raw, fun = np.asarray(res.x, dtype=float), float(res.fun)
        if subset is not None:
            fun = float(spec.cost_function(t_s, v, y)(x_raw[None, :])[0])
        x_ref, fun_ref, nfev_ref = refine(spec, x_raw, t_s, v, y,
                                          max_nfev=settings.refine_max_nfev)
    if fun_ref < fun:
        x_raw, fun = x_ref, fun_ref
    return run_from_fit(spec, rec, x_raw, fun, run_id=run_id,
                        nfev=(int(res.nit) + 1) * popsize * spec.n_params + int(nfev_ref),
                        nit=int(res.nit), message='differential evolution (global phase)')


def _stop_callback(should_stop: Callable[[], bool]) -> Callable:
    """A ``differential_evolution`` callback that halts it once ``should_stop()`` holds."""
    def callback(intermediate_result) -> bool:
        return bool(should_stop())
    return callback


def run_from_fit(spec: ChainSpec, rec: Recording, x_raw: np.ndarray, fun: float, *,
                 run_id: int, nfev: int, nit: int, message: str) -> SeedRun:
    """A fit of the global phase or of hopping as a :class:`SeedRun`, in the canonical gauge.

    A fit whose calibration gain is zero (no output left to scale) gets an
    infinite cost, so that no comparison keeps it.
    """
    t_s, v, y = rec.t_s, rec.command, rec.measurement
    k, b = spec.fit_calibration(x_raw, t_s, v, y)
    x = canonical_gauge(x_raw, (k, b), spec.family) if k != 0 else x_raw
    return SeedRun(seed=run_id, x_raw=x_raw, x=x, sign=output_sign((k, b)) if k != 0 else 1.0,
                   fun=fun if k != 0 else np.inf, er_percent=float(er_percent(fun, y)),
                   er_gaass_percent=float('nan'), nfev=int(nfev), nit=int(nit),
                   best_history=np.zeros(0), message=message, initial=spec.initial,
                   hold=spec.hold)


def global_phases(spec: ChainSpec, others: list[ChainSpec], rec: Recording,
                  settings: IdentifySettings, best: SeedRun, floor_percent: float,
                  n_workers: int = 1, should_stop: Callable[[], bool] | None = None,
                  subset: np.ndarray | None = None,
                  on_run: Callable[[SeedRun], None] | None = None) -> list[SeedRun]:
    """The global phase's runs that improved on ``best``, in the order they did.

    Parameters
    ----------
    spec : ChainSpec
        The chain (its conventions are replaced per run).
    others : list of ChainSpec
        The chain under the other conventions, best ranked first.
    rec : Recording
        What is identified.
    settings : IdentifySettings
        ``global_evals``, ``global_factor``, ``global_runs`` and the refinement's budget.
    best : SeedRun
        The best run of the seeds.
    floor_percent : float
        The estimated noise floor (%e_r).
    n_workers : int
        Processes for a round's runs (results do not depend on it).
    should_stop : callable, optional
        As for :func:`~hyst_id.identification.workers.map_in_processes`; a run
        in this process looks at it after each generation.
    subset : numpy.ndarray, optional
        Sample indices the searches see on a long record (:func:`global_phase`).
    on_run : callable, optional
        Called with every run as its round ends (it may raise to stop).
    """
    if not (settings.refine and settings.global_evals > 0 and settings.global_runs > 0):
        return []
    sweep, seen = [], set()
    for s in [replace(spec, initial=best.initial, hold=best.hold)] + list(others):
        if (s.initial, s.hold) not in seen:
            seen.add((s.initial, s.hold))
            sweep.append(s)
    improved: list[SeedRun] = []
    k = 0
    while k < settings.global_runs and best.er_percent > settings.global_factor * floor_percent:
        tasks = []
        for j in range(k, min(k + ROUND, settings.global_runs)):
            if j < len(sweep):
                tasks.append((sweep[j], rec, settings, settings.seeds[0], -1 - j, None,
                              subset))
            elif best.er_percent <= settings.long_runs_within * floor_percent:
                # other streams, longer, under the best fit's conventions
                phase = replace(spec, initial=best.initial, hold=best.hold)
                tasks.append((phase, rec, settings, settings.seeds[0], -1 - j,
                              _LONG_RUN * settings.global_evals, subset))
        if not tasks:
            break
        k += len(tasks)
        if n_workers > 1 and len(tasks) > 1:
            results = map_in_processes(global_phase, tasks, min(n_workers, len(tasks)),
                                       should_stop=should_stop)
        else:
            results = [global_phase(*t, should_stop=should_stop) for t in tasks]
        for run in results:        # in task order: ties go to the earlier run
            if on_run is not None:
                on_run(run)
            if run.fun < best.fun:
                improved.append(run)
                best = run
    return improved
