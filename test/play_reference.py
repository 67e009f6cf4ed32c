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

"""A play (backlash) operator written apart from the package, and records that start inside it.

Used by ``test/identification/test_start_state.py`` and ``bench/start_state.py``:
``y = 2 play(u, 0.8) + 1`` plus white noise of 0.01, the command resting at 0
for ``rest_s`` seconds (the output in the middle of the play, or on its rising
edge), then a sine of varying amplitude at 100 Hz.
"""

from __future__ import annotations

import numpy as np

from hyst_id.io.recording import Recording

__all__ = ['mild_start', 'play', 'rest_then_sine']


def play(u: np.ndarray, half_width: float, y0: float) -> np.ndarray:
    """A play operator of half width ``half_width`` whose output starts at ``y0``."""
    out, y = np.empty_like(u), y0
    for i, x in enumerate(u):
        y = min(max(y, x - half_width), x + half_width)
        out[i] = y
    return out


def rest_then_sine(seed: int, rest_s: float, inside: bool, sine_s: float) -> Recording:
    """The record (see the module): mid-play (``inside``) or edge start, noise ``seed``."""
    t = np.arange(0.0, rest_s + sine_s, 0.01)
    s = t - rest_s
    u = np.where(s < 0, 0.0, 5 * np.sin(2 * np.pi * 0.2 * s) * (0.6 + 0.4 * np.sin(
        2 * np.pi * 0.013 * s)))
    y = 2.0 * play(u, 0.8, 0.0 if inside else -0.8) + 1.0
    return Recording(t, u, y + np.random.default_rng(seed).normal(0, 0.01, t.size), 'position')


def mild_start(seed: int) -> Recording:
    """A new-user trial's case: a sine from 0 in the middle of a play, behind a 0.15 s lag.

    ``y = lag(0.13 play(u, 20) + 5)`` on the pressure chain, ``u`` the decaying 10 s sine
    of Eq. 24 scaled to ±150, 100 s at 20 Hz, noise 0.5 % of the span; the lag is the
    reference simulator's first-order sensor (written apart from the package too).
    """
    from reference_sim import first_order_sensor
    t = np.arange(0.0, 100.0, 0.05)
    u = 150.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    y = first_order_sensor(t, 0.13 * play(u, 20.0, 0.0) + 5.0, 0.15)
    y = y + np.random.default_rng(seed).normal(0.0, 0.005 * np.ptp(y), t.size)
    return Recording(t, u, y, 'pressure')
