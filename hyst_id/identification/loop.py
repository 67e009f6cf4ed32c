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

"""What a recording's loop looks like before any model is fitted.

Orientation (counter-clockwise like the model, or mirrored), the sign a
profiled calibration will take, whether the response moves against the
command right after reversals (a friction loop), the steepest slope the data
show, and the loop's width at the measurement's median. Search domains
(:mod:`.domains`), data-built starts (:mod:`.starts`) and identification
warnings (:mod:`.quality`) read them.
"""

from __future__ import annotations

import numpy as np

from hyst_id.io.recording import Recording
from hyst_id.signals.noise import estimate_noise_std
from hyst_id.signals.reversals import reversal_indices, reversal_times

__all__ = ['THIN_LOOP', 'loop_orientation', 'loop_width', 'measurement_sign',
           'reversal_response', 'steepest_slope']

#: Orientation index below which a loop counts as too thin to tell its direction.
THIN_LOOP = 0.005


def loop_orientation(command: np.ndarray, measurement: np.ndarray) -> float:
    """Signed area of the measured loop, normalised to [-1/2, 1/2].

    ``sum((y - mean y) dv) / (sum |dv| * span y)``: ``-1/2`` for a
    rectangular counter-clockwise loop (rising on the bottom, falling on the
    top, like the hysteresis model), ``+1/2`` for a clockwise one, near 0
    for a line. Additive noise does not bias it.

    Parameters
    ----------
    command, measurement : numpy.ndarray
        The recording's command and measurement.

    Returns
    -------
    float
        Orientation index (negative: counter-clockwise).
    """
    v = np.asarray(command, dtype=np.float64)
    y = np.asarray(measurement, dtype=np.float64)
    dv = np.diff(v)
    y_mid = 0.5 * (y[1:] + y[:-1])
    travel = float(np.sum(np.abs(dv)))
    span = float(np.ptp(y))
    if travel <= 0.0 or span <= 0.0:
        return 0.0
    return float(np.sum((y_mid - y_mid.mean()) * dv) / (travel * span))


def measurement_sign(rec: Recording) -> int:
    """+1 if the recording's loop runs like the model's, -1 if it is mirrored.

    The model's loop is counter-clockwise and rises with the command. A
    clearly oriented loop (``|orientation| > 0.005``) decides by its
    direction; a thin one by the sign of the command/measurement covariance.
    A loop that runs clockwise while rising (a friction force against
    displacement) is not representable in either sign; its direction
    decides, because the mirrored loop is at least traversed the model's way.

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    int
        ``+1`` or ``-1``: the ``output_sign`` an identification should find
        (it finds it from the profiled gain; this is the data's own view).
    """
    orientation = loop_orientation(rec.command, rec.measurement)
    if abs(orientation) > THIN_LOOP:
        return -1 if orientation > 0 else 1
    v = np.asarray(rec.command, dtype=np.float64)
    y = np.asarray(rec.measurement, dtype=np.float64)
    cov = float(np.mean((v - v.mean()) * (y - y.mean())))
    return -1 if cov < 0 else 1


def reversal_response(command: np.ndarray, measurement: np.ndarray,
                      travel: float = 0.05) -> float:
    """Fraction of command reversals after which the measurement moves against the command.

    After each reversal (beyond 2 % of the command span), the measurement's
    change over the next ``travel`` command spans is compared with the new
    command direction; it counts as *against* when it goes the other way by
    more than 20 % of the measurement span. The model's branches are
    monotone, so its output never does this (a slow sensor only briefly).

    Returns
    -------
    float
        Fraction in [0, 1] (0 when the command never reverses).
    """
    v = np.asarray(command, dtype=float)
    y = np.asarray(measurement, dtype=float)
    span_v, span_y = float(np.ptp(v)), float(np.ptp(y))
    idx, dirs = reversal_indices(v, 0.02 * span_v)
    revs = list(zip(idx.tolist(), dirs.tolist()))
    against = 0
    counted = 0
    for j, direction in revs:
        moved = np.flatnonzero(direction * (v[j:] - v[j]) >= travel * span_v)
        if not moved.size:
            continue
        counted += 1
        k = j + int(moved[0])
        against += direction * (y[k] - y[j]) < -0.2 * span_y
    return against / counted if counted else 0.0


def steepest_slope(rec: Recording, window: float = 0.02) -> float:
    """Steepest slope the data shows, in mean loop slopes (output span over command span).

    Over every stretch in which the command travels ``window`` command spans
    without reversing, the measurement's change, less four noise standard
    deviations (of a difference), over the command's change; the largest.
    A lower bound: noise cannot inflate it much, a transition sharper than
    the window shows as the window's slope.

    Parameters
    ----------
    rec : Recording
        The recording.
    window : float
        Command travel per stretch, in command spans.

    Returns
    -------
    float
        Steepest slope, >= 0.
    """
    v = np.asarray(rec.command, dtype=np.float64)
    y = np.asarray(rec.measurement, dtype=np.float64)
    span_v = float(np.ptp(v))
    y_lo, y_hi = np.percentile(y, [0.5, 99.5])
    if not span_v > 0.0 or not y_hi > y_lo:
        return 0.0
    step = window * span_v
    travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(v)))])
    k = np.searchsorted(travel, travel + step)
    ok = k < v.shape[0]
    j, k = np.flatnonzero(ok), k[ok]
    dv = np.abs(v[k] - v[j])
    straight = dv >= 0.9 * step                 # no reversal inside the stretch
    if not straight.any():
        return 0.0
    sigma = estimate_noise_std(y)
    dy = np.abs(y[k] - y[j])[straight] - 4.0 * np.sqrt(2.0) * sigma
    slopes = dy / dv[straight]
    return max(0.0, float(np.max(slopes)) / ((y_hi - y_lo) / span_v))


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
