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

"""Bouc-Wen loops written apart from the package, in the structural and the piezo form.

A Bouc-Wen state ``dz/dx = 1 - (beta sign(z dx) + gamma) |z|`` (n = 1, A = 1,
explicit Euler steps a twentieth of a sample long) on a sine whose swing comes and
goes (2,000 samples at 20 Hz, period 8-12 s, noise 0.4 % of the span). Used by
``test/diagnosis/test_friction.py`` and ``bench/bouc_wen_forms.py``.
"""

from __future__ import annotations

import numpy as np

from hyst_id.io.recording import Recording

__all__ = ['bouc_wen_recording', 'bouc_wen_state']


def bouc_wen_state(x: np.ndarray, beta: float, gamma: float, substeps: int = 20) -> np.ndarray:
    """``z`` along ``x`` from 0 (n = 1, A = 1), explicit Euler."""
    z, zs = np.zeros_like(x), 0.0
    for i in range(1, x.size):
        dx = (x[i] - x[i - 1]) / substeps
        for _ in range(substeps):
            zs += (1.0 - (beta * np.sign(dx * zs) + gamma) * abs(zs)) * dx
        z[i] = zs
    return z


def bouc_wen_recording(seed: int, form: str) -> Recording:
    """One recording, ``form`` ``'force'`` or ``'piezo'``.

    ``force``: a restoring force against its displacement, ``F = 0.3 x + 0.7 z``
    (beta = gamma = 0.5): the loop runs clockwise (higher while the displacement
    rises), a sliding element in parallel with a spring; ``z`` saturates at 1, so
    the band is ±0.7. ``piezo``: an actuator's travel against its voltage,
    ``x = V - 0.4 z`` (beta 0.8, gamma 0.2): counter-clockwise, curved branches.
    """
    rng = np.random.default_rng([seed, 23])
    t = np.arange(2000) * 0.05
    x = (2.0 * np.sin(2 * np.pi * t / rng.uniform(8, 12))
         * (0.7 + 0.3 * np.sin(2 * np.pi * t / 37 + rng.uniform(0, 6))))
    if form == 'force':
        y = 0.3 * x + 0.7 * bouc_wen_state(x, 0.5, 0.5)
    elif form == 'piezo':
        y = x - 0.4 * bouc_wen_state(x, 0.8, 0.2)
    else:
        raise ValueError(f'form must be force or piezo, got {form!r}')
    return Recording(t, x, y + rng.normal(0, 0.004 * np.ptp(y), y.size), 'position', 'mm',
                     'N' if form == 'force' else 'um', f'Bouc-Wen {form} #{seed}')
