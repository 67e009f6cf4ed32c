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

"""A diagnosis baseline over loops whose output jumps, when only such a loop fits.

``identify`` searches loops outside the proper set (corners out of order,
``docs/model.md``) when its proper fit stops above the floor
(:mod:`hyst_id.identification.loose_phase`). A diagnosis's baseline searched
proper loops only, so on a clean recording of such a loop (an independent
simulator of the paper's equations drawing its parameters under the paper's
constraints makes them often) the baseline stopped above its floor and a
block filled the gap: ``bench/improper_loops.py --diagnose`` measured false
claims (``friction``, ``supply_decay``) there.

So when the proper baseline ends above :data:`LOOSE_FROM` x the floor of the
training or of the held-out part, a quick identification (the baseline's GAASS
seeds and hopping, no global phase: a few seconds) searches the loose set,
choosing the initial state and sensor hold from the data as the baseline does;
when that ends above :data:`LOOSE_NEAR` x the training floor and within
:data:`LOOSE_RETRY` x of it, or below :data:`LOOSE_HALF` x the proper baseline's
training %e_r, identify's global phase (two runs) searches again. Its
best chain, polished, becomes the baseline only when it fits the training part
within :data:`LOOSE_NEAR` x the floor and either fits the training part
clearly better by identify's rule (:func:`~hyst_id.identification.loose_phase.kept_loose`:
below :data:`~hyst_id.identification.loose_phase.LOOSE_GAIN` x the proper one's
%e_r, or within 1.1 x the floor where the proper one is 1.1 x above it), or within
:data:`LOOSE_EVEN` of it with a held-out %e_r below ``LOOSE_GAIN`` x the proper
one's: then the loop alone explains the record. A
record with physics as well keeps its proper baseline (a loop does not reach the
floor there), so the diagnoses of proper chains are unchanged but for those
seconds. ``python bench/improper_loops.py --diagnose`` measures it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hyst_id.diagnosis.baseline import identify_base
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import Data, evaluate, FitResult, polish
from hyst_id.errors import NoExcitationError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.loose_phase import kept_loose, LOOSE_GAIN, misordered_corners
from hyst_id.io.recording import Recording
from hyst_id.models.tk import loop_is_proper
from hyst_id.signals.noise import floor_percent

__all__ = ['kept_loose_note', 'LOOSE_EVEN', 'LOOSE_FROM', 'LOOSE_HALF', 'LOOSE_NEAR',
           'LOOSE_RETRY', 'loose_baseline']

#: The loose search runs when the proper baseline's training or held-out %e_r is above this
#: multiple of that part's floor (below it a diagnosis claims no block either: a round
#: after the first stops at 1.2 x, ``hyst_id.diagnosis.driver``).
LOOSE_FROM = 1.2

#: A loose chain becomes the baseline only within this multiple of the training floor.
LOOSE_NEAR = 1.3

#: A quick loose fit between :data:`LOOSE_NEAR` and this multiple of the training floor is
#: searched again with identify's global phase (two runs): ``bench/improper_loops.py
#: --diagnose`` #22, a clean improper chain whose quick loose fit stopped short of
#: LOOSE_NEAR and that a ``friction`` block then filled.
LOOSE_RETRY = 2.0

#: ...or anywhere above :data:`LOOSE_NEAR` when it fits the training part within this share of
#: the proper baseline's %e_r (``bench/cmaes_review.py --seeds 2 --diagnose`` 2:r8, a clean
#: improper chain: proper 11 x the floor, the quick loose fit 2.29 x, identify's global phase
#: on the whole record 0.98 x the true noise).
LOOSE_HALF = 0.5

#: ...and when it fits the training part clearly better (``LOOSE_GAIN``), or as well (within
#: this factor) while predicting the held-out part clearly better: a proper loop can match an
#: improper one over the training part's sweeps and miss where the held-out part goes.
LOOSE_EVEN = 1.05


def loose_baseline(rec_train: Recording, spec: ChainSpec, settings: DiagnoseSettings,
                   data: Data, ctx: Context, best: FitResult) -> tuple[FitResult, str]:
    """``best``, or a baseline whose loop is outside the proper set, and the words that say so.

    Parameters
    ----------
    rec_train : Recording
        The training part, in the model's command units.
    spec : ChainSpec
        The baseline's chain (proper loops).
    settings : DiagnoseSettings
        ``loose_loops`` (off: ``best`` as it is), the seeds and sizes of the search.
    data : Data
        The whole record the fits are evaluated on.
    ctx : Context
        What the composed model needs (its ``command_scale`` turns the corners
        back into the recording's command units for the note).
    best : FitResult
        The proper baseline (:func:`hyst_id.diagnosis.challenge.chain_fit`).

    Returns
    -------
    fit : FitResult
        The loose baseline, or ``best``.
    note : str
        Why the loop is not proper ('' when ``best`` is kept).
    """
    model = best.model
    if not settings.loose_loops or not model.spec.proper or model.spec.family.id != 'tk':
        return best, ''
    floor = floor_percent(data.y[:data.n_train], data.noise_std)
    floor_h = floor_percent(data.y[data.n_train:], data.noise_std)
    if not (best.er_train_percent > LOOSE_FROM * floor
            or best.er_holdout_percent > LOOSE_FROM * floor_h):
        return best, ''
    fit = _loose_fit(rec_train, spec, settings, data, ctx, global_runs=0)
    if fit is not None and LOOSE_NEAR * floor < fit.er_train_percent and (
            fit.er_train_percent <= LOOSE_RETRY * floor
            or fit.er_train_percent < LOOSE_HALF * best.er_train_percent):
        wider = _loose_fit(rec_train, spec, settings, data, ctx, global_runs=2)
        if wider is not None and wider.er_train_percent < fit.er_train_percent:
            fit = wider
    if fit is None:
        return best, ''
    # identify's rule (clearly better, or at the floor where the proper loop is not)
    fits = kept_loose(fit.er_train_percent, best.er_train_percent, floor,
                      IdentifySettings.global_factor)
    predicts = (fit.er_train_percent <= LOOSE_EVEN * best.er_train_percent
                and fit.er_holdout_percent < LOOSE_GAIN * best.er_holdout_percent)
    if not (fit.er_train_percent <= LOOSE_NEAR * floor and (fits or predicts)):
        return best, ''
    if loop_is_proper(*fit.p[:8]):
        return best, ''     # a proper loop the baseline had missed: left to its own search
    return fit, _note(fit.p[:8], ctx, best.er_train_percent / floor,
                      fit.er_train_percent / floor)


def _loose_fit(rec_train: Recording, spec: ChainSpec, settings: DiagnoseSettings, data: Data,
               ctx: Context, global_runs: int) -> FitResult | None:
    """The loose identification of the training part, polished in the composed model.

    The baseline's seeds and hopping, conventions from the data, ``global_runs``
    runs of identify's global phase (0: the quick search). None when the part
    no longer excites the loop or no run ended.
    """
    wide = {'global_runs': global_runs, 'global_evals': IdentifySettings.global_evals}
    try:
        ident = identify(rec_train, spec=replace(spec, proper=False), settings=IdentifySettings(
            **{**identify_base(settings), **wide, 'conventions': 'auto'}),
            should_stop=settings.should_stop)
    except NoExcitationError:
        return None
    if not ident.runs:
        return None
    run = min(ident.runs, key=lambda r: r.fun)
    loose = ComposedModel(rec_train.channel, [], ctx, spec.bounds, hold=run.hold,
                          initial=run.initial, proper=False)
    x0 = np.array(run.x_raw, dtype=float)
    p, _, nfev = polish(loose, data, x0, max_nfev=2 * settings.fit_budget)
    return evaluate(loose, data, p, nfev)


def kept_loose_note(final: FitResult, note: str) -> tuple[bool, str]:
    """Whether the diagnosis's final loop is proper, and ``note`` only when it is not.

    A loose baseline's blocks may bring the chain back to a proper loop; the
    note that the loop is not proper then no longer holds.
    """
    proper = (bool(loop_is_proper(*final.p[:8])) if final.model.spec.family.id == 'tk'
              else True)
    return proper, '' if proper else note


def _note(h: np.ndarray, ctx: Context, proper_ratio: float, loose_ratio: float) -> str:
    """What the loop outside the proper set is, in the recording's command units."""
    out = misordered_corners(h, tuple(ctx.command_scale))
    return (f"the chain's loop is not a proper one: the best proper loop fits the training "
            f'part at {proper_ratio:.2f} x its noise floor, one whose corners are out of order '
            f"(the paper's constraints admit it) at {loose_ratio:.2f} x (command at the "
            f'corners: {out}; A, D: the left line at the bottom and top lines, B, '
            "C: the right line), and the diagnosis runs over such loops. The paper's step "
            'rule makes its output jump at reversals between those corners, as another '
            'simulator of its equations may, or an actuator that snaps; H^-1 is no exact '
            'inverse of it (the compensator refuses this set)')
