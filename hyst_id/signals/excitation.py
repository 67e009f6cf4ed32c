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

"""Command profiles (mA) as plain functions of time: the paper's and a few more.

Every profile takes the sample times ``t_s`` (seconds, any array shape, or a
scalar) and returns the command in mA with the same shape, so a node can
evaluate it one sample at a time and a batch run on a whole grid, with
identical values. :func:`make_excitation` picks one by name.

=============  ================================================================
``eq24``       ``9 + 2 e^{-0.01 t} sin(2 pi t/10)``: the paper's identification run
``eq25``       ``9 + sin(2 pi t/12)``: the paper's compensation run
``multisine``  sum of sines, Schroeder phases, peak-normalised
``chirp``      linear frequency sweep, repeated every ``sweep_s``
``steps``      staircase through a list of levels, ``hold_s`` each, repeated
=============  ================================================================
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any, Callable, Sequence

import numpy as np

from hyst_id.errors import ConfigError

__all__ = ['EXCITATIONS', 'eq24', 'eq25', 'multisine', 'chirp', 'steps', 'make_excitation']

DEFAULT_MULTISINE_HZ = (0.01, 0.023, 0.047, 0.083, 0.13)
DEFAULT_STEP_LEVELS_MA = (9.0, 10.5, 8.0, 11.0, 7.5, 9.5, 7.0, 10.0, 8.5)


def _t(t_s: Any) -> np.ndarray:
    return np.asarray(t_s, dtype=np.float64)


def eq24(t_s: Any, *, offset_ma: float = 9.0, amplitude_ma: float = 2.0,
         decay_per_s: float = 0.01, period_s: float = 10.0) -> np.ndarray:
    """Paper Eq. 24: decaying sine, ``offset + A e^{-d t} sin(2 pi t/T)`` mA."""
    t = _t(t_s)
    return offset_ma + amplitude_ma * np.exp(-decay_per_s * t) * np.sin(2 * np.pi * t / period_s)


def eq25(t_s: Any, *, offset_ma: float = 9.0, amplitude_ma: float = 1.0,
         period_s: float = 12.0) -> np.ndarray:
    """Paper Eq. 25: ``offset + A sin(2 pi t/T)`` mA (the compensation test input)."""
    t = _t(t_s)
    return offset_ma + amplitude_ma * np.sin(2 * np.pi * t / period_s)


def _schroeder(frequencies_hz: Sequence[float]) -> tuple[np.ndarray, np.ndarray, float]:
    f = np.asarray(frequencies_hz, dtype=float).ravel()
    return _schroeder_cached(tuple(f.tolist()))


@lru_cache(maxsize=32)
def _schroeder_cached(frequencies_hz: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray, float]:
    f = np.array(frequencies_hz)
    if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ConfigError(f'multisine frequencies must be positive, got {list(f)}')
    k = np.arange(1, f.size + 1)
    phase = -np.pi * k * (k - 1) / f.size
    # Peak over a long dense grid, independent of the caller's samples.
    grid = np.linspace(0.0, 2.0 / f.min(), 20001)
    peak = float(np.max(np.abs(np.sin(2 * np.pi * np.outer(grid, f) + phase).sum(axis=1))))
    return f, phase, peak


def multisine(t_s: Any, *, offset_ma: float = 9.0, amplitude_ma: float = 1.5,
              frequencies_hz: Sequence[float] = DEFAULT_MULTISINE_HZ) -> np.ndarray:
    """Equal-amplitude sines with Schroeder phases, scaled to peak ``amplitude_ma``.

    The peak is measured over two periods of the lowest frequency, so the
    scaling does not depend on ``t_s``.
    """
    f, phase, peak = _schroeder(frequencies_hz)
    t = _t(t_s)
    s = np.sin(2 * np.pi * t[..., None] * f + phase).sum(axis=-1)
    return offset_ma + amplitude_ma * s / peak


def chirp(t_s: Any, *, offset_ma: float = 9.0, amplitude_ma: float = 1.5,
          f0_hz: float = 0.02, f1_hz: float = 0.25, sweep_s: float = 100.0) -> np.ndarray:
    """Linear sweep from ``f0_hz`` to ``f1_hz`` over ``sweep_s``, then again."""
    if not (f0_hz > 0 and f1_hz > 0 and sweep_s > 0):
        raise ConfigError('chirp needs f0_hz, f1_hz and sweep_s > 0')
    tau = np.mod(_t(t_s), sweep_s)
    phase = 2 * np.pi * (f0_hz * tau + 0.5 * (f1_hz - f0_hz) * tau ** 2 / sweep_s)
    return offset_ma + amplitude_ma * np.sin(phase)


def steps(t_s: Any, *, levels_ma: Sequence[float] = DEFAULT_STEP_LEVELS_MA,
          hold_s: float = 5.0) -> np.ndarray:
    """Staircase: each level held ``hold_s`` seconds, the list repeated."""
    levels = np.asarray(levels_ma, dtype=float).ravel()
    if levels.size == 0 or not np.all(np.isfinite(levels)):
        raise ConfigError('steps needs at least one finite level')
    if not hold_s > 0:
        raise ConfigError(f'steps needs hold_s > 0, got {hold_s}')
    k = np.floor(_t(t_s) / hold_s).astype(np.int64) % levels.size
    return levels[k]


#: Profiles by name.
EXCITATIONS: dict[str, Callable[..., np.ndarray]] = {
    'eq24': eq24, 'eq25': eq25, 'multisine': multisine, 'chirp': chirp, 'steps': steps,
}


def make_excitation(name: str, t_s: Any, **kw: Any) -> np.ndarray:
    """Evaluate the profile ``name`` at ``t_s`` with keyword parameters ``kw``.

    Raises
    ------
    ConfigError
        Unknown profile or parameter.
    """
    try:
        fun = EXCITATIONS[name]
    except KeyError:
        raise ConfigError(f'unknown excitation {name!r}; expected one of '
                          f'{tuple(EXCITATIONS)}') from None
    try:
        return fun(t_s, **kw)
    except TypeError as exc:
        raise ConfigError(f'excitation {name}: {exc}') from None
