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

"""A candidate block searched jointly with the chain, over the whole box.

A round fits each block locally, warm-started from the current chain
(:func:`hyst_id.diagnosis.select.fit_model`), and the winner's chain is then
identified afresh with the blocks undone (:mod:`.refit`). Neither leaves a
basin where the chain has absorbed the missing effect in a way the block
cannot undo: a friction band runs against the hysteresis loop, so the
baseline makes its loop narrower by the band, and the block, fitted around
that chain, finds a force a fraction of the true one. On the blind family's
#175 (friction on a pressure channel, random steps, a 5.8 s sensor) the
friction block stopped at 1.51 x the training floor and 7.2 x the held-out
one, whatever was re-identified; differential evolution over the chain and
the block together (the linear parts solved at each point, as in every fit)
reached 1.03-1.09 x on training and 1.31-2.48 x held out, in four random
streams, 4-5 s each (``python bench/joint_search.py``).

:func:`joint_search` is that search: scipy's ``differential_evolution`` over
the composed model's parameters within their bounds, the current values in
its first population (so it ends no worse on the training part), a fixed
random stream, then the least-squares polish. Once a round's candidates are
fitted locally, :func:`hyst_id.diagnosis.trial.try_all` runs it on the
:data:`JOINT_LEADERS` whose local fits lower the training BIC the most, among
those that lower it by more than the criteria's drop (they found something)
yet stay above :data:`JOINT_ABOVE` times the training floor (what they found
may be a basin's share); the search's fit replaces the local one, and the
candidate is judged again, when it is better on the training part and not
worse on the judged held-out samples (the rule of
:func:`hyst_id.diagnosis.refit.reidentify`). Only the leaders, for time: a
search costs seconds (``docs/diagnosis.md``, "The joint search"). The exchanges
(:mod:`.exchange`) fit their rivals through the same round, so a rival is searched
too. A model whose H family was swapped (``loop_shape``, ``bouc_wen``) is not searched,
as :mod:`.refit` does not re-identify it: its chain has its own baseline fit.

Off by default (``DiagnoseSettings.joint_generations`` 0; ``diagnose
--joint-generations 300`` turns it on): its seconds, two searches a round, made the test
suite's diagnoses too slow for its time budget.

Most of the box violates the chain's constraints (about 1 % of uniform
points are feasible), so the search needs its generations: on #175, 200 of
them left the start in place, 300 left it in each of four streams.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.optimize import differential_evolution
from threadpoolctl import threadpool_limits

from hyst_id.diagnosis.select import Data, evaluate, FitResult, polish, training_sse
from hyst_id.identification.workers import WorkersStopped
from hyst_id.signals.noise import floor_percent

__all__ = ['JOINT_ABOVE', 'JOINT_LEADERS', 'JOINT_POPSIZE', 'joint_search', 'worth_searching']

#: A candidate's local fit within this factor of the training floor is not searched again.
JOINT_ABOVE = 1.1

#: Candidates of a round searched: those with the lowest training BIC among the worthy.
JOINT_LEADERS = 2

#: Population per parameter of the search (scipy's default).
JOINT_POPSIZE = 15


def worth_searching(fit: FitResult, delta_bic: float, data: Data, bic_drop: float) -> bool:
    """Whether a candidate's local fit found something and may have stopped in a basin.

    Parameters
    ----------
    fit : FitResult
        The candidate's local fit.
    delta_bic : float
        Its training BIC against the model it extends.
    data : Data
        The record (its noise and training part give the floor).
    bic_drop : float
        The criteria's BIC drop.
    """
    if fit.model is None or fit.model.swapped_by or not delta_bic < -bic_drop:
        return False
    return fit.er_train_percent > JOINT_ABOVE * floor_percent(data.y[:data.n_train],
                                                              data.noise_std)


def joint_search(fit: FitResult, data: Data, *, generations: int, polish_nfev: int,
                 seed: int = 0, should_stop: Callable[[], bool] | None = None) -> FitResult:
    """``fit``'s model searched over its whole box, started from its values; the better fit.

    Parameters
    ----------
    fit : FitResult
        A composed model's fit (chain and blocks).
    data : Data
        The record in the model's command units.
    generations : int
        Differential-evolution generations (0: none, ``fit`` is returned).
    polish_nfev : int
        Least-squares evaluations of the polish after the search.
    seed : int, optional
        The search's random stream.
    should_stop : callable, optional
        Looked at after every generation; when it holds the search ends and
        :class:`~hyst_id.identification.workers.WorkersStopped` is raised.

    Returns
    -------
    FitResult
        The search's fit when it is better on the training part and not worse on
        the judged held-out samples; else ``fit`` (also for a model with a swapped
        family, as :mod:`.refit` leaves those, or no feasible start).
    """
    model = fit.model
    if model is None or model.swapped_by or generations <= 0:
        return fit
    cost = training_sse(model, data)
    x0 = np.clip(fit.p, model.bounds[:, 0], model.bounds[:, 1])
    if not model.feasible(x0):
        return fit
    with threadpool_limits(limits=1):
        res = differential_evolution(cost, model.bounds, maxiter=generations,
                                     popsize=JOINT_POPSIZE, tol=0.0, atol=0.0, polish=False,
                                     x0=x0, init='latinhypercube', updating='deferred',
                                     rng=np.random.default_rng([seed, 14, 17]),
                                     callback=None if should_stop is None
                                     else (lambda intermediate_result: bool(should_stop())))
        if should_stop is not None and should_stop():
            raise WorkersStopped('stopped on request in the joint search')
        p = np.asarray(res.x, dtype=float)
        if not model.feasible(p):
            return fit
        p, _, nfev = polish(model, data, p, max_nfev=polish_nfev)
        got = evaluate(model, data, p, fit.nfev + int(res.nfev) + nfev)
    if not got.sse_train < fit.sse_train:       # NaN included
        return fit
    if data.n_holdout and not data.judged_er_percent(got) <= data.judged_er_percent(fit):
        return fit
    return got
