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

"""Test excitations and recordings shared by several test modules (plain numpy)."""

from __future__ import annotations

import numpy as np

__all__ = ['moves_and_holds', 'off_chain_recording']


def moves_and_holds(rng: np.random.Generator, t_s: np.ndarray, dwell_s: float, move_s: float,
                    n_levels: int, lo: float = 6.0, hi: float = 12.5,
                    start: float = 9.0) -> np.ndarray:
    """Ramps of ``move_s`` between random levels in ``[lo, hi]``, each held to ``dwell_s``.

    A hold test: after every move the command stands still, so anything slow
    (creep) or ringing (second-order dynamics) shows on its own.
    """
    levels = rng.uniform(lo, hi, n_levels)
    seg = np.minimum((t_s // dwell_s).astype(int), levels.size - 1)
    prev = np.concatenate([[start], levels[:-1]])[seg]
    frac = np.clip((t_s % dwell_s) / move_s, 0.0, 1.0)
    return prev + (levels[seg] - prev) * frac


def off_chain_recording(channel: str, seed: int):
    """A sine run whose response has a slow drift no chain makes (fits stay above the floor).

    600 samples at 20 Hz, a 6 s sine about 9 mA, ``tanh`` of the command
    plus a 30 s drift of half its size, and 0.002 of white noise: what makes
    the global phase run every global run it is given.
    """
    from hyst_id.io.recording import Recording
    t = np.arange(600) * 0.05
    v = 9.0 + 3.0 * np.sin(2 * np.pi * t / 6.0)
    y = np.tanh(v - 9.0) + 0.5 * np.sin(2 * np.pi * t / 30.0)
    y = y + np.random.default_rng(seed).normal(0.0, 0.002, t.size)
    return Recording(t, v, y, channel, 'mA', 'mm', 'drift the chain lacks')
