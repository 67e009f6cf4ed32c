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

"""Chains built from the data themselves, to start local fits from.

The loop's width where the output crosses its median (``loop.loop_width``)
is split between H and the backlash B in several ways (:data:`SPLITS`); the
hysteresis family builds loops of the H share (``HysteresisFamily.starts``),
B gets the rest. These starts avoid the trap every global search can fall
into on low-noise or play-like loops: a backlash dead band standing in for
H's flat inner lines ("linear H + backlash").
"""

from __future__ import annotations

import numpy as np

from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.loop import loop_width
from hyst_id.models.family import LoopBox

__all__ = ['MORE_SPLITS', 'SPLITS', 'box_of', 'data_starts', 'sensor_guesses']

#: (loop width / measured width, share of it given to B) of the data-built starts.
SPLITS = ((1.0, 0.1), (1.0, 0.5), (0.7, 0.1), (1.4, 0.1))

#: The rest of the grid of widths 0.7, 1.0, 1.4 x the measured one with 10, 30 and 50 % of
#: it in B, tried by identify's incumbent when the starts of :data:`SPLITS` stop above
#: the floor (:func:`hyst_id.identification.incumbent.data_incumbent`). The true chain's basin
#: can be narrow when H and B share the width about evenly: on clean recordings of the
#: independent reference (bench/blind_family.py #59, #63, #122, #32) the best incumbent
#: came from one of these (``python bench/start_splits.py``).
MORE_SPLITS = ((0.7, 0.3), (0.7, 0.5), (1.0, 0.3), (1.4, 0.3), (1.4, 0.5))


def box_of(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray) -> LoopBox:
    """The spec's loop box (data-derived domains keep one), else one for a preset's scale.

    A preset (the paper's domains) has no virtual output scale: H's output
    then lives where the command does (unit mean slope through the origin,
    as on the paper's rig, position in mA-equivalent).
    """
    box = spec.extra.get('loop_box') if spec.extra else None
    w = loop_width(t_s, v, y)
    if isinstance(box, LoopBox):
        return LoopBox(**{**box.__dict__, 'loop_width': w})
    lo, hi = float(np.min(v)), float(np.max(v))
    span = hi - lo or 1.0
    return LoopBox(v_lo=lo - 0.25 * span, v_hi=hi + 0.25 * span, v_min=lo, v_max=hi,
                   u_lo=lo - 0.25 * span, u_hi=hi + 0.25 * span, slope=1.0, steep=10.0,
                   slope_min=0.5, flat_max=2.0, loop_width=w)


def sensor_guesses(spec: ChainSpec, half_period_s: float) -> list[np.ndarray]:
    """Sensor parameters to combine with the data-built chains (inside the domains).

    Pressure: a time constant of 0.05, 0.2, 0.6 and 2 half periods; flow:
    damping 0.5 with a natural period of 0.1, 0.4 and 1.5 half periods (a
    sensor slower than a fast excitation is common). Position: none.
    """
    b = spec.bounds[spec.sensor_slice]
    if spec.channel == 'pressure':
        out = [np.array([f * half_period_s]) for f in (0.05, 0.2, 0.6, 2.0)]
    elif spec.channel == 'flow':
        out = [np.array([0.5, 2.0 * np.pi / (f * half_period_s)]) for f in (0.1, 0.4, 1.5)]
    else:
        return [np.zeros(0)]
    return [np.clip(x, b[:, 0], b[:, 1]) for x in out]


def data_starts(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
                sensors: list[np.ndarray] | None = None, splits: tuple = SPLITS,
                per_split: int | None = None) -> list[np.ndarray]:
    """Chain vectors built from the data, inside the spec's domains and feasible.

    Parameters
    ----------
    spec : ChainSpec
        The chain (its family builds H, its domains filter).
    t_s, v, y : numpy.ndarray
        The recording (or its training part) in the spec's command units.
    sensors : list of numpy.ndarray, optional
        Sensor parameters to combine with every chain (default
        :func:`sensor_guesses`).
    splits : tuple of (float, float)
        Pairs of (width factor, share of the width given to B).
    per_split : int, optional
        Keep at most this many of the family's loops per split.

    Returns
    -------
    list of numpy.ndarray
        Full chain vectors (H, m_bl = 1, a centred B, sensor).
    """
    box = box_of(spec, t_s, v, y)
    if sensors is None:
        from hyst_id.signals.reversals import half_period_s
        sensors = sensor_guesses(spec, half_period_s(t_s, v))
    out = []
    for factor, share in splits:
        width = factor * box.loop_width
        loops = spec.family.starts(box, width * (1.0 - share))
        if per_split is not None:
            loops = loops[:per_split]
        half_b = 0.5 * width * share * box.slope
        for h in loops:
            for sensor in sensors:
                x = np.concatenate([h, [1.0, -half_b, half_b], sensor])
                inside = np.all((x >= spec.bounds[:, 0]) & (x <= spec.bounds[:, 1]))
                if inside and spec.feasible(x[None, :])[0]:
                    out.append(x)
    return out
