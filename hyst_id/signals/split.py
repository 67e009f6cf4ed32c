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

import numpy as np

from hyst_id.errors import ConfigError

__all__ = ['split_index']


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
