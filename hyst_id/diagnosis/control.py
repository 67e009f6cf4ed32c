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

"""The null control: the block, or the chain refit that came with it.

Fitting a block polishes the whole chain again, from the current parameters
and from the data-built starts. When the current chain had stopped short of
its own optimum (a baseline above the noise floor on a clean recording), that
refit alone can buy the held-out gain, and the block gets the credit: on the
blind family (bench/blind_family.py) this was most of the physical claims on
clean recordings. The control takes the chain the block's fit found, drops
the block, polishes that chain in the current model with the same budget, and
judges every accepted block again against it (:func:`hyst_id.diagnosis.select.compare`).
A block that is no longer accepted was the refit's doing; the refit, better on
the training part, then becomes the current model.

:func:`drop_superseded` is the same question asked backwards at the end: with
two or more blocks, is each still needed once the others are in? A block
accepted early against a chain the missing effect had biased can be made
redundant by a later one (an offset ramp taken first for a gain that grows
about a distant zero, the gain drift added next then explains both).
"""

from __future__ import annotations

from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import compare, Comparison, Criteria, Data, evaluate, FitResult
from hyst_id.diagnosis.select import passes_holdout, polish

__all__ = ['drop_superseded', 'equivalent_chain', 'null_control', 'recheck', 'without']


def null_control(candidate: Comparison, current: FitResult, data: Data, *,
                 max_nfev: int) -> FitResult | None:
    """The current model refitted from the chain of ``candidate``'s fit, or None.

    None when the candidate's chain is not the current model's (a swapped
    hysteresis family) or the refit is not better than ``current`` on the
    training part.
    """
    refit = _chain_refit(candidate, current, data, max_nfev=max_nfev)
    if refit is None or not refit.sse_train < current.sse_train:
        return None
    return refit


def _chain_refit(candidate: Comparison, current: FitResult, data: Data, *,
                 max_nfev: int) -> FitResult | None:
    """The current model polished from the chain of ``candidate``'s fit (None: not possible)."""
    prev, model = current.model, candidate.fit.model
    n = prev.n_chain
    if model.n_chain != n or model.spec.family.id != prev.spec.family.id:
        return None
    thetas = {pm.id: model.theta(candidate.fit.p, pm.id) for pm in prev.mechanisms}
    p0 = prev.pack(candidate.fit.p[:n], thetas)
    if not prev.feasible(p0):
        return None
    p, _, nfev = polish(prev, data, p0, max_nfev=max_nfev)
    return evaluate(prev, data, p, nfev)


def equivalent_chain(comparisons: list[Comparison], current: FitResult, data: Data,
                     criteria: Criteria, *, max_nfev: int) -> FitResult | None:
    """A chain that fits the training part as well as ``current`` and predicts held-out better.

    When no block is accepted but the blocks' fits (each of which polishes
    the chain again) predict the held-out part better than the current
    model, the training part has not pinned the chain down: fits equally
    good on it differ where the held-out part goes. The candidate with the
    lowest judged held-out %e_r gives its chain; the current model is
    polished from it without the block. The refit is returned when the
    training part gives no strong evidence against it (its BIC not more than
    ``criteria.bic_drop`` above the current one: the same parameters, and
    the threshold a block must clear to be accepted; polishes from two starts
    can stop a few units apart, measured up to +5 by
    ``bench/null_control_spread.py``) and it passes the held-out half of the
    acceptance test against ``current`` (improvement z, gain and share;
    :func:`hyst_id.diagnosis.select.compare`). Otherwise None.
    """
    if current.model is None:
        return None
    usable = [c for c in comparisons if c.fit.model is not None]
    if not usable:
        return None
    best = min(usable, key=lambda c: data.judged_er_percent(c.fit))
    refit = _chain_refit(best, current, data, max_nfev=max_nfev)
    if refit is None:
        return None
    n = data.n_train
    if refit.bic(n) > current.bic(n) + criteria.bic_drop:
        return None
    ok_hold = passes_holdout(compare(current, refit, data, best.mechanism, criteria), criteria)
    return refit if ok_hold else None


def recheck(comparisons: list[Comparison], null: FitResult, data: Data,
            criteria: Criteria) -> int:
    """Judge every accepted comparison again against ``null``; how many lost it.

    A comparison that is no longer accepted gets the status
    ``'rejected: the chain refit alone does as well'``; its other figures stay
    those against the current model.
    """
    lost = 0
    for c in comparisons:
        if c.accepted and not compare(null, c.fit, data, c.mechanism, criteria).accepted:
            c.accepted, c.status = False, 'rejected: the chain refit alone does as well'
            lost += 1
    return lost


def without(current: FitResult, mid: str, data: Data, *, max_nfev: int) -> FitResult | None:
    """``current`` with block ``mid`` taken out, the rest polished from the current values.

    None when the rest, as the current values pack it, is not feasible.
    """
    prev = current.model
    keep = [m for m in prev.mechanisms if m.id != mid]
    model = ComposedModel(prev.channel, keep, prev.ctx, prev.bounds[:prev.n_chain],
                          family=prev.spec.family.id, swapped_by=prev.swapped_by,
                          hold=prev.hold, initial=prev.initial, proper=prev.spec.proper)
    p0 = model.pack(current.p[:prev.n_chain], {m.id: prev.theta(current.p, m.id) for m in keep})
    if not model.feasible(p0):
        return None
    p, _, nfev = polish(model, data, p0, max_nfev=max_nfev)
    return evaluate(model, data, p, nfev)


def drop_superseded(current: FitResult, order: list[str], data: Data, criteria: Criteria,
                    *, max_nfev: int) -> tuple[FitResult, list[str]]:
    """Withdraw blocks the others make redundant (backward elimination).

    Each block of ``current`` (in ``order``, the order they were accepted) is
    taken out, the rest is polished from the current values, and the model
    with the block is judged against the one without it by the acceptance
    criteria (:func:`hyst_id.diagnosis.select.compare`). A block that is no
    longer accepted is withdrawn, the reduced model becomes the current one,
    and the check starts again; the last block is kept (it was accepted
    against the model before it).

    Returns
    -------
    FitResult
        The model without the withdrawn blocks.
    list of str
        The ids withdrawn, in the order they were.
    """
    dropped: list[str] = []
    while current.model is not None and len(current.model.mechanisms) > 1:
        prev = current.model
        for mid in [i for i in order if i in prev.slices and i not in dropped]:
            reduced = without(current, mid, data, max_nfev=max_nfev)
            if reduced is None:
                continue
            if not compare(reduced, current, data, mid, criteria).accepted:
                current = reduced
                dropped.append(mid)
                break
        else:
            break
    return current, dropped
