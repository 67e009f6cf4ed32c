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

"""Recordings that start in a state the chain cannot start in.

The chain starts on the rising or the falling edge of its loop
(:data:`hyst_id.identification.chains.INITIAL_STATES`). An actuator resting
inside its play (backlash) or inside its loop, the usual state of a machine
that was last moved some time ago, is on neither: until the command has
swept far enough one way, the measurement stays where the chain cannot be,
and a fit of the whole record bends every parameter to meet that stretch.
By the command's first reversal the actuator is on an edge again.

When a fit stays above the noise floor, identification tries the record
from the first reversal on (:func:`refit_start`: a short probe first), keeps
that fit when it is clearly closer to its floor, and says what it left out
(:func:`left_out_note`). A long rest inside the play spreads the misfit over
the whole record (the fit bends to the rest's level), so the residual alone
does not show where it comes from; the probe does.
"""

from __future__ import annotations

import numpy as np

from hyst_id.identification.quality import FIT_FACTOR, floor_says_nothing
from hyst_id.signals.reversals import reversal_indices

__all__ = ['MIN_BEFORE', 'MIN_KEEP', 'NEAR_FACTOR', 'RETRY_FACTOR', 'keep_refit',
           'left_out_note', 'refit_start']

#: A fit further than this from its noise floor is tried again from the first reversal.
RETRY_FACTOR = 1.1
#: A probe from the first reversal within this of its floor, and this much closer to it
#: than the whole record's fit, is kept (a mild start inside the play: 1.24 x -> 1.0 x).
NEAR_FACTOR = 1.1

#: Share of the samples that must lie after the first reversal for a refit from there.
MIN_KEEP = 0.5
#: Fewest samples before the first reversal worth leaving out.
MIN_BEFORE = 5


def refit_start(command: np.ndarray, er_percent: float, floor_percent: float,
                factor: float = RETRY_FACTOR) -> int | None:
    """The first reversal's sample, when a fit from there is worth trying.

    Parameters
    ----------
    command : numpy.ndarray
        Command samples of the fitted record.
    er_percent, floor_percent : float
        The fit's %e_r and the record's noise floor.
    factor : float
        A fit within this multiple of the floor is not tried again
        (:data:`RETRY_FACTOR`; a diagnosis's start cut passes
        :data:`~hyst_id.identification.quality.FIT_FACTOR`).

    Returns
    -------
    int or None
        None when the fit is within ``factor`` of the floor or the
        floor says nothing (:func:`~hyst_id.identification.quality.floor_says_nothing`), the
        command reverses fewer than three times, fewer than
        :data:`MIN_BEFORE` samples lie before the first reversal, or less
        than :data:`MIN_KEEP` of them after it.
    """
    if (not factor * floor_percent < er_percent
            or floor_says_nothing(er_percent, floor_percent)):
        return None     # at the floor, or a noise-free record (no ratio to judge by)
    index, _ = reversal_indices(np.asarray(command, dtype=float))
    if index.size < 3:
        return None
    k, n = int(index[0]), int(np.asarray(command).size)
    if k < MIN_BEFORE or n - k < MIN_KEEP * n:
        return None
    return k


def keep_refit(before: float, probe: float) -> bool:
    """Whether a probe from the first reversal beats the whole record's fit clearly.

    ``before`` and ``probe``: each fit's %e_r over its noise floor. Kept when
    the probe is :data:`~hyst_id.identification.quality.FIT_FACTOR` (1.5) times
    closer to its floor, or within :data:`NEAR_FACTOR` of it and that much
    closer: a start inside the play that costs the whole fit only a quarter
    above its floor still bends every parameter (a sensor lag 30 % long).
    """
    return probe * FIT_FACTOR < before or (probe <= NEAR_FACTOR
                                           and probe * NEAR_FACTOR < before)


def left_out_note(t_s: np.ndarray, index: int, before: float, after: float) -> str:
    """Words for a record fitted from its first reversal on.

    ``before`` and ``after``: the fit's %e_r over the noise floor with the
    start in and without it.
    """
    return (f"the first {t_s[index] - t_s[0]:.4g} s ({index} samples, up to the command's "
            f'first reversal) are left out of the fit: with them the fit was {before:.2f} x '
            f'the noise floor, without them {after:.2f} x. The actuator started inside its '
            'play or loop, a state the chain cannot start in (it starts on an edge of its '
            'loop); by the first reversal it is on an edge again')
