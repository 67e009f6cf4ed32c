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

"""Choose H's family on held-out data: fit each on the first part, score the rest.

Every candidate family is identified (:func:`~hyst_id.identification.driver.identify`)
on the first ``fit_share`` of the recording's *duration*; its parameter set then
simulates the whole recording (the state runs on through the split) and the
held-out part is scored by %e_r. The family with the lower held-out %e_r wins and
is identified again on the whole recording, which is the result a user gets. A
tie (held-out errors within ``tie_ratio`` of each other) goes to the family listed
first, the paper's ``tk`` by default: the simpler loop keeps the paper's
parameters and its inverse's clean corners.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Sequence

import numpy as np

from hyst_id.errors import IdentificationError, RecordingError
from hyst_id.identification.domains import domains_from_data
from hyst_id.identification.driver import identify
from hyst_id.identification.result import Identification, IdentifySettings
from hyst_id.io.recording import Recording, validate_recording
from hyst_id.models.registry import get_family

__all__ = ['AUTO_FAMILIES', 'MIN_HELD_OUT', 'FamilyScore', 'ModelChoice', 'choose_family',
           'format_choice', 'holdout_error']

#: Fewest samples the held-out part may have (it needs no excitation of its own).
MIN_HELD_OUT = 20
#: Families ``auto`` compares, in tie-break order.
AUTO_FAMILIES = ('tk', 'smooth')


@dataclass(frozen=True)
class FamilyScore:
    """One family's fit on the training part and its error on the held-out part.

    Attributes
    ----------
    family : str
        Family id.
    train_er_percent, holdout_er_percent : float
        %e_r on the training and on the held-out part.
    identification : Identification
        The fit on the training part.
    """

    family: str
    train_er_percent: float
    holdout_er_percent: float
    identification: Identification


@dataclass(frozen=True)
class ModelChoice:
    """Result of :func:`choose_family`.

    Attributes
    ----------
    chosen : str
        The family with the lowest held-out %e_r (ties to the first listed).
    scores : tuple of FamilyScore
        Every candidate, in the order given.
    identification : Identification
        The chosen family identified on the whole recording.
    fit_share : float
        Share of the duration used for training.
    """

    chosen: str
    scores: tuple
    identification: Identification
    fit_share: float

    def to_dict(self) -> dict:
        """JSON-ready summary of the comparison (without the full fits)."""
        return {'chosen': self.chosen, 'fit_share': self.fit_share,
                'families': [{'family': s.family, 'train_er_percent': s.train_er_percent,
                              'holdout_er_percent': s.holdout_er_percent}
                             for s in self.scores]}


def holdout_error(ident: Identification, rec: Recording, n_train: int) -> tuple[float, float]:
    """%e_r of ``ident`` on ``rec[:n_train]`` and ``rec[n_train:]``, simulating all of ``rec``."""
    pred = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    y = rec.measurement

    def er(a: np.ndarray, b: np.ndarray) -> float:
        r = a - b
        return float(np.sqrt((r @ r) / max(float(a @ a), 1e-300)) * 100.0)

    return er(y[:n_train], pred[:n_train]), er(y[n_train:], pred[n_train:])


def choose_family(recording: Recording, families: Sequence[str] = AUTO_FAMILIES, *,
                  settings: IdentifySettings | None = None, fit_share: float = 0.7,
                  tie_ratio: float = 1.02,
                  progress: Callable[[str, str], None] | None = None,
                  seed_progress: Callable | None = None,
                  on_generation: Callable | None = None,
                  should_stop: Callable | None = None) -> ModelChoice:
    """Identify each family on the first part, keep the one that predicts the rest best.

    Parameters
    ----------
    recording : Recording
        The whole run.
    families : sequence of str
        Registered family ids (:mod:`hyst_id.models.registry`), in tie-break order.
    settings : IdentifySettings, optional
        Settings for every fit (default the package's).
    fit_share : float
        Share of the duration to train on, in (0.3, 0.95).
    tie_ratio : float
        A later family must beat the best earlier one by more than this factor.
    progress : callable, optional
        Called as ``progress(family, stage)`` with stage ``'train'`` or ``'final'``.
    seed_progress, on_generation, should_stop : callable, optional
        Passed to every :func:`identify` as its ``progress``, ``on_generation``
        and ``should_stop``.

    Returns
    -------
    ModelChoice

    Raises
    ------
    IdentificationError
        Fewer than one family, an unknown family, a split with too little
        data or excitation on either side.
    """
    fams = tuple(dict.fromkeys(str(f) for f in families))
    if not fams:
        raise IdentificationError('no hysteresis family to choose from')
    for fam in fams:
        get_family(fam)
    if not 0.3 <= fit_share <= 0.95:
        raise IdentificationError(f'fit_share must be in [0.3, 0.95], got {fit_share}')
    rec = validate_recording(recording)
    train, held = rec.split(fit_share)
    try:
        train = validate_recording(train)
        if held.n_samples < MIN_HELD_OUT:
            raise RecordingError(f'{held.n_samples} samples held out (need {MIN_HELD_OUT})')
    except RecordingError as exc:
        raise IdentificationError(
            f'cannot hold out the last {1 - fit_share:.0%} of the recording to choose the '
            f'family: {exc}; pass a family explicitly') from exc
    settings = settings or IdentifySettings()
    scores = []
    # the families are compared on their basins, not on the last per cent of a floor: the
    # wrong family's fit is off its floor by design, and the longer global runs and
    # hopping within 4 x would be spent on it (minutes); the chosen family's final fit
    # gets the whole schedule
    compare = replace(settings, long_runs_within=min(settings.long_runs_within, 1.5),
                      global_runs=min(settings.global_runs, 6))
    for fam in fams:
        if progress:
            progress(fam, 'train')
        ident = identify(train, spec=domains_from_data(train, family=fam), settings=compare,
                         progress=seed_progress, on_generation=on_generation,
                         should_stop=should_stop)
        tr, ho = holdout_error(ident, rec, train.n_samples)
        scores.append(FamilyScore(fam, tr, ho, ident))
    best = scores[0]
    for s in scores[1:]:
        if s.holdout_er_percent * tie_ratio < best.holdout_er_percent:
            best = s
    if progress:
        progress(best.family, 'final')
    final = identify(rec, spec=domains_from_data(rec, family=best.family), settings=settings,
                     progress=seed_progress, on_generation=on_generation,
                     should_stop=should_stop)
    return ModelChoice(best.family, tuple(scores), final, fit_share)


def format_choice(choice: ModelChoice) -> str:
    """A small table: each family's training and held-out %e_r, and which was kept."""
    lines = [f'H family chosen on held-out data (fit on the first {choice.fit_share:.0%} of '
             'the duration):', '',
             '| family | %e_r fit | %e_r held out | |', '|---|---|---|---|']
    for s in choice.scores:
        mark = 'kept' if s.family == choice.chosen else ''
        lines.append(f'| {s.family} | {s.train_er_percent:.4f} | '
                     f'{s.holdout_er_percent:.4f} | {mark} |')
    return '\n'.join(lines)
