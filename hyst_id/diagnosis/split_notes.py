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

"""A diagnosis's time split: big enough to judge by, and notes on what it holds out."""

from __future__ import annotations

import numpy as np

from hyst_id.errors import RecordingError
from hyst_id.signals.split import level_excursion

__all__ = ['MIN_HELDOUT_SAMPLES', 'MIN_TRAIN_SAMPLES', 'level_note', 'range_note',
           'require_split']

#: Fewest training samples a diagnosis fits blocks on: the chain has 11-13 parameters
#: and a block up to three more; on 35 (a new-user trial's 50-sample record) a
#: dead time was claimed on a record that had none.
MIN_TRAIN_SAMPLES = 100
#: Fewest held-out samples a block is judged on.
MIN_HELDOUT_SAMPLES = 40


def require_split(n_train: int, n_total: int) -> None:
    """A :class:`RecordingError` when the split leaves too few samples to judge a block by."""
    if n_train < MIN_TRAIN_SAMPLES or n_total - n_train < MIN_HELDOUT_SAMPLES:
        raise RecordingError(
            f'record too short to diagnose: {n_train} training and {n_total - n_train} '
            f'held-out samples (need at least {MIN_TRAIN_SAMPLES} and '
            f'{MIN_HELDOUT_SAMPLES} to judge a block); identify can still fit it')


def range_note(v: np.ndarray, n_train: int, n_judged: int | None = None) -> list[str]:
    """A warning when the held-out command leaves the training range (extrapolation).

    With ``n_judged`` (held-out samples the blocks were judged on, see
    :func:`hyst_id.signals.split.inside_rows`) the note says which part decided.
    """
    lo_t, hi_t = float(np.min(v[:n_train])), float(np.max(v[:n_train]))
    lo_h, hi_h = float(np.min(v[n_train:])), float(np.max(v[n_train:]))
    if max(lo_t - lo_h, hi_h - hi_t) > 0.05 * (hi_t - lo_t):
        note = (f'the held-out command reaches {lo_h:.4g} to {hi_h:.4g}, beyond the training '
                f'range {lo_t:.4g} to {hi_t:.4g}: held-out errors there are extrapolation of '
                'the model, not necessarily missing physics')
        if n_judged is not None and n_judged < (n_ho := v.size - n_train):
            note += (f'; the blocks were judged on the first {n_judged} of {n_ho} held-out '
                     'samples, before the command first leaves the training range')
        return [note]
    return []


def level_note(y: np.ndarray, n_train: int) -> list[str]:
    """A note when a fifth or more of the held-out measurement lies beyond the training levels.

    Made only when the held-out command stays inside its training range (else
    :func:`range_note` already names the likelier cause).
    """
    share, lo, hi, lo_h, hi_h = level_excursion(y, n_train)
    return [] if share < 0.2 else [
        f'{100 * share:.0f} % of the held-out measurement lies beyond the levels of the '
        f'training part ({lo_h:.4g} to {hi_h:.4g} against {lo:.4g} to {hi:.4g}): an end '
        'stop or plateau reached only later, or a drift; blocks fitted on the training '
        'part were never shown those levels, so the split can leave them undecided']
