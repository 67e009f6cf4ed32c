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


"""The width of an identified loop, in command units: a maintenance metric that holds.

The paper's chain can share one loop's width between H (``c_r - c_l``) and
the backlash (``c_br - c_bl``, in the chain's signal units) in many ways that
fit a record equally well, so neither parameter difference tracks a play
that widens over a fleet's recordings. The loop the whole chain makes does:
:func:`loop_width_command` drives the identified chain with a slow triangle
over the record's command range and measures, at each output level of the
middle half of the loop's span, how far the falling branch lies from the
rising one along the command axis; the median of those distances is the
loop's width in the command's own units (mA, V, %).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ['loop_width_command']

#: Samples per branch of the sweep.
_N = 2000
#: Seconds between sweep samples: every sensor settles within one (a quasi-static loop).
_SLOW_DT_S = 1e6


def loop_width_command(ident: Any, command_range: tuple[float, float]) -> float | None:
    """Median horizontal width of ``ident``'s quasi-static loop over ``command_range``.

    Parameters
    ----------
    ident : Identification
        An identification (its chain and parameters: :meth:`spec`, ``x``).
    command_range : tuple of float
        The recording's lowest and highest command.

    Returns
    -------
    float or None
        The width in command units; None when the loop has no sloped middle
        to measure (a chain that does not move over the range).
    """
    lo, hi = map(float, command_range)
    if not hi > lo:
        return None
    up = np.linspace(lo, hi, _N)
    v = np.concatenate([up, up[::-1], up, up[::-1]])    # the first cycle settles the state
    y = ident.spec().simulate(ident.x, np.arange(v.size) * _SLOW_DT_S, v)
    rising, falling = y[2 * _N:3 * _N], y[3 * _N:][::-1]     # both over ``up``
    if rising[-1] < rising[0]:
        rising, falling = -rising, -falling
    rising, falling = np.maximum.accumulate(rising), np.maximum.accumulate(falling)
    bottom, top = max(rising[0], falling[0]), min(rising[-1], falling[-1])
    if not top > bottom:
        return None
    levels = np.linspace(bottom + 0.25 * (top - bottom), top - 0.25 * (top - bottom), 51)
    # where each branch first reaches a level: the command on it
    v_rise = np.interp(levels, rising, up)
    v_fall = np.interp(levels, falling, up)
    return float(np.median(np.abs(v_rise - v_fall)))
