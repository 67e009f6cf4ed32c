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

"""Identification of a chain from a recording: GAASS over seeds, refinement, noise floor.

``identify(recording)`` runs GAASS once per seed (in parallel processes),
optionally polishes each best chromosome with a bounded local least-squares
fit (:mod:`hyst_id.identification.refine`), brings every result into the canonical gauge
(:mod:`hyst_id.identification.gauge`) so seeds can be compared and averaged, and returns an
:class:`Identification` holding all of it, the paper's %e_r (Eq. 7) and the
noise floor.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable

import numpy as np
from threadpoolctl import threadpool_limits

from hyst_id.errors import IdentificationError, InvalidParametersError
from hyst_id.identification.chains import chain_spec, ChainSpec, er_percent
from hyst_id.identification.domains import domains_from_data
from hyst_id.identification.gauge import canonical_gauge, output_sign
from hyst_id.identification.global_phase import global_phase, global_phases
from hyst_id.identification.hop import HOP_RUN_ID, hop_with_cost
from hyst_id.identification.incumbent import (
    best_polished,
    choose_conventions,
    CONVENTION_GAIN,
    data_incumbent,
    rank_conventions,
    search_subset,
)
from hyst_id.identification.loose_phase import loose_retry
from hyst_id.identification.quality import assess
from hyst_id.identification.refine import refine
from hyst_id.identification.result import Identification, IdentifySettings, SeedRun
from hyst_id.identification.start_state import keep_refit, left_out_note, refit_start
from hyst_id.identification.workers import map_in_processes, n_processes, WorkersStopped
from hyst_id.io.recording import Recording, roundoff_probe, validate_recording
from hyst_id.signals.noise import noise_floor_percent
from hyst_id.solvers.gaass import GaassSolver

__all__ = ['choose_conventions', 'data_incumbent', 'global_phase', 'identify', 'rank_conventions',
           'run_seed', 'search_subset', 'summarise']


def run_seed(spec: ChainSpec, t_s: np.ndarray, command: np.ndarray, measurement: np.ndarray,
             settings: IdentifySettings, seed: int, floor_percent: float = 0.0,
             on_generation: Callable[[int, int, int, float], Any] | None = None,
             incumbent: tuple[np.ndarray, float, int] | None = None,
             alternates: tuple[ChainSpec, ...] = ()) -> SeedRun:
    """Identify with one seed: GAASS, refinement, restarts; picklable for workers.

    The first GAASS run uses ``seed`` itself (the paper's procedure). With
    refinement on, the ``refine_top`` best distinct chromosomes of the final
    population are polished and the best kept; while %e_r stays above
    ``restart_factor`` times the noise floor, GAASS restarts with a seed
    derived from ``(seed, restart)``, up to ``restarts`` times, or until
    ``restart_patience`` restarts in a row gain less than 1 % while %e_r is
    above 1.5 x the floor.
    ``on_generation(seed, restart, generation, er_percent)`` is called after
    every GAASS generation (it may raise to abandon the seed).
    ``incumbent`` ``(x, cost, nfev)`` (the best polished data-built start,
    :func:`data_incumbent`) is the result to beat from the start: a seed
    whose GAASS runs all end in a worse basin returns it; its evaluations
    are counted in this seed's ``nfev``.
    ``alternates`` (the same chain under other initial states or sensor
    holds, :func:`rank_conventions`) are searched in turn by the restarts
    after the first: a recording whose conventions the data-built start
    misjudged still reaches its basin. :func:`identify` rotates their order
    from seed to seed, so that the first restarts of the seeds cover them
    all. The run reports the conventions of the chain it ends with.
    """
    with threadpool_limits(limits=1):   # parallelism is over seeds, not inside BLAS
        return _run_seed(spec, t_s, command, measurement, settings, seed, floor_percent,
                         on_generation, incumbent, alternates)


def _run_seed(spec: ChainSpec, t_s: np.ndarray, command: np.ndarray, measurement: np.ndarray,
              settings: IdentifySettings, seed: int, floor_percent: float,
              on_generation: Callable[[int, int, int, float], Any] | None,
              incumbent: tuple[np.ndarray, float, int] | None = None,
              alternates: tuple[ChainSpec, ...] = ()) -> SeedRun:
    specs = (spec,) + tuple(alternates)
    sub = search_subset(command, settings.search_samples) if settings.refine else None
    search = (t_s, command, measurement) if sub is None else \
        (t_s[sub], command[sub], measurement[sub])
    costs = [s.cost_function(*search) for s in specs]
    best_spec = spec
    sum_sq = float(np.sum(measurement ** 2))
    target = None
    if settings.er_bound_percent is not None:
        target = (settings.er_bound_percent / 100.0) ** 2 * sum_sq
    search_target = None if target is None else target * float(np.sum(search[2] ** 2)) / sum_sq
    good_enough = (settings.restart_factor * floor_percent / 100.0) ** 2 * sum_sq
    best_x, best_fun, er_ga, nfev, nit, history, message = None, np.inf, np.nan, 0, 0, None, ''
    if incumbent is not None:
        best_x, best_fun, nfev = np.asarray(incumbent[0], dtype=float), incumbent[1], incumbent[2]
    stalled = 0
    for restart in range(1 + (settings.restarts if settings.refine else 0)):
        rng = seed if restart == 0 else np.random.default_rng([seed, restart])
        which = 0 if restart == 0 or len(specs) == 1 else 1 + (restart - 1) % (len(specs) - 1)
        here, cost = specs[which], costs[which]
        solver = GaassSolver(cost, here.bounds, feasible=here.feasible,
                             pop_size=settings.pop_size, maxiter=settings.maxiter, c=settings.c,
                             xi=settings.xi, target=search_target, rng=rng,
                             callback=_report(on_generation, seed, restart, search[2]))
        res = solver.solve()
        nfev += int(res.nfev)
        nit += int(res.nit)
        if restart == 0:
            er_ga = float(er_percent(res.fun, search[2]))
            history, message = np.asarray(res.history.best_fun, dtype=float), str(res.message)
        candidates = [(np.asarray(res.x, dtype=float), float(res.fun))]  # refine off: all data
        if settings.refine:
            candidates = []
            starts = _distinct_best(res.population, res.population_fun, settings.refine_top)
            if sub is not None:         # polish all on the subset, the best on every sample
                x_sub, nfev_sub = best_polished(here, starts, search, settings.refine_max_nfev)
                starts, nfev = [x_sub], nfev + nfev_sub
            for x0 in starts:
                x_ref, fun_ref, nfev_ref = refine(here, x0, t_s, command, measurement,
                                                  max_nfev=settings.refine_max_nfev)
                nfev += nfev_ref
                candidates.append((x_ref, fun_ref))
        previous = best_fun
        for x, fun in candidates:
            # another convention must gain clearly, as in rank_conventions
            if fun < (best_fun if here is best_spec else CONVENTION_GAIN * best_fun):
                best_x, best_fun, best_spec = x, fun, here
        if best_fun <= good_enough or (target is not None and best_fun <= target):
            break
        # far above the floor the model cannot reach it (unmodelled physics): stop once
        # restarts stop gaining; near it a later restart often finds the exact basin
        far = best_fun > (_STALL_FLOOR_FACTOR * floor_percent / 100.0) ** 2 * sum_sq
        stalled = stalled + 1 if restart and far and best_fun > 0.99 * previous else 0
        if stalled >= settings.restart_patience:
            break
    k, b = best_spec.fit_calibration(best_x, t_s, command, measurement)
    if k == 0:
        raise IdentificationError('the best chain output does not vary: the measurement '
                                  'shows no response to the command')
    x = canonical_gauge(best_x, (k, b), best_spec.family)
    return SeedRun(seed=int(seed), x_raw=best_x, x=x, sign=output_sign((k, b)),
                   fun=float(best_fun),
                   er_percent=float(er_percent(best_fun, measurement)), er_gaass_percent=er_ga,
                   nfev=nfev, nit=nit, best_history=history, message=message,
                   initial=best_spec.initial, hold=best_spec.hold)


def _report(on_generation: Callable[[int, int, int, float], Any] | None, seed: int,
            restart: int, measurement: np.ndarray) -> Callable[[Any], None] | None:
    """GAASS callback that hands each generation to ``on_generation`` (None: none)."""
    if on_generation is None:
        return None

    def callback(res: Any) -> None:
        on_generation(seed, restart, int(res.nit), float(er_percent(res.fun, measurement)))
    return callback


def _distinct_best(pop: np.ndarray, fun: np.ndarray, count: int) -> list[np.ndarray]:
    """The ``count`` best finite rows of a population, skipping duplicates."""
    order = np.argsort(np.where(np.isfinite(fun), fun, np.inf))
    chosen: list[np.ndarray] = []
    for i in order:
        if not np.isfinite(fun[i]):
            break
        if any(np.allclose(pop[i], c, rtol=1e-9, atol=1e-12) for c in chosen):
            continue
        chosen.append(np.asarray(pop[i], dtype=float))
        if len(chosen) == count:
            break
    return chosen


#: Restarts may stop for lack of gain only above this multiple of the noise floor.
_STALL_FLOOR_FACTOR = 1.5


def _n_workers(settings: IdentifySettings) -> int:
    return n_processes(settings.workers, len(settings.seeds))


def identify(recording: Recording, *, spec: ChainSpec | None = None,
             settings: IdentifySettings | None = None,
             progress: Callable[[int, int, SeedRun], None] | None = None,
             on_generation: Callable[[int, int, int, float], Any] | None = None,
             should_stop: Callable[[], bool] | None = None) -> Identification:
    """Identify the chain of ``recording.channel`` from a recording.

    Parameters
    ----------
    recording : Recording
        The run to identify from (validated here).
    spec : ChainSpec, optional
        Chain spec with search domains; default derived from the recording
        (:func:`hyst_id.identification.domains.domains_from_data`). The paper's domains are
        ``hyst_id.identification.domains.preset_spec('paper', channel)``.
    settings : IdentifySettings, optional
        GAASS and refinement settings; default the paper's.
    progress : callable, optional
        Called as ``progress(done, total, seed_run)`` after each seed, then
        after each run of the global phase (seeds ``-1``, ``-2``, ...; ``total``
        then counts the most global runs there can be). If it has an attribute
        ``hopping``, that is called as ``progress.hopping(jump, jumps,
        er_percent)`` before each jump of basin hopping and at its end
        (``jump == jumps``). If it has ``restart``, that is called with a few
        words before the start-state retry's probe and again before its full
        run (``IdentifySettings.start_state``), whose seeds count from the start.
    on_generation : callable, optional
        Called as ``on_generation(seed, restart, generation, er_percent)``
        after every GAASS generation, when the seeds run in this process
        (``workers == 1``; worker processes report per seed only).
    should_stop : callable, optional
        With worker processes: looked at every 0.2 s; when true the
        workers are ended at once and
        :class:`~hyst_id.identification.workers.WorkersStopped` is raised
        (with ``workers == 1`` raise from ``on_generation`` instead). Basin
        hopping, in this process, looks at it before each jump.

    Returns
    -------
    Identification
    """
    rec = validate_recording(recording)
    ident = _identify(rec, spec, settings, progress, on_generation, should_stop)
    full = settings or IdentifySettings()
    k = (refit_start(rec.command, ident.er_percent, ident.noise_floor_percent)
         if full.start_state else None)
    if k is None:
        return ident
    # a start inside the play or loop (see start_state): a short probe from the first reversal
    rest, before = rec.window(k, rec.n_samples), ident.er_percent / ident.noise_floor_percent
    restart = getattr(progress, 'restart', lambda what: None)
    restart('probing from the first reversal')
    probe = _identify(rest, spec, replace(full, seeds=full.seeds[:2], global_runs=0, hops=0),
                      None, None, should_stop)
    if not (probe.noise_floor_percent > 0
            and keep_refit(before, probe.er_percent / probe.noise_floor_percent)):
        return ident        # (also when the rest's floor is 0: nothing to judge by)
    restart('GAASS seeds, from the first reversal')
    again = _identify(rest, spec, full, progress, on_generation, should_stop)
    after = again.er_percent / again.noise_floor_percent   # > 0: the probe's was
    # after an improper loop's warning, which the CLI's --params-out refusal points to
    again.warnings.insert(0 if again.proper else 1, left_out_note(rec.t_s, k, before, after))
    return again


def _identify(rec: Recording, spec: ChainSpec | None, settings: IdentifySettings | None,
              progress, on_generation, should_stop) -> Identification:
    """:func:`identify` of a validated recording, as it is: proper loops, then maybe loose ones."""
    rec = roundoff_probe(rec)
    settings = settings or IdentifySettings()
    spec = spec or domains_from_data(rec)
    ident = _identify_chain(rec, spec, settings, progress, on_generation, should_stop)
    return loose_retry(ident, spec, settings, lambda loose, plain, quiet: _identify_chain(
        rec, loose, plain, None if quiet else progress, None if quiet else on_generation,
        should_stop))


def _identify_chain(rec: Recording, spec: ChainSpec, settings: IdentifySettings,
                    progress, on_generation, should_stop) -> Identification:
    """:func:`identify` in one chain's constraint set."""
    if spec.channel != rec.channel:
        raise IdentificationError(
            f'chain is for {spec.channel!r} but the recording is {rec.channel!r}')
    if not settings.seeds:
        raise IdentificationError('no seeds given')
    floor = noise_floor_percent(rec.measurement)
    args = (spec, rec.t_s, rec.command, rec.measurement, settings)
    more_above = floor if settings.more_starts else None     # more data-built starts above it
    incumbent = data_incumbent(*args, more_above) if settings.refine and settings.data_starts \
        else None
    others: list[ChainSpec] = []
    if incumbent is not None and settings.conventions == 'auto':
        ranked = rank_conventions(spec, rec, incumbent, settings, more_above)
        spec, incumbent = ranked[0]
        others = [e[0] for e in ranked[1:]] + [spec] if len(ranked) > 1 else []
        args = (spec, rec.t_s, rec.command, rec.measurement, settings)
    # the shared start's evaluations are counted once, in the first seed
    given = {s: (incumbent if k == 0 or incumbent is None else (*incumbent[:2], 0))
             for k, s in enumerate(settings.seeds)}
    # restarts after the first try the other conventions, in an order rotated per seed
    alternates = {s: tuple(others[k % len(others):] + others[:k % len(others)]) if others
                  else () for k, s in enumerate(settings.seeds)}
    runs: list[SeedRun] = []
    n_workers = _n_workers(settings)
    if n_workers == 1:
        for seed in settings.seeds:
            runs.append(run_seed(*args, seed, floor, on_generation, given[seed],
                                 alternates[seed]))
            if progress:
                progress(len(runs), len(settings.seeds), runs[-1])
    else:
        done: list[SeedRun] = []

        def on_result(run: SeedRun) -> None:
            done.append(run)
            if progress:
                progress(len(done), len(settings.seeds), run)

        runs = map_in_processes(
            run_seed, [(*args, seed, floor, None, given[seed], alternates[seed])
                       for seed in settings.seeds], n_workers,
            on_result=on_result, should_stop=should_stop)
    best = min(runs, key=lambda r: r.fun)
    global_runs: list[SeedRun] = []

    def on_global_run(run: SeedRun) -> None:   # the bar grows by the global runs' most
        global_runs.append(run)
        if progress:
            progress(len(runs) + len(global_runs), len(settings.seeds) + settings.global_runs,
                     run)
    # basin hopping from the best seed; unless it reaches the floor, the global phase starts
    # from the seeds' best as without it (a hopped incumbent would change which conventions
    # its longer runs take: family #170 then missed), and the better of the two is hopped
    hopping = getattr(progress, 'hopping', None)

    def on_jump(jump: int, jumps: int, er: float) -> None:
        if should_stop is not None and should_stop():
            raise WorkersStopped('stopped on request while hopping')
        if hopping is not None:
            hopping(jump, jumps, er)
    first, spent = hop_with_cost(spec, rec, best, settings, floor, on_jump=on_jump,
                                 n_workers=n_workers)
    hopped = [first] if first is not None else []
    at_floor = bool(hopped) and hopped[0].er_percent <= settings.global_factor * floor
    improved = global_phases(spec, others, rec, settings, hopped[0] if at_floor else best,
                             floor, n_workers, should_stop,
                             subset=search_subset(rec.command, settings.search_samples),
                             on_run=on_global_run)
    if improved and improved[-1].fun < min(h.fun for h in hopped + [best]):
        again, more = hop_with_cost(spec, rec, improved[-1], settings, floor, HOP_RUN_ID - 1,
                                    on_jump=on_jump, n_workers=n_workers)
        hopped += [again] if again is not None else []
        spent += more
    ident = summarise(rec, spec, settings, runs + hopped + improved)
    # evaluations outside the kept runs: the global runs that did not improve, hops that did not
    ident.other_nfev = (sum(r.nfev for r in global_runs) - sum(r.nfev for r in improved)
                        + spent - sum(h.nfev for h in hopped))
    warnings, ident.poorly_determined = assess(ident, rec, spec)
    ident.warnings += warnings
    return ident


def summarise(rec: Recording, spec: ChainSpec, settings: IdentifySettings,
              runs: list[SeedRun]) -> Identification:
    """Combine seed runs into an :class:`Identification`."""
    best = min(runs, key=lambda r: r.fun)
    # the chain is the best run's: its initial state and sensor hold
    spec = replace(spec, initial=best.initial, hold=best.hold)
    canon = replace(chain_spec(rec.channel, calibration=(best.sign, 0.0), family=spec.family),
                    initial=spec.initial, hold=spec.hold, proper=spec.proper)
    warnings = []
    same_chain = [r for r in runs if (r.initial, r.hold) == (best.initial, best.hold)]
    if len(same_chain) < len(runs):
        warnings.append(f'{len(runs) - len(same_chain)} seed(s) ended with another initial '
                        'state or sensor hold convention; they are left out of the mean')
    same_sign = [r for r in same_chain if r.sign == best.sign]
    if len(same_sign) < len(same_chain):
        warnings.append(f'{len(same_chain) - len(same_sign)} seed(s) found the opposite sensor '
                        'gain sign; they are left out of the mean')
    xs = np.array([r.x for r in same_sign])
    x_mean = xs.mean(axis=0)
    try:
        y_mean = canon.simulate(x_mean, rec.t_s, rec.command)
        er_mean = float(er_percent(np.sum((rec.measurement - y_mean) ** 2), rec.measurement))
    except InvalidParametersError:  # an average of feasible sets can be infeasible
        er_mean = float('nan')
    return Identification(
        channel=rec.channel, names=spec.names, params=spec.as_dict(best.x),
        params_mean=spec.as_dict(x_mean), output_sign=best.sign, er_percent=best.er_percent,
        er_mean_params_percent=er_mean,
        noise_floor_percent=noise_floor_percent(rec.measurement),
        runs=runs, bounds=spec.bounds, domain_source=spec.domain_source,
        settings=settings, warnings=warnings, source=rec.source, family=spec.family.id,
        initial=spec.initial, hold=spec.hold)
