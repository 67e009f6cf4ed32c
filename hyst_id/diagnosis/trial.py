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

"""One round of the diagnosis: every candidate block fitted into the current model.

:func:`try_all` fits each mechanism at its place in the chain (warm-started
from the current model and the data-built chain starts; a mechanism that
swaps the hysteresis family gets its own baseline fit) and judges it against
the current model (:func:`hyst_id.diagnosis.select.compare`). The fits are
independent of each other, so with ``settings.workers`` other than 1 they run
in worker processes (:func:`hyst_id.identification.workers.map_in_processes`),
the costliest first; each is computed exactly as in one process, and the
comparisons come back in the order of ``mechs``, so the round's outcome does
not depend on the number of workers.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from hyst_id.diagnosis.baseline import quick_memo, quick_starts, remember
from hyst_id.diagnosis.joint import JOINT_LEADERS, joint_search, worth_searching
from hyst_id.diagnosis.locate import Localization
from hyst_id.diagnosis.mechanisms.base import Context, Mechanism
from hyst_id.diagnosis.model import ComposedModel, held
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import compare, Comparison, Data, evaluate, fit_model
from hyst_id.diagnosis.select import FitResult, polish
from hyst_id.identification.chains import HOLDS
from hyst_id.identification.domains import domains_from_data
from hyst_id.identification.workers import map_in_processes, n_processes
from hyst_id.io.recording import Recording

__all__ = ['judge', 'polish_all', 'try_all', 'try_mechanism']

#: Mechanisms whose fits cost the most, handed to workers first (the rest keep their order).
COSTLY_FIRST = ('loop_shape', 'actuator_dynamics', 'friction', 'bouc_wen', 'creep',
                'saturation')


def try_all(mechs: list[Mechanism], current: FitResult, data: Data, ctx: Context,
            settings: DiagnoseSettings, loc: Localization, chain_starts: list[np.ndarray],
            say: Callable[[str], None] = lambda text: None) -> list[Comparison]:
    """Fit and judge every mechanism of ``mechs`` against ``current``, in that order.

    Parameters
    ----------
    mechs : list of Mechanism
        Candidates of this round.
    current : FitResult
        The model they extend.
    data, ctx, loc, chain_starts :
        The record, its context, the located mismatch and the data-built chain starts.
    settings : DiagnoseSettings
        Fit budget, criteria and ``workers`` (0: one per core; 1: this process).
    say : callable, optional
        Progress, a line per mechanism.

    Returns
    -------
    list of Comparison
        One per mechanism, in the order of ``mechs``. A block that fits as another
        of the round (:attr:`~hyst_id.diagnosis.mechanisms.base.Mechanism.fits_as`)
        is judged on that block's fit, made once.
    """
    ids = [m.id for m in mechs]
    twin = {i: ids.index(m.fits_as) for i, m in enumerate(mechs) if m.fits_as in ids}
    own = [i for i in range(len(mechs)) if i not in twin]
    got = dict(zip(own, _fit_and_judge([mechs[i] for i in own], current, data, ctx, settings,
                                       loc, chain_starts, say)))
    _search_leaders(got, mechs, current, data, ctx, settings, loc, say)
    for i, j in twin.items():
        say(f'{mechs[i].id}: the fit of {mechs[j].id}, judged as {mechs[i].id}')
        got[i] = _as_twin(mechs[i], got[j].fit, current, data, ctx, settings, loc)
    return [got[i] for i in range(len(mechs))]


def _fit_and_judge(mechs: list[Mechanism], current: FitResult, data: Data, ctx: Context,
                   settings: DiagnoseSettings, loc: Localization,
                   chain_starts: list[np.ndarray],
                   say: Callable[[str], None]) -> list[Comparison]:
    """:func:`try_mechanism` of each of ``mechs``, in this process or in workers."""
    workers = n_processes(settings.workers, len(mechs))
    if workers <= 1:
        comps = []
        for m in mechs:
            say(f'testing {m.id}')
            comps.append(try_mechanism(m, current, data, ctx, settings, loc, chain_starts))
        return comps
    say(f'testing {", ".join(m.id for m in mechs)} in {workers} processes')
    order = sorted(range(len(mechs)), key=lambda i: (
        COSTLY_FIRST.index(mechs[i].id) if mechs[i].id in COSTLY_FIRST else len(COSTLY_FIRST)))
    # a worker does not start workers of its own; a stop check does not cross processes
    one = replace(settings, workers=1, should_stop=None)
    memo = quick_memo()     # the swaps' searches so far, for workers that did not fork them
    got = map_in_processes(_try_in_worker, [(mechs[i], current, data, ctx, one, loc,
                                             chain_starts, memo) for i in order], workers,
                           on_result=lambda r: say(f'{r[0].mechanism} fitted'))
    comps: list[Comparison | None] = [None] * len(mechs)
    for i, (comp, searched) in zip(order, got):
        comps[i] = comp
        remember(searched)    # a swap's search, for the next round
    return comps


def _try_in_worker(m: Mechanism, current: FitResult, data: Data, ctx: Context,
                   settings: DiagnoseSettings, loc: Localization,
                   chain_starts: list[np.ndarray], memo: dict) -> tuple[Comparison, dict]:
    """:func:`try_mechanism` in a worker process, and the family swap's search it made.

    ``memo``: the swaps' searches the round's parent holds
    (:func:`hyst_id.diagnosis.baseline.quick_memo`), for a worker that did not fork
    them; the second value is every search the worker holds when ``m`` swaps the
    family (empty otherwise), for the parent to keep for the next round.
    """
    if memo:
        remember(memo)
    comp = try_mechanism(m, current, data, ctx, settings, loc, chain_starts)
    return comp, (quick_memo() if getattr(m, 'swap_family', '') else {})


def polish_all(pairs: list[tuple[ComposedModel, np.ndarray]], data: Data, max_nfev: int,
               workers: int) -> list[tuple[np.ndarray, float, int]]:
    """:func:`hyst_id.diagnosis.select.polish` of each ``(model, start)``, in that order.

    ``workers`` as in :class:`DiagnoseSettings` (0: one per core); each polish is
    computed as in one process.
    """
    n = n_processes(workers, len(pairs))
    if n <= 1:
        return [polish(model, data, x0, max_nfev=max_nfev) for model, x0 in pairs]
    return map_in_processes(_polish_one, [(model, data, x0, max_nfev) for model, x0 in pairs], n)


def _polish_one(model: ComposedModel, data: Data, x0: np.ndarray,
                max_nfev: int) -> tuple[np.ndarray, float, int]:
    return polish(model, data, x0, max_nfev=max_nfev)


def _search_leaders(got: dict[int, Comparison], mechs: list[Mechanism], current: FitResult,
                    data: Data, ctx: Context, settings: DiagnoseSettings, loc: Localization,
                    say: Callable[[str], None]) -> None:
    """The round's leading local fits searched jointly with the chain, judged again in place.

    At most :data:`~hyst_id.diagnosis.joint.JOINT_LEADERS` of the fits worth it
    (:func:`~hyst_id.diagnosis.joint.worth_searching`), lowest training BIC first. The
    searched fit is kept when it is better on the training part and, judged again, loses
    nothing: an accepted block stays accepted (else the local fit is kept), and a first
    filter on a static chain in the ``after`` hold must still do more than the hold's
    one-sample shift (:func:`_filter_beats_shift`).
    """
    if settings.joint_generations <= 0:
        return
    bic_drop = settings.criteria.bic_drop
    lead = sorted((i for i, c in got.items()
                   if worth_searching(c.fit, c.delta_bic, data, bic_drop)),
                  key=lambda i: got[i].delta_bic)[:JOINT_LEADERS]
    if not lead:
        return
    say(f'{", ".join(mechs[i].id for i in lead)}: searched with the chain over the whole box')
    args = [(got[i].fit, data, settings.joint_generations, 2 * settings.fit_budget)
            for i in lead]
    workers = n_processes(settings.workers, len(lead))
    fits = ([_search(*a, should_stop=settings.should_stop) for a in args] if workers <= 1
            else map_in_processes(_search, args, workers, should_stop=settings.should_stop))
    for i, fit in zip(lead, fits):
        m, local = mechs[i], got[i]
        if not fit.sse_train < local.fit.sse_train:
            continue
        static = current.model is not None and not current.model.dynamic
        if (fit.model.hold == 'after' and static and m.stage == 'sensor'
                and not _filter_beats_shift(fit, m, data)):
            say(f'{m.id}: the search made it a one-sample delay; its local fit kept')
            continue
        again = judge(m, current, fit, data, ctx, settings, loc, local.screened)
        if local.accepted and not again.accepted:
            say(f'{m.id}: the searched fit is {again.status}; its accepted local fit kept')
            continue
        say(f'{m.id}: searched, training %e_r {local.fit.er_train_percent:.4g} -> '
            f'{fit.er_train_percent:.4g}, {again.status}')
        got[i] = again


def _search(fit: FitResult, data: Data, generations: int, polish_nfev: int,
            should_stop: Callable[[], bool] | None = None) -> FitResult:
    """:func:`~hyst_id.diagnosis.joint.joint_search` (module level: for worker processes)."""
    return joint_search(fit, data, generations=generations, polish_nfev=polish_nfev,
                        should_stop=should_stop)


def try_mechanism(m: Mechanism, current: FitResult, data: Data, ctx: Context,
                  settings: DiagnoseSettings, loc: Localization,
                  chain_starts: list[np.ndarray]) -> Comparison:
    """Fit ``m`` into ``current`` and judge it (the criteria, its evidence, its plausibility).

    A family swap's search is kept in this process
    (:func:`hyst_id.diagnosis.baseline.remember`) for the next round.
    """
    prev = current.model
    thetas = {pm.id: prev.theta(current.p, pm.id) for pm in prev.mechanisms}
    screened = None
    if getattr(m, 'swap_family', ''):
        fit = _swap_family(m, current, data, ctx, settings, thetas)
    else:
        # the first filter on a static chain is fitted in both hold conventions
        holds = (prev.hold,) if prev.dynamic or m.stage != 'sensor' else HOLDS
        fit = None
        for hold in holds:
            model = ComposedModel(ctx.channel, list(prev.mechanisms) + [m], ctx,
                                  prev.bounds[:prev.n_chain], family=prev.spec.family.id,
                                  swapped_by=prev.swapped_by, hold=hold,
                                  initial=prev.initial, proper=prev.spec.proper)
            p_prev = model.pack(current.p[:prev.n_chain], thetas)
            # the data-built starts are the baseline family's chains
            got = fit_model(model, data, p_prev, m, budget=settings.fit_budget,
                            chain_starts=[c for c in chain_starts if c.size == prev.n_chain])
            if len(holds) > 1 and hold == 'after' and not _filter_beats_shift(got, m, data):
                screened = got  # a one-sample delay in disguise: dead_time's business
                continue
            if fit is None or got.sse_train < fit.sse_train:
                fit = got
    return judge(m, current, fit, data, ctx, settings, loc, screened)


def _as_twin(m: Mechanism, fit: FitResult, current: FitResult, data: Data, ctx: Context,
             settings: DiagnoseSettings, loc: Localization) -> Comparison:
    """``m`` judged on ``fit``, the fit of the block ``m`` fits as, under ``m``'s name.

    The same parameters in the same places: the model is rebuilt with ``m``
    in its twin's place and evaluated once at the fitted vector.
    """
    prev = fit.model
    model = ComposedModel(ctx.channel, [m if pm.id == m.fits_as else pm
                                        for pm in prev.mechanisms], ctx,
                          prev.bounds[:prev.n_chain], family=prev.spec.family.id,
                          swapped_by=prev.swapped_by, hold=prev.hold, initial=prev.initial,
                          proper=prev.spec.proper)
    return judge(m, current, evaluate(model, data, fit.p, fit.nfev), data, ctx, settings, loc)


def judge(m: Mechanism, current: FitResult, fit: FitResult, data: Data, ctx: Context,
          settings: DiagnoseSettings, loc: Localization,
          screened: FitResult | None = None) -> Comparison:
    """Judge ``fit`` (``current`` extended by ``m``): criteria, evidence, plausibility."""
    comp = compare(current, fit, data, m.id, settings.criteria)
    comp.screened = screened
    comp.evidence, comp.where = m.evidence(loc)
    model = fit.model
    theta = model.theta(fit.p, m.id) if m.id in model.slices else np.zeros(0)
    reason = m.implausible(theta, fit.coef, fit.span, data.noise_std, ctx, labels=fit.labels)
    comp.doubt = m.doubt(theta, fit.coef, fit.labels, data.y[:data.n_train])
    if reason and comp.accepted:
        comp.accepted, comp.status = False, f'rejected: {reason}'
    return comp


def _filter_beats_shift(fit: FitResult, m: Mechanism, data: Data) -> bool:
    """Whether a filter block fitted in the ``after`` convention does more than its hold.

    On a static chain the ``after`` convention is itself a one-sample delay, so a
    nearly transparent filter in it is a delay (``dead_time``), not dynamics: the
    block must change its (held) input by more than the hold's shift does. The
    input is taken as the chain's travel (before position-stage blocks such as
    an end stop, which change it little): a screening test, not the fit.
    """
    x = fit.travel_raw[:data.n_train]
    shifted = held(x, 'after')
    out = m.sensor(fit.model.theta(fit.p, m.id), data.t_s[:data.n_train], shifted)
    return float(np.linalg.norm(out - shifted)) > float(np.linalg.norm(shifted - x))


def _swap_family(m: Mechanism, current: FitResult, data: Data, ctx: Context,
                 settings: DiagnoseSettings, thetas: dict) -> FitResult:
    """The chain refitted with H from ``m.swap_family`` (the blocks that work with it kept).

    H's family changes the chain's parameters, so there is nothing to
    warm-start from: the new chain gets its own baseline fit (GAASS seeds and
    data-built starts on the training part, each polished with the kept blocks;
    the search is the same in every round, :func:`hyst_id.diagnosis.baseline.quick_starts`).
    """
    prev, fam, n = current.model, m.swap_family, data.n_train
    rec_train = Recording(data.t_s[:n], data.v[:n], data.y[:n], ctx.channel)
    spec = replace(domains_from_data(rec_train, family=fam), initial=prev.initial)
    keep = [pm for pm in prev.mechanisms if pm.families is None or fam in pm.families]
    model = ComposedModel(ctx.channel, keep, ctx, spec.bounds, family=fam, swapped_by=m.id,
                          hold=prev.hold, initial=prev.initial)
    x_fits, starts = quick_starts(rec_train, spec, settings)
    best = None
    for x0 in x_fits + starts:
        p0 = model.pack(x0, thetas)
        if not model.feasible(p0):
            continue
        got = polish(model, data, p0, max_nfev=2 * settings.fit_budget)
        if best is None or got[1] < best[1]:
            best = got
    if best is None:
        return current
    return evaluate(model, data, best[0], best[2])
