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

"""Re-identify the whole chain once a block is in it (issue 14, item 4).

A block is first fitted locally, warm-started from the baseline chain
(:func:`hyst_id.diagnosis.select.fit_model`). When the missing effect had
biased that baseline (a gain that grows over the run pulls the loop's
branches apart), the local fit stays in the biased basin: on the blind
family's gain drifts identify reached 0.97-1.03 x the floor once the true
drift was divided out, the joint fit 1.1-15 x (``bench/drift_refit.py``).

:func:`reidentify` takes every block that can be inverted on data out of the
record (:meth:`hyst_id.diagnosis.mechanisms.base.Mechanism.undo`: a dead
time moves the command, a drift or gain in time is taken off the
measurement, an additive output term is subtracted), identifies the chain
afresh on what is left (identify's GAASS seeds, refined, and the data-built
starts), puts the blocks back with their fitted values and polishes the
whole model from each chain found. The best of these and the local fit on
the training part is kept, so the result is never worse there. When that is still
above :data:`REFIT_ABOVE` times the training floor, the same is done once
more from the better fit (its blocks undone again) with identify's global
phase (one differential-evolution run over the whole box). A re-identified
model that is worse than the local fit on the held-out samples the blocks
are judged on is not kept: on the blind family a chain that fitted the
training part better with the wrong block (a dead time for an end stop and a
sensor lag, #22) extrapolated much worse.

:func:`contest` applies the same to the round's runners-up. The winner is
chosen on fits made locally around the current chain, and a chain biased by
the missing effect can favour the wrong block there: on the blind family's
#42 (a gain drift whose pivot lies far below the travel) the local fits put
``offset_drift`` first (judged held-out 0.90 % against 1.43 %), but
re-identified ``offset_drift`` stops at 5.0 x the noise floor where
``gain_drift`` reaches 1.02 x. When the re-identified winner stays above
:data:`CONTEST_ABOVE` x the floor, the accepted runners-up within
:data:`CONTEST_RATIO` of its local judged error (at most :data:`CONTESTANTS`)
are re-identified too, and one
that then predicts the judged held-out samples clearly better (by more than
``criteria.tie_ratio``) takes the round.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.baseline import baseline_starts
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.diagnosis.select import evaluate, FitResult, polish
from hyst_id.errors import IdentificationError, RecordingError
from hyst_id.identification.chains import ChainSpec
from hyst_id.io.recording import Recording

__all__ = ['CONTEST_ABOVE', 'CONTEST_RATIO', 'CONTESTANTS', 'contest', 'implausible_after',
           'REFIT_ABOVE',
           'reidentify', 'undone_record']

#: A fit within this factor of the training noise floor is not re-identified.
REFIT_ABOVE = 1.1
#: A re-identified winner above this factor of the judged held-out floor is contested.
CONTEST_ABOVE = 1.5
#: Runners-up whose local judged held-out %e_r is within this factor of the winner's contest.
CONTEST_RATIO = 2.0
#: At most this many runners-up are re-identified in a contest.
CONTESTANTS = 2


def undone_record(fit: FitResult, data, ctx) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Command and measurement with every invertible block of ``fit`` taken out.

    Blocks are undone from the measurement's end back to the command's
    (reverse signal order). Returns the command, the measurement and the ids
    of the blocks undone (empty: nothing could be).
    """
    model = fit.model
    a = model.evaluate(fit.p, data.t_s, data.v, data.n_train).matrix()
    terms = {lab: a[:, j] * fit.coef[j] for j, lab in enumerate(fit.labels)}
    v, y, done = data.v, data.y, []
    for m in reversed(model.mechanisms):
        theta = model.theta(fit.p, m.id)
        got = m.undo(theta, data.t_s, v, y, terms, ctx)
        if got is not None and np.all(np.isfinite(got[0])) and np.all(np.isfinite(got[1])):
            v, y = got
            terms = m.undo_terms(theta, data.t_s, terms, ctx)
            done.append(m.id)
    return v, y, done


def reidentify(fit: FitResult, data, ctx, spec: ChainSpec, settings, *,
               floor_train_percent: float, say=None) -> FitResult:
    """The model of ``fit`` with its chain identified afresh on the record with blocks undone.

    Parameters
    ----------
    fit : FitResult
        A composed model's fit (blocks and chain).
    data : Data
        The record in the model's command units.
    ctx : Context
        Recording facts the blocks need.
    spec : ChainSpec
        The diagnosis's chain spec (search domains of the chain).
    settings : DiagnoseSettings
        GAASS seeds, population, generations, workers and the polish budget.
    floor_train_percent : float
        %e_r of the noise alone on the training part: a fit within
        :data:`REFIT_ABOVE` times it is returned as it is.
    say : callable, optional
        Progress words (``say(text)``) before each identification of the chain
        (minutes on a long record).

    Returns
    -------
    FitResult
        The re-identified model when it is better on the training part and not
        worse on the judged held-out samples, else ``fit``.
    """
    model = fit.model
    if model is None or not model.mechanisms or model.swapped_by \
            or fit.er_train_percent <= REFIT_ABOVE * floor_train_percent:
        return fit
    local = fit
    for global_phase in (False, True):
        fit = _reidentify_once(fit, data, ctx, spec, settings, global_phase, say)
        if fit.er_train_percent <= REFIT_ABOVE * floor_train_percent:
            break
    if data.n_holdout and data.judged_er_percent(fit) > data.judged_er_percent(local):
        return local    # better on the training part, worse where the blocks are judged
    return fit


