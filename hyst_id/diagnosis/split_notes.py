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
from scipy.stats import spearmanr

from hyst_id.errors import RecordingError
from hyst_id.signals.reversals import reversal_indices
from hyst_id.signals.split import level_excursion

__all__ = ['LEVEL_SHAPES', 'MIN_HELDOUT_SAMPLES', 'MIN_SWINGS', 'MIN_TRAIN_SAMPLES', 'SWING_RHO',
           'TIME_GAINS', 'level_note', 'range_note', 'require_split', 'swing_note',
           'swing_trend']

#: Fewest training samples a diagnosis fits blocks on: the chain has 11-13 parameters
#: and a block up to three more; on 35 (a new-user trial's 50-sample record) a
#: dead time was claimed on a record that had none.
MIN_TRAIN_SAMPLES = 100
#: Fewest held-out samples a block is judged on.
MIN_HELDOUT_SAMPLES = 40


def require_split(n_train: int, n_total: int) -> None:
    """A :class:`RecordingError` when the split leaves too few samples to judge a block by."""
    if n_train < MIN_TRAIN_SAMPLES or n_total - n_train < MIN_HELDOUT_SAMPLES:
        if n_total >= MIN_TRAIN_SAMPLES + MIN_HELDOUT_SAMPLES:     # the split, not the record
            raise RecordingError(
                f'the training fraction leaves {n_train} training and {n_total - n_train} '
                f'held-out samples of {n_total} (need at least {MIN_TRAIN_SAMPLES} and '
                f'{MIN_HELDOUT_SAMPLES} to judge a block): choose a train_fraction '
                '(--train-fraction) nearer 0.7')
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


#: Blocks whose gain changes with time, and blocks that shape the response over the level.
TIME_GAINS = frozenset({'gain_drift', 'gain_loss', 'supply_decay'})
LEVEL_SHAPES = frozenset({'static_nonlinearity', 'saturation', 'loop_shape'})
#: The command's swings (reversal to reversal) trend with time when their rank correlation
#: with time is at least this large (the blind family: every decaying sine at -1, 3 of 29
#: chirps and 1 of 34 minor-loop runs; ``bench/swing_trends.py``) ...
SWING_RHO = 0.8
#: ... over at least this many swings.
MIN_SWINGS = 8


def swing_trend(t_s: np.ndarray, v: np.ndarray) -> tuple[float, np.ndarray]:
    """Rank correlation of the command's reversal-to-reversal swings with their times.

    Returns the correlation (NaN with fewer than :data:`MIN_SWINGS` swings, or when
    every swing is equal: no trend, and no rank correlation) and the swings.
    """
    idx, _ = reversal_indices(v)
    if idx.size < MIN_SWINGS + 1:
        return float('nan'), np.zeros(0)
    swing = np.abs(np.diff(v[idx]))
    if np.ptp(swing) == 0.0:
        return float('nan'), swing
    return float(spearmanr(t_s[idx[1:]], swing).statistic), swing


def swing_note(t_s: np.ndarray, v: np.ndarray, named) -> list[str]:
    """A note when the command's swing trends with time and a time gain or level shape is named.

    On such a record (the decaying sine of the paper's Eq. 24) the large
    swings come early and the small ones late, so a gain that changes with
    time and a curve or loop shape over the level act alike: the new-user
    trial's force reading, whose gain fell 30 % over a decaying sine, was
    named ``static_nonlinearity`` and ``loop_shape``.

    Parameters
    ----------
    t_s, v : numpy.ndarray
        Time (s) and command of the whole record.
    named : iterable of str
        Mechanisms the diagnosis names (findings and their alternatives).
    """
    named = set(named)
    if not named & (TIME_GAINS | LEVEL_SHAPES):
        return []
    rho, swing = swing_trend(t_s, v)
    if not abs(rho) >= SWING_RHO:
        return []
    q = max(swing.size // 4, 1)
    kinds = ', '.join(sorted(named & (TIME_GAINS | LEVEL_SHAPES)))
    return [f"the command's swing {'falls' if rho < 0 else 'grows'} steadily over the run "
            f'(median {np.median(swing[:q]):.4g} in its first quarter of reversals, '
            f'{np.median(swing[-q:]):.4g} in its last; rank correlation with time '
            f'{rho:+.2f}): on such a record a gain that changes with time and a curve or loop '
            f'shape over the level act alike, so what is named ({kinds}) may be the other '
            'kind; an excitation that comes back to earlier swings later in the run '
            'separates them']
