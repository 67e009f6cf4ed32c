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

"""Dahl's friction written apart from the package, for recordings with friction.

Explicit Euler steps a fraction of a sample long (the package's
``friction`` block steps the exact exponential solution instead), used by
``test/diagnosis/test_friction.py`` and the blind family's friction recordings
(``bench/blind_family.py``).
"""

from __future__ import annotations

import numpy as np

__all__ = ['euler_dahl']


def euler_dahl(x: np.ndarray, length: float, substeps: int = 50) -> np.ndarray:
    """Dahl's state ``dz/dx = (1 - z sign(dx)) / length`` along ``x``, from 0.

    Parameters
    ----------
    x : numpy.ndarray
        The path (travel or displacement).
    length : float
        Presliding travel, in the unit of ``x``.
    substeps : int, optional
        Euler steps per sample; a step longer than ``length`` (a jump of the
        path) would overshoot, so the state is kept within ``[-1, 1]``.
    """
    z = np.zeros(x.size)
    zk = 0.0
    for k in range(1, x.size):
        dx = (x[k] - x[k - 1]) / substeps
        for _ in range(substeps):
            zk = min(1.0, max(-1.0, zk + dx / length * (1.0 - zk * np.sign(dx))))
        z[k] = zk
    return z
