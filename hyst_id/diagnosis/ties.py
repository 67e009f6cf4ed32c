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

"""Which accepted candidate wins a round, and which the report states as judgement calls.

:func:`choose` picks the winner among the accepted candidates of a round:
the lowest judged held-out error; candidates tied with it (within
``tie_ratio`` or ``tie_floor`` x the noise floor, or not significantly worse,
``z < tie_z``) are decided by the training BIC, then the located evidence.
Two rules make a block step back in a tie: a block that nests another
(:data:`NESTS`) without evidence of its own, and a fit that goes against its
block's own physics (:meth:`hyst_id.diagnosis.mechanisms.base.Mechanism.doubt`,
a supply decay whose readings rise) where a tied one does not. The others are
stated with the finding: tied candidates, close calls (:func:`close_calls`),
filters behind a one-sample hold (:func:`hold_calls`), in the form
:func:`alternatives_record` gives them.
"""

from __future__ import annotations

from hyst_id.diagnosis.select import Comparison, Criteria, Data, improvement_z

__all__ = ['alternatives_record', 'choose', 'close_calls', 'HOLD_CALL_SAMPLES', 'hold_calls',
           'NESTS']


#: Blocks that nest another (a falling gain about a distant zero is an offset ramp): while the
#: nested one is accepted and within the judgement ratio, one wins only with its own located
#: evidence (> 0). Blind #118 and #38, offset drifts, went to ``gain_loss`` without this.
NESTS = {'gain_loss': 'offset_drift'}


def choose(comparisons: list[Comparison], data: Data, criteria: Criteria
           ) -> tuple[Comparison | None, list[Comparison]]:
    """Pick the accepted candidate: held-out error, then BIC among ties, then evidence.

    A nesting block without evidence steps back (:data:`NESTS`), and so does, among the
    tied, a fit with a doubt (:attr:`Comparison.doubt`) where a tied one has none. Returns
    the winner (None when nothing is accepted) and the others tied with it (equally
    consistent with the data).
    """
    ok = [c for c in comparisons if c.accepted]
    if not ok:
        return None, []
    er = {id(c): data.judged_er_percent(c.fit) for c in ok}
    mine = {c.mechanism: c for c in ok}
    ok = [c for c in ok if not ((m := mine.get(NESTS.get(c.mechanism))) and c.evidence <= 0.0
                                and er[id(m)] <= criteria.judgement_ratio * er[id(c)])]
    best = min(ok, key=lambda c: er[id(c)])
    rows = data.judged_rows
    near = max(criteria.tie_ratio * er[id(best)],
               criteria.tie_floor * data.floor_holdout_percent)
    tied = [c for c in ok if c is best or er[id(c)] <= near
            or improvement_z(c.fit.prediction[rows], best.fit.prediction[rows], data.y[rows],
                             data.noise_std) < criteria.tie_z]
    n = data.n_train
    pool = [c for c in tied if not c.doubt] or tied
    bics = {c.mechanism: c.fit.bic(n) for c in pool}
    low = min(bics.values())
    close = [c for c in pool if bics[c.mechanism] < low + 2.0]
    winner = max(close, key=lambda c: (c.evidence, -bics[c.mechanism]))
    return winner, [c for c in tied if c is not winner]


def close_calls(comparisons: list[Comparison], winner: Comparison | None,
                tied: list[Comparison], data: Data, criteria: Criteria) -> list[Comparison]:
    """Accepted runners-up, not tied, close enough to the winner to make it a judgement call.

    Their judged held-out %e_r is within ``criteria.judgement_ratio`` of the
    winner's: the data prefer the winner, but by less than round-off, the
    split or a slightly different record could reverse; a report names them.
    """
    if winner is None:
        return []
    best = data.judged_er_percent(winner.fit)
    return [c for c in comparisons if c.accepted and c is not winner
            and all(c is not t for t in tied)
            and data.judged_er_percent(c.fit) <= criteria.judgement_ratio * best]


#: :func:`hold_calls` only for a dead time up to this many sample periods: the screen
#: drops ``after``-hold lags below about 1.44 samples (``a > 0.5``), so such a lag and its
#: hold delay the reading by at most about 2.4 samples on average; 3 leaves a margin
HOLD_CALL_SAMPLES = 3.0


def hold_calls(winner: Comparison, comps: list[Comparison], data: Data,
               criteria: Criteria, dt_s: float) -> list[dict]:
    """Filters behind a one-sample hold that a winning dead time stands for as well.

    On a static chain a filter block fitted in the ``after`` hold is dropped
    when it changes its input less than the hold's one-sample shift does
    (:func:`hyst_id.diagnosis.trial.try_mechanism`): it is mostly a delay.
    But a first-order lag of about a sample behind such a hold (the reference
    simulator's convention, a rig sampled before the new command acts) is also
    mostly a delay: on the blind family's #134 (a 0.5-sample lag) ``dead_time``
    won with 1.2 samples and the dropped lag fit was as good on held-out data
    (on #84, a 1.4-sample lag, it was not: fitted around a biased chain). When the winner is
    ``dead_time`` and such a dropped fit predicts the judged held-out samples
    within ``criteria.judgement_ratio`` of it, the report names it (``kind``
    ``hold``). Only for delays up to :data:`HOLD_CALL_SAMPLES` sample periods:
    a longer delay is not what a sub-sample lag behind a hold looks like
    (``dt_s``: the sample period, :attr:`~hyst_id.diagnosis.mechanisms.base.Context.dt_s`).
    """
    if winner.mechanism != 'dead_time':
        return []
    model = winner.fit.model
    if model is None or model.theta(winner.fit.p, 'dead_time')[0] > HOLD_CALL_SAMPLES * dt_s:
        return []
    best = data.judged_er_percent(winner.fit)
    out = []
    for c in comps:
        if c.screened is None:
            continue
        er = data.judged_er_percent(c.screened)
        if er <= criteria.judgement_ratio * best:
            out.append({'mechanism': c.mechanism, 'kind': 'hold',
                        'er_holdout_after_percent': c.screened.er_holdout_percent,
                        'er_judged_after_percent': er})
    return out


def alternatives_record(tied: list[Comparison], close: list[Comparison],
                        data: Data) -> list[dict]:
    """A finding's ``alternatives``: tied candidates, then close calls, with which they are.

    A candidate with a doubt carries it (``doubt``: why it stepped back in the tie).

    Each with its held-out %e_r (all held-out rows) and the judged one the
    criteria compare (:attr:`Data.judged_rows`).
    """
    return [{'mechanism': c.mechanism, 'er_holdout_after_percent': c.fit.er_holdout_percent,
             'er_judged_after_percent': data.judged_er_percent(c.fit), 'kind': kind,
             **({'doubt': c.doubt} if c.doubt else {})}
            for kind, group in (('tied', tied), ('close', close)) for c in group]
