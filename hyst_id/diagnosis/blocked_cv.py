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

"""Blocked cross-validation: each time block predicted by a fit on the others.

The diagnosis judges blocks on one time split (the last 30 % held out).
That split can fail to decide: a held-out part with little excitation, or
one whose command leaves the training range, says little about a block that
acts elsewhere. Blocked cross-validation cuts the whole record into
``n_blocks`` blocks of equal duration; for each block it refits a model
(bounded least squares from the model's values, all parameters free, the
linear part solved again) on the samples *outside* the block and predicts
the block. A hysteresis carries its state through the block, so the model
is simulated over the whole record and only the fit is masked: the block's
outputs are not in the refit's residuals nor in its linear solve. The refit
starts from the model's values, fitted on the training part, and its budget
is small (``max_nfev``), so the nonlinear parameters stay near values that
saw the first blocks' outputs: for those blocks the figures lean optimistic,
for both models alike (the comparison is between them); the last block
(held out of the training part) is clean.

Each block is judged on its samples whose command lies inside the range the
fitting samples cover (within ``tol`` of it); the others are extrapolation,
counted apart. So are the first block's samples before the command has swept
that range: until then the output depends on the record's initial state,
which the later blocks do not constrain (in a first version that judged it
whole, a dead-time model refitted on the last three quarters of a synthetic
record missed the first quarter by far more than the others; not kept as a
figure). Two models A and B are compared block by block by the same
improvement z as the single split (:func:`hyst_id.diagnosis.select.improvement_z`),
both ways, and by the %e_r each leaves there: B is better in a block where
A's residual projects on B - A beyond ``z_min`` noise units and B's %e_r is
the lower, worse where B's residual projects on A - B that far and A's %e_r
is the lower.

What it can and cannot say (``docs/diagnosis.md``, "Blocked cross-validation"):
a block that is the missing physics is better in every time block; so is a
block that fills a gap the baseline's chain leaves, so it does not separate
the two. It confirms the single split's claims (:meth:`BlockedCV.confirm`)
and decides a round only where the split judged too little
(:data:`SPLIT_MINORITY`, :meth:`BlockedCV.decide`): between tied blocks on a
split that judges most of its held-out part it was right once and wrong
twice (``bench/blocked_ties.py``), so there the split decides.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hyst_id.diagnosis.model import ComposedModel, solve_linear
from hyst_id.diagnosis.select import Comparison, Data, FitResult, improvement_z, polish
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import er_percent

__all__ = ['BlockedCV', 'BlockPrediction', 'BlockVerdict', 'block_predictions', 'compare_blocked',
           'confirm', 'confirmed', 'N_BLOCKS', 'SPLIT_MINORITY', 'split_record',
           'summary', 'UNCONFIRMED_WORSE']

#: blocks of the record (four: each holds a quarter, the fit sees three quarters,
#: about what the single split's 70 % training part holds)
N_BLOCKS = 4

#: a block the model without it predicts better in at least this many time blocks (and
#: in at least as many as the block helps) is not confirmed (:func:`confirmed`). On 48
#: recordings of the blind family (``bench/blind_family.py --indices ...``, the command in
#: docs/diagnosis.md) the 31 findings that were an effect of the recording were worse in
#: 0 (25) or 1 (6) of the time blocks; 5 of the 23 that were not were worse in 2 or 3
UNCONFIRMED_WORSE = 2

#: The single split decides a round alone unless it judges fewer than this share of its
#: held-out samples (the held-out command left the training range early:
#: :func:`hyst_id.signals.split.inside_rows`); then :meth:`BlockedCV.decide` may.
SPLIT_MINORITY = 0.5


@dataclass
class BlockPrediction:
    """One model's prediction of every block from fits on the other blocks."""

    #: [start, stop) row index of each block
    bounds: list[tuple[int, int]]
    #: the whole record, each block's rows predicted by the fit without it
    prediction: np.ndarray
    #: rows (absolute) judged in each block: the command inside the fitted range
    judged: list[np.ndarray]
    #: rows of each block whose command lies outside the fitted range
    n_extrapolated: list[int]
    #: rows of the first block inside the range but before the command swept it
    n_unswept: list[int] = field(default_factory=list)
    #: function evaluations the fits took
    nfev: int = 0


