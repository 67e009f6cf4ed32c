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

"""The train / held-out split of a record, by duration."""

from __future__ import annotations

import math

import numpy as np

from hyst_id.errors import ConfigError

__all__ = ['inside_rows', 'level_excursion', 'split_index']


def split_index(t_s: np.ndarray, train_fraction: float) -> int:
    """Index of the first held-out sample when the first train_fraction of the duration trains.

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times (s), increasing.
    train_fraction : float
        Share of the *duration* (not of the samples) used for training, in (0, 1).

    Raises
    ------
    ConfigError
        train_fraction outside (0, 1).
    """
    if not 0.0 < train_fraction < 1.0:
        raise ConfigError(f'train fraction must be in (0, 1), got {train_fraction}')
    t = np.asarray(t_s, dtype=np.float64)
    t_cut = t[0] + train_fraction * (t[-1] - t[0])
    return int(np.searchsorted(t, t_cut))


def inside_rows(command: np.ndarray, n_train: int, *, tol: float = 0.02,
                min_share: float = 0.1, min_samples: int = 30) -> np.ndarray:
    """Held-out rows whose prediction is not an extrapolation: before the command leaves.

    A hysteresis remembers its turning points, so once the held-out command
    has gone beyond the training range (by more than ``tol`` of it) every
    later sample depends on a turning point the model never saw fitted. The
    rows kept are the held-out ones before that first excursion; when they
    are fewer than ``min_share`` of the held-out part or ``min_samples``,
    the whole held-out part is returned (nothing better to judge on).

    Parameters
    ----------
    command : numpy.ndarray
        The whole record's command.
    n_train : int
        Training samples (the held-out part follows).
    tol, min_share, min_samples : float, float, int
        See above.

    Returns
    -------
    numpy.ndarray
        Absolute row indices (int) into the record, a prefix of the held-out part.
    """
    v = np.asarray(command, dtype=float)
    n = v.size
    if n_train >= n:
        return np.arange(n_train, n)
    lo, hi = float(np.min(v[:n_train])), float(np.max(v[:n_train]))
    margin = tol * (hi - lo)
    out = np.flatnonzero((v[n_train:] < lo - margin) | (v[n_train:] > hi + margin))
    stop = n if out.size == 0 else n_train + int(out[0])
    if stop - n_train < max(min_samples, min_share * (n - n_train)):
        stop = n
    return np.arange(n_train, stop)


def level_excursion(measurement: np.ndarray, n_train: int, *,
                    tol: float = 0.02) -> tuple[float, float, float, float, float]:
    """Share of held-out samples whose measurement lies beyond the training part's range.

    Beyond by more than ``tol`` of that range. The command may stay inside
    its training range while the response does not (an end stop or plateau
    reached only later, a drift): no block fitted on the training part was
    shown those levels.

    Returns
    -------
    tuple of float
        ``(share, train_low, train_high, held_out_low, held_out_high)``; share 0
        without held-out samples.
    """
    y = np.asarray(measurement, dtype=float)
    if n_train >= y.size or n_train < 1:
        return 0.0, math.nan, math.nan, math.nan, math.nan
    lo, hi = float(np.min(y[:n_train])), float(np.max(y[:n_train]))
    held = y[n_train:]
    margin = tol * (hi - lo)
    share = float(np.mean((held < lo - margin) | (held > hi + margin)))
    return share, lo, hi, float(np.min(held)), float(np.max(held))
