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

"""The baseline fit: the paper's chain of a channel on the training part.

GAASS with a few seeds (refined by least squares, :func:`hyst_id.identification.identify`)
finds a basin; a handful of starts built from the data themselves
(:func:`structured_starts`: the loop width measured where the output
crosses its median, split between H and the backlash) are polished too,
because on some records every GAASS seed ends in the same wrong basin (a
backlash dead band standing in for the hysteron's flat inner lines). The
best of them all is the baseline; the data-built starts also seed the
mechanism fits, so that a chain distorted by a missing mechanism does not
trap them.
"""

from __future__ import annotations

import numpy as np

from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import ChainSpec
from hyst_id.io.recording import Recording
from hyst_id.signals.reversals import reversal_times

__all__ = ['baseline_starts', 'loop_width', 'structured_starts']


def loop_width(t_s: np.ndarray, v: np.ndarray, y: np.ndarray) -> float:
    """Loop width in command units where the output crosses its median level.

    Each monotone stretch of the command that carries the measurement
    across its median gives one crossing command; the width is the median
    crossing while rising minus the median crossing while falling (the
    rising branch lies to the right for either sign of the gain).
    """
    span = float(np.ptp(v)) or 1.0
    idx = np.searchsorted(t_s, reversal_times(t_s, v))
    bounds = np.unique(np.concatenate([[0], idx, [v.size - 1]]))
    level = float(np.median(y))
    rising, falling = [], []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < 2:
            continue
        seg_y = y[a:b + 1] - level
        cross = np.nonzero(np.sign(seg_y[:-1]) * np.sign(seg_y[1:]) < 0)[0]
        if cross.size == 0:
            continue
        k = a + int(cross[0])
        f = (level - y[k]) / (y[k + 1] - y[k]) if y[k + 1] != y[k] else 0.5
        vc = v[k] + f * (v[k + 1] - v[k])
        (rising if v[b] > v[a] else falling).append(vc)
    if not rising or not falling:
        return 0.2 * span
    return float(np.clip(np.median(rising) - np.median(falling), 0.02 * span, 0.8 * span))


#: (loop width / measured width, share of it given to B) of the data-built starts.
SPLITS = ((1.0, 0.1), (1.0, 0.5), (0.7, 0.1), (1.4, 0.1))


def structured_starts(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
                      sensor: np.ndarray, splits: tuple = SPLITS) -> list[np.ndarray]:
    """Chain starts built from the data: the loop width split between H and B.

    Unit side slopes, flat inner lines (slope 0.1), top and bottom lines
    outside the commanded range, the width estimated by :func:`loop_width`
    given mostly to H, half and half, or mostly to B (``splits``: pairs of
    width factor and share of B). Starts outside the search domains or
    infeasible are dropped.
    """
    lo, hi = float(np.min(v)), float(np.max(v))
    span = hi - lo or 1.0
    w = loop_width(t_s, v, y)
    mid = 0.5 * (lo + hi)
    shift = mid - 9.0 if not (spec.bounds[6, 0] <= mid <= spec.bounds[6, 1]) else 0.0
    out = []
    for factor, share in splits:
        width = factor * w
        wh, wb = width * (1.0 - share), width * share
        m_t = 0.1
        c_l, c_r = shift - 0.5 * wh, shift + 0.5 * wh
        v1, v2 = hi - 0.1 * span, lo + 0.1 * span
        c_t = (v1 - c_r) - m_t * v1
        c_b = (v2 - c_l) - m_t * v2
        x = np.array([1.0, 1.0, m_t, m_t, c_l, c_r, c_t, c_b, 1.0, -0.5 * wb, 0.5 * wb,
                      *sensor])
        inside = np.all((x >= spec.bounds[:, 0]) & (x <= spec.bounds[:, 1]))
        if inside and spec.feasible(x[None, :])[0]:
            out.append(x)
    return out


def baseline_starts(rec_train: Recording, spec: ChainSpec, settings
                    ) -> tuple[np.ndarray, list[np.ndarray]]:
    """GAASS result (few seeds, refined) and the data-built starts."""
    ident_settings = IdentifySettings(pop_size=settings.pop_size, maxiter=settings.generations,
                                      seeds=tuple(settings.seeds), workers=settings.workers,
                                      refine=True, refine_top=2, restarts=1,
                                      refine_max_nfev=1500)
    ident = identify(rec_train, spec=spec, settings=ident_settings)
    x_ga = np.array(min(ident.runs, key=lambda r: r.fun).x_raw, dtype=float)
    return x_ga, structured_starts(spec, rec_train.t_s, rec_train.command,
                                   rec_train.measurement, x_ga[11:])