@dataclass
class BlockVerdict:
    """Model B against model A, block by block."""

    er_a_percent: list[float]
    er_b_percent: list[float]
    floor_percent: list[float]
    #: improvement z of B over A in each block (the residual of A projected on B - A)
    z: list[float]
    #: the same of A over B
    z_back: list[float]
    n_judged: list[int]
    n_extrapolated: list[int]
    n_unswept: list[int]
    #: blocks where B predicts significantly better (``z`` above ``z_min``, lower %e_r)
    better: int
    #: blocks where A predicts significantly better (``z_back`` above ``z_min``, lower %e_r)
    worse: int

    @property
    def n_blocks(self) -> int:
        """Blocks with judged samples."""
        return sum(1 for n in self.n_judged if n > 0)

    def to_dict(self) -> dict:
        """JSON-ready figures."""
        return {'blocks': self.n_blocks, 'better': self.better, 'worse': self.worse,
                'er_a_percent': self.er_a_percent, 'er_b_percent': self.er_b_percent,
                'noise_floor_percent': self.floor_percent, 'z': self.z,
                'z_back': self.z_back,
                'n_judged': self.n_judged, 'n_extrapolated': self.n_extrapolated,
                'n_unswept': self.n_unswept}


def _block_bounds(t_s: np.ndarray, n_blocks: int) -> list[tuple[int, int]]:
    edges = t_s[0] + (t_s[-1] - t_s[0]) * np.arange(n_blocks + 1) / n_blocks
    cut = np.searchsorted(t_s, edges[1:-1])
    starts = np.concatenate([[0], cut])
    stops = np.concatenate([cut, [t_s.size]])
    return [(int(a), int(b)) for a, b in zip(starts, stops)]


def _refit(model: ComposedModel, data: Data, p0: np.ndarray, rows: np.ndarray,
           max_nfev: int) -> tuple[np.ndarray, int]:
    """:func:`~hyst_id.diagnosis.select.polish` on ``rows``; the whole record's prediction."""
    p, _, nfev = polish(model, data, p0, max_nfev=max_nfev, rows=rows)
    a = model.evaluate(p, data.t_s, data.v, data.n_train).matrix()
    coef, _ = solve_linear(a[rows], data.y[rows])
    return a @ coef, nfev