def _reidentify_once(fit: FitResult, data, ctx, spec: ChainSpec, settings,
                     global_phase: bool, say=None) -> FitResult:
    model = fit.model
    v, y, done = undone_record(fit, data, ctx)
    if not done:
        return fit
    if say is not None:
        how = "with identify's global phase" if global_phase else 'with GAASS seeds'
        say(f're-identifying the chain {how} on the record with {", ".join(done)} undone')
    n = data.n_train
    rec = Recording(data.t_s[:n], v[:n], y[:n], ctx.channel)
    try:
        x_fits, starts = baseline_starts(rec, spec, settings, thorough=False,
                                         global_phase=global_phase)
    except (RecordingError, IdentificationError):   # e.g. a dead time that ate the record
        return fit
    thetas = {m.id: model.theta(fit.p, m.id) for m in model.mechanisms}
    best = (fit.p, fit.sse_train, 0)
    for x0 in x_fits + starts:
        p0 = model.pack(x0, thetas)
        if not model.feasible(p0):
            continue
        got = polish(model, data, p0, max_nfev=2 * settings.fit_budget)
        if got[1] < best[1]:
            best = got
    if best[0] is fit.p:
        return fit
    return evaluate(model, data, best[0], fit.nfev + best[2])


def implausible_after(comp, data, ctx) -> str:
    """Why ``comp``'s block, in its re-identified fit, cannot be what the data show ('').

    The trial judged the block on its local fit; re-identified with the chain its
    values can move where the physics cannot go (a new user's Bouc-Wen record: a
    creep relaxing back by 110 % of the travel took the round this way).
    """
    fit = comp.fit
    mech = MECHANISMS.get(comp.mechanism)
    model = getattr(fit, 'model', None)     # a fit without its model cannot be judged
    if mech is None or model is None or mech.id not in model.slices:
        return ''
    return mech.implausible(model.theta(fit.p, mech.id), fit.coef, fit.span,
                            data.noise_std, ctx, fit.labels)


def contest(winner, comps: list, data, ctx, spec: ChainSpec, settings, *,
            floor_train_percent: float, say=None, beats=None) -> tuple:
    """The round's winner re-identified, or a runner-up whose re-identified chain beats it.

    Parameters
    ----------
    winner : Comparison
        The round's choice on local fits.
    comps : list of Comparison
        Every candidate of the round (accepted runners-up are the contestants).
    data, ctx, spec, settings, floor_train_percent
        As :func:`reidentify`.
    say : callable, optional
        Progress words (``say(text)``) before each identification of the winner's
        chain and before each runner-up's re-identification.
    beats : callable, optional
        ``beats(fit, rival_fit)``: whether a re-identified runner-up takes the
        round from the current choice. Default: its judged held-out %e_r is
        below the choice's by more than ``criteria.tie_ratio``; the diagnosis
        passes :meth:`hyst_id.diagnosis.blocked_cv.BlockedCV.beats` when the
        split judged too little to decide alone.

    Returns
    -------
    chosen : Comparison
        ``winner`` or a runner-up, its ``fit`` replaced by the re-identified one
        (the runners-up that lose keep their re-identified ``fit`` too).
    contest : list of dict
        Empty when no runner-up was re-identified, else each contestant's
        judged held-out %e_r after re-identification (``winner`` first).
    """
    local = {id(c): data.judged_er_percent(c.fit) for c in comps}
    local_fit = winner.fit
    winner.fit = reidentify(winner.fit, data, ctx, spec, settings,
                            floor_train_percent=floor_train_percent, say=say)
    why = implausible_after(winner, data, ctx)
    if why:
        # re-identified into values its physics cannot have (a new user's gain_loss at
        # the slowest rate of its search, an offset ramp): the accepted local fit stays
        if say is not None:
            say(f'{winner.mechanism} re-identified: {why}; its local fit stays')
        winner.fit = local_fit
    best_er = data.judged_er_percent(winner.fit)
    if best_er <= CONTEST_ABOVE * data.floor_holdout_percent:
        return winner, []
    rivals = sorted((c for c in comps if c.accepted and c is not winner
                     and local[id(c)] <= CONTEST_RATIO * local[id(winner)]),
                    key=lambda c: local[id(c)])[:CONTESTANTS]
    if not rivals:
        return winner, []
    record = [{'mechanism': winner.mechanism, 'er_judged_after_percent': best_er}]
    chosen = winner
    for c in rivals:
        if say is not None:
            ratio = best_er / data.floor_holdout_percent
            say(f'{winner.mechanism} re-identified stays at {ratio:.2g} x the floor: '
                f're-identifying {c.mechanism} to compare')
        c.fit = reidentify(c.fit, data, ctx, spec, settings,
                           floor_train_percent=floor_train_percent)
        er = data.judged_er_percent(c.fit)
        record.append({'mechanism': c.mechanism, 'er_judged_after_percent': er})
        why = implausible_after(c, data, ctx)
        if why:     # re-identified into values its physics cannot have: it cannot take the round
            record[-1]['implausible'] = why
            continue
        if beats is None:
            if er * settings.criteria.tie_ratio < data.judged_er_percent(chosen.fit):
                chosen = c
        elif beats(chosen.fit, c.fit):
            chosen = c
    return chosen, record
