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

"""Command reversals, the loop period and monotone stretches: one detector for all.

A *reversal* is where the command turns round by more than a tolerance
(default 2 % of its span) from its last extremum: wiggles below the
tolerance are ignored. Identification counts them (a loop needs a rise and a
fall), search domains take the excitation's half period from them, and the
diagnosis cuts the record into monotone stretches at them.
"""

from __future__ import annotations

from numba import njit
import numpy as np

__all__ = [
    'DEFAULT_TOLERANCE',
    'command_context',
    'count_reversals',
    'half_period_s',
    'period_s',
    'reversal_indices',
    'reversal_times',
]

#: Default reversal tolerance, as a fraction of the command's span.
DEFAULT_TOLERANCE = 0.02


@njit(cache=True)
def _reversals(command, tol):
    """Extremum index and new direction (+1 rising, -1 falling) of every reversal."""
    n = command.shape[0]
    idx = np.empty(n, dtype=np.int64)
    new_dir = np.empty(n, dtype=np.int64)
    k = 0
    direction = 0
    anchor = 0
    for j in range(1, n):
        c = command[j]
        if direction >= 0 and c < command[anchor] - tol:
            if direction > 0:
                idx[k] = anchor
                new_dir[k] = -1
                k += 1
            direction = -1
            anchor = j
        elif direction <= 0 and c > command[anchor] + tol:
            if direction < 0:
                idx[k] = anchor
                new_dir[k] = 1
                k += 1
            direction = 1
            anchor = j
        elif (direction > 0 and c > command[anchor]) or (direction < 0 and c < command[anchor]):
            anchor = j
    return idx[:k], new_dir[:k]


def _tolerance(command: np.ndarray, tolerance: float | None, fraction: float) -> float:
    span = float(np.ptp(command)) if command.size else 0.0
    return fraction * span if tolerance is None else float(tolerance)


def reversal_indices(command: np.ndarray, tolerance: float | None = None, *,
                     fraction: float = DEFAULT_TOLERANCE) -> tuple[np.ndarray, np.ndarray]:
    """Where the command turns round, and which way it goes on.

    Parameters
    ----------
    command : numpy.ndarray
        Command samples.
    tolerance : float, optional
        Smallest excursion from the last extremum that counts as a move, in
        command units; default fraction of the command's span.
    fraction : float
        Default tolerance as a fraction of the span.

    Returns
    -------
    index : numpy.ndarray of int
        Sample of the extremum at each reversal.
    direction : numpy.ndarray of int
        Direction after it: +1 rising, -1 falling.
    """
    v = np.ascontiguousarray(command, dtype=np.float64)
    if v.size < 2 or not np.ptp(v) > 0.0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return _reversals(v, _tolerance(v, tolerance, fraction))


def count_reversals(command: np.ndarray, tolerance: float | None = None) -> int:
    """Number of reversals beyond tolerance (default 2 % of the command's span)."""
    return int(reversal_indices(command, tolerance)[0].size)


def reversal_times(t_s: np.ndarray, command: np.ndarray,
                   tol_fraction: float = DEFAULT_TOLERANCE) -> np.ndarray:
    """Times (s) of the extrema where the command turns round."""
    idx, _ = reversal_indices(command, fraction=tol_fraction)
    return np.asarray(t_s, dtype=np.float64)[idx]


def half_period_s(t_s: np.ndarray, command: np.ndarray) -> float:
    """Mean time between reversals: record length over (reversals + 1), seconds."""
    t = np.asarray(t_s, dtype=np.float64)
    return float(t[-1] - t[0]) / (count_reversals(command) + 1)


def period_s(t_s: np.ndarray, command: np.ndarray) -> float:
    """Typical loop period: twice the median time between reversals, seconds.

    With two reversals or fewer, a quarter of the record's duration.
    """
    rev = reversal_times(t_s, command)
    if rev.size > 2:
        return float(2.0 * np.median(np.diff(rev)))
    t = np.asarray(t_s, dtype=np.float64)
    return float(0.25 * (t[-1] - t[0]))


def command_context(t_s: np.ndarray, command: np.ndarray) -> dict[str, float]:
    """What the diagnosis's blocks need to know of a command: its loop period, span and speed.

    Returns
    -------
    dict
        ``period_s`` (:func:`period_s`), ``command_span`` (max - min, the
        command's units) and ``command_rate_max`` (the largest change between
        two samples over their interval, units per second).
    """
    t = np.asarray(t_s, dtype=np.float64)
    v = np.asarray(command, dtype=np.float64)
    dt = np.diff(t)
    rates = np.abs(np.diff(v)) / np.where(dt > 0.0, dt, np.inf)
    return {'period_s': period_s(t, v), 'command_span': float(np.ptp(v)) if v.size else 0.0,
            'command_rate_max': float(np.max(rates)) if rates.size else 0.0}