def _swept(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Samples after the command has reached both ``lo`` and ``hi`` (a state of its own)."""
    reached = (np.minimum.accumulate(v) <= lo) & (np.maximum.accumulate(v) >= hi)
    return reached


def block_predictions(fit: FitResult, data: Data, *, n_blocks: int = N_BLOCKS,
                      max_nfev: int = 60, tol: float = 0.02) -> BlockPrediction:
    """Predict every time block of the record by a refit of ``fit`` on the others.

    Parameters
    ----------
    fit : FitResult
        A fitted model (its ``model`` and values ``p`` start each refit).
    data : Data
        The record.
    n_blocks : int
        Blocks of equal duration.
    max_nfev : int
        Budget of each refit's least squares (its Jacobian evaluations aside).
    tol : float
        Share of the fitted command range a judged sample may lie outside it.

    Returns
    -------
    BlockPrediction
    """
    if not 2 <= n_blocks <= data.y.size // 10:
        raise ConfigError(f'blocked cross-validation needs 2 to {data.y.size // 10} blocks '
                          f'of at least 10 samples, got {n_blocks}')
    bounds = _block_bounds(data.t_s, n_blocks)
    pred = np.array(fit.prediction, dtype=float)
    judged, extrapolated, unswept, nfev = [], [], [], 0
    every = np.arange(data.y.size)
    for a, b in bounds:
        if b <= a:      # no sample in this block (a gap in the record)
            judged.append(every[a:a])
            extrapolated.append(0)
            unswept.append(0)
            continue
        rows = np.concatenate([every[:a], every[b:]])
        whole, k = _refit(fit.model, data, fit.p, rows, max_nfev)
        nfev += k
        pred[a:b] = whole[a:b]
        lo, hi = float(np.min(data.v[rows])), float(np.max(data.v[rows]))
        margin = tol * (hi - lo)
        inside = (data.v[a:b] >= lo - margin) & (data.v[a:b] <= hi + margin)
        swept = (_swept(data.v[a:b], lo + margin, hi - margin) if a == 0
                 else np.ones(b - a, dtype=bool))   # before: the record's initial state
        judged.append(every[a:b][inside & swept])
        extrapolated.append(int(np.count_nonzero(~inside)))
        unswept.append(int(np.count_nonzero(inside & ~swept)))
    return BlockPrediction(bounds=bounds, prediction=pred, judged=judged,
                           n_extrapolated=extrapolated, n_unswept=unswept, nfev=nfev)


def compare_blocked(a: BlockPrediction, b: BlockPrediction, data: Data, *,
                    z_min: float = 4.0) -> BlockVerdict:
    """Model ``b`` against model ``a`` on each block's judged samples.

    Both predictions must come from :func:`block_predictions` on the same
    ``data`` and ``n_blocks``.
    """
    er_a, er_b, floors, zs, zs_back, n_j = [], [], [], [], [], []
    for rows in a.judged:
        y = data.y[rows]
        n_j.append(int(rows.size))
        if rows.size == 0:
            er_a.append(float('nan'))
            er_b.append(float('nan'))
            floors.append(float('nan'))
            zs.append(0.0)
            zs_back.append(0.0)
            continue
        ra, rb = y - a.prediction[rows], y - b.prediction[rows]
        er_a.append(float(er_percent(float(ra @ ra), y)))
        er_b.append(float(er_percent(float(rb @ rb), y)))
        floors.append(float(np.sqrt(rows.size * data.noise_std ** 2
                                    / max(float(y @ y), 1e-300)) * 100.0))
        zs.append(improvement_z(a.prediction[rows], b.prediction[rows], y, data.noise_std))
        zs_back.append(improvement_z(b.prediction[rows], a.prediction[rows], y,
                                     data.noise_std))
    return BlockVerdict(er_a_percent=er_a, er_b_percent=er_b, floor_percent=floors, z=zs,
                        z_back=zs_back, n_judged=n_j, n_extrapolated=list(a.n_extrapolated),
                        n_unswept=list(a.n_unswept),
                        better=sum(1 for z, a_, b_ in zip(zs, er_a, er_b)
                                   if z > z_min and b_ < a_),
                        worse=sum(1 for z, a_, b_ in zip(zs_back, er_a, er_b)
                                  if z > z_min and b_ > a_))


class BlockedCV:
    """Blocked cross-validation of the models of one record, each model's blocks refitted once.

    A diagnosis compares each accepted block against the model before it and
    the final model against the baseline; the same fit recurs (the baseline,
    a finding's model that is also the final one), so its block predictions
    are kept.
    """

    def __init__(self, data: Data, *, n_blocks: int = N_BLOCKS, z_min: float = 4.0,
                 max_nfev: int = 60) -> None:
        self.data, self.n_blocks, self.z_min, self.max_nfev = data, n_blocks, z_min, max_nfev
        self._predicted: dict[int, tuple[FitResult, BlockPrediction]] = {}

    def predict(self, fit: FitResult) -> BlockPrediction:
        """:func:`block_predictions` of ``fit``, computed once."""
        if id(fit) not in self._predicted:      # the fit is kept, so its id is not reused
            self._predicted[id(fit)] = (fit, block_predictions(
                fit, self.data, n_blocks=self.n_blocks, max_nfev=self.max_nfev))
        return self._predicted[id(fit)][1]

    def decide(self, winner: Comparison, rivals: list[Comparison]) -> tuple[Comparison, dict]:
        """The round's block when the single split judged too little to decide alone.

        When the split judges fewer than :data:`SPLIT_MINORITY` of its
        held-out samples (the held-out command left the training range
        early), its winner rests on a short stretch. A rival (a candidate
        tied with the winner or a close call) that predicts *every* judged
        time block better than the winner, in at least two, takes the round;
        of several, the one with the lowest summed %e_r over the blocks. On
        the shared M130 steel B(H) loops (60 of 231 held-out samples judged)
        ``creep`` won the split and ``loop_shape`` predicted all three judged
        quarters better (``python bench/real_diagnoses.py --only M130``).

        Returns
        -------
        tuple
            The chosen comparison, and (when it is not ``winner``) the
            rival's :meth:`BlockVerdict.to_dict` against the winner with
            ``over`` (the split's winner); else ``{}``.
        """
        if not rivals or not self.split_short:
            return winner, {}
        chosen, best, key = winner, {}, np.inf
        for c in rivals:
            v = self.beats(winner.fit, c.fit)
            total = np.inf if v is None else float(np.nansum(v.er_b_percent))
            if total < key:
                chosen, best, key = c, v.to_dict(), total
        if chosen is not winner:
            best.update(over=winner.mechanism, z_min=self.z_min)
        return chosen, best

    @property
    def split_short(self) -> bool:
        """Whether the split judges fewer than :data:`SPLIT_MINORITY` of its held-out samples."""
        return self.data.judged_rows.size < SPLIT_MINORITY * self.data.n_holdout

    def beats(self, fit: FitResult, rival: FitResult) -> BlockVerdict | None:
        """``rival`` against ``fit`` if it predicts all judged time blocks better (>=2), else None.

        Both models are refitted per block (:meth:`predict`, kept for the
        diagnosis); the verdict is :func:`compare_blocked`'s.
        """
        v = compare_blocked(self.predict(fit), self.predict(rival), self.data, z_min=self.z_min)
        return v if v.n_blocks >= 2 and v.better == v.n_blocks else None

    def confirm(self, before: FitResult, after: FitResult) -> dict:
        """Blocked cross-validation of ``after`` (a model with a block more) against ``before``.

        Returns
        -------
        dict
            :meth:`BlockVerdict.to_dict` of the two models' block predictions,
            with the blocks' time bounds (``t_s``: [start, stop] in s) and
            ``z_min``; JSON-ready.
        """
        a, b = self.predict(before), self.predict(after)
        out = compare_blocked(a, b, self.data, z_min=self.z_min).to_dict()
        t = self.data.t_s
        out['t_s'] = [[float(t[i]), float(t[j - 1])] if j > i else [float('nan')] * 2
                      for i, j in a.bounds]
        out['z_min'] = self.z_min
        return out


def confirm(before: FitResult, after: FitResult, data: Data, *, n_blocks: int = N_BLOCKS,
            z_min: float = 4.0, max_nfev: int = 60) -> dict:
    """:meth:`BlockedCV.confirm` once (see there)."""
    return BlockedCV(data, n_blocks=n_blocks, z_min=z_min, max_nfev=max_nfev).confirm(
        before, after)


def confirmed(cv: dict) -> bool:
    """Whether a block's blocked cross-validation (:func:`confirm`) holds it up.

    Not confirmed: the model without the block predicts at least
    :data:`UNCONFIRMED_WORSE` time blocks better and at least as many as the
    block improves. An empty ``cv`` (not computed), or one that judged no
    block, confirms: with nothing judged there is nothing against the block.
    """
    if not cv:
        return True
    worse, better = int(cv.get('worse') or 0), int(cv.get('better') or 0)
    return not (worse >= UNCONFIRMED_WORSE and worse >= better)


def split_record(split: Comparison, chosen: Comparison, data: Data, cv: dict) -> dict:
    """A finding's alternative (kind ``split``): the split's winner that blocked CV overruled.

    With its held-out %e_r (all held-out rows and the judged ones), how many
    held-out samples the split judged, the judged %e_r of ``chosen`` (the
    finding's model), and ``cv``, the finding's block against it per time
    block.
    """
    return {'mechanism': split.mechanism, 'kind': 'split',
            'er_holdout_after_percent': split.fit.er_holdout_percent,
            'er_judged_after_percent': data.judged_er_percent(split.fit),
            'er_judged_chosen_percent': data.judged_er_percent(chosen.fit),
            'n_judged': int(data.judged_rows.size), 'n_holdout': data.n_holdout,
            'blocked_cv': cv}


def summary(cv: dict) -> str:
    """One sentence: in how many time blocks the model with the block predicts better."""
    ratios = ', '.join(f'{b / a:.2f}' if a > 0 else '-'
                       for a, b in zip(cv['er_a_percent'], cv['er_b_percent']))
    extra, unswept = sum(cv['n_extrapolated']), sum(cv.get('n_unswept') or [0])
    tail = (f'; {extra} samples outside the fitted command range not judged'
            if extra else '')
    tail += (f'; {unswept} samples of the first block before the command swept the range '
             'not judged' if unswept else '')
    n_all = len(cv['er_a_percent'])
    blocks = (f"{cv['blocks']} time blocks" if n_all == cv['blocks'] else
              f"{n_all} time blocks, {cv['blocks']} judged")
    return (f'blocked cross-validation ({blocks}, each predicted by a refit on the others): '
            f"better in {cv['better']}, worse in {cv['worse']} (|z| > {cv['z_min']:g}); %e_r "
            f"after / before per block {ratios}{' (-: not judged)' if '-' in ratios else ''}"
            f'{tail}')
