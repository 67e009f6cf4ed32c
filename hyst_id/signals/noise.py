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

"""Measurement-noise estimate and the %e_r it alone would give (the noise floor).

The noise standard deviation is estimated from the data itself, without a
model: for difference orders ``d = 1, 2, 3`` the d-th differences of white
noise have variance ``C(2d, d) sigma^2``; a smooth signal adds little to
them, hysteresis kinks and backlash jumps add a few outliers. Each order's
scale is a *trimmed* root mean square (the largest 5 % of deviations from
the median dropped, corrected for the trimming of a Gaussian), which
ignores the outliers but, unlike a median of absolute deviations, is not
fooled by A/D quantisation (differences of quantised noise take only a few
discrete values). The signal can only inflate each order's estimate, so the
smallest of the three is taken. Heavily quantised sensors (many repeated
values) get at least the quantisation noise ``q / sqrt(12)``.

A second estimate, :func:`robust_noise_std`, takes medians instead (up to
half the differences may be jumps, as in a stick-slip record) and dithers
quantised data first; the diagnosis uses it. Both judge repeats and ties to
round-off (:data:`REPEAT_TOLERANCE`), so a last-bit change does not move them.

The noise floor is the %e_r (Eq. 7) a perfect model would score:
``sqrt(n sigma^2 / sum(y^2)) * 100``.
"""

from __future__ import annotations

from math import comb

import numpy as np

__all__ = ['estimate_noise_std', 'floor_percent', 'held_share', 'noise_floor_percent',
           'OFFSET_SPANS', 'offset_words', 'quantum', 'REPEAT_FLOOR', 'REPEAT_TOLERANCE',
           'repeat_tolerance', 'robust_noise_std', 'STUCK_SHARE']

#: Steps below this share of the signal's spread count as repeats: a value written
#: through a unit conversion, or perturbed at round-off level, is still the same A/D count.
REPEAT_TOLERANCE = 1e-9
#: ...and never below this share of the largest value (:func:`repeat_tolerance`).
REPEAT_FLOOR = 1e-11

#: Share of the differences kept by the trimmed RMS.
_KEEP = 0.95
#: E[x^2 ; |x| < z] / (P(|x| < z) sigma^2) for a Gaussian trimmed to _KEEP
#: (z = 1.95996): the trimmed RMS underestimates sigma by its square root.
_TRIM_FACTOR = (0.95 - 2.0 * 1.959964 * 0.0584409) / 0.95


def estimate_noise_std(measurement: np.ndarray) -> float:
    """Estimate the standard deviation of additive white measurement noise.

    Parameters
    ----------
    measurement : numpy.ndarray
        Measured samples.

    Returns
    -------
    float
        Estimated noise standard deviation, in the measurement's units.
    """
    y = np.asarray(measurement, dtype=np.float64)
    estimates = []
    for order in (1, 2, 3):
        d = np.diff(y, n=order)
        if d.size < 8:
            continue
        dev = np.abs(d - np.median(d))
        cut = float(np.quantile(dev, _KEEP))
        # ties (quantised data) stay together when the last bits move
        kept = dev[dev <= cut * (1.0 + 1e-6) + repeat_tolerance(y)]
        rms = np.sqrt(np.mean(kept ** 2) / _TRIM_FACTOR)
        estimates.append(rms / np.sqrt(comb(2 * order, order)))
    sigma = min(estimates) if estimates else 0.0
    steps = np.abs(np.diff(y))
    tol = repeat_tolerance(y)
    steps = steps[steps > tol]
    if steps.size and held_share(y) > 0.2:
        sigma = max(sigma, float(np.min(steps)) / np.sqrt(12.0))
    return float(sigma)


def repeat_tolerance(y: np.ndarray) -> float:
    """Steps of ``y`` at most this large are repeats: its round-off (:data:`REPEAT_TOLERANCE`).

    Relative to the values' spread, not their size: a measurement riding on a large
    offset (1e8 with steps of 0.01) had half its samples called frozen when the
    tolerance was a share of ``max |y|``. Never below :data:`REPEAT_FLOOR` of the
    largest value (ten times the round-off probe's default perturbation,
    :func:`hyst_id.io.recording.roundoff_probe`), so a last-bit change still does not
    move the answer.
    """
    y = np.asarray(y, dtype=np.float64)
    if not y.size:
        return 0.0
    return max(REPEAT_TOLERANCE * float(np.ptp(y)), REPEAT_FLOOR * float(np.max(np.abs(y))))


#: Share of repeated samples above which :func:`robust_noise_std` leaves the repeats out
#: (when the values are not quantised): a reading stuck at a clip or end stop on 62 % of
#: a record gave a noise of 0, and the diagnosis divided by that floor.
STUCK_SHARE = 0.2


def _in_repeat_runs(y: np.ndarray) -> np.ndarray:
    """Whether each sample repeats a neighbour (to round-off)."""
    rep = np.abs(np.diff(y)) <= repeat_tolerance(y)
    out = np.zeros(y.size, dtype=bool)
    out[1:] |= rep
    out[:-1] |= rep
    return out


def held_share(measurement: np.ndarray) -> float:
    """Share of consecutive samples that repeat the previous value (to round-off)."""
    y = np.asarray(measurement, dtype=np.float64)
    if y.size < 2:
        return 0.0
    return float(np.mean(np.abs(np.diff(y)) <= repeat_tolerance(y)))


def quantum(measurement: np.ndarray) -> float:
    """A/D step of a quantised measurement (0 when the values are not on a grid).

    The smallest step between consecutive samples, when (nearly) every value
    lies on a grid of that step and at least 2 % of the samples repeat the
    previous one. Repeats and grid are judged to round-off
    (:data:`REPEAT_TOLERANCE`), so the answer does not change with the last
    bits of the values.
    """
    y = np.asarray(measurement, dtype=np.float64)
    d = np.abs(np.diff(y))
    d = d[d > repeat_tolerance(y)]
    if d.size < 10:
        return 0.0
    q = float(np.min(d))
    k = (y - y[0]) / q
    on_grid = np.mean(np.abs(k - np.round(k)) < 0.02) > 0.99
    return q if on_grid and held_share(y) > 0.02 else 0.0


def noise_floor_percent(measurement: np.ndarray, noise_std: float | None = None) -> float:
    """%e_r (Eq. 7) that measurement noise alone gives a perfect model.

    Parameters
    ----------
    measurement : numpy.ndarray
        Measured samples.
    noise_std : float, optional
        Known noise standard deviation; estimated when omitted.
    """
    y = np.asarray(measurement, dtype=np.float64)
    sigma = estimate_noise_std(y) if noise_std is None else float(noise_std)
    return floor_percent(y, sigma)


def floor_percent(measurement: np.ndarray, sigma: float) -> float:
    """%e_r (Eq. 7) that white noise of standard deviation ``sigma`` gives on ``measurement``.

    ``sqrt(n sigma^2 / sum(y^2)) * 100``: the error of a perfect model.
    """
    y = np.asarray(measurement, dtype=np.float64)
    return float(np.sqrt(y.size * sigma ** 2 / max(float(y @ y), 1e-300)) * 100.0)


#: A measurement whose mean lies further from zero than this many spans has %e_r read small.
OFFSET_SPANS = 1.0


def offset_words(er_percent: float, measurement: np.ndarray, unit: str = '') -> str:
    """Why %e_r reads small on a measurement far from zero, and the error in its units ('').

    %e_r (Eq. 7) divides by the measurement's RMS about zero, so an offset (a
    4-20 mA transmitter, a reading of 1000 kPa swinging by 100) makes it small for
    the same fit: an independent reviewer's 0.5 % of the span read 0.046 %.
    """
    y = np.asarray(measurement, dtype=np.float64)
    span = float(np.ptp(y)) if y.size else 0.0
    mean = float(np.mean(y)) if y.size else 0.0
    if not span > 0.0 or abs(mean) <= OFFSET_SPANS * span or not np.isfinite(er_percent):
        return ''
    rms = er_percent / 100.0 * float(np.sqrt(np.mean(y * y)))
    u = f' {unit}' if unit else ''
    return (f"%e_r (Eq. 7) divides by the measurement's RMS about zero, which its offset "
            f'dominates (mean {mean:.4g}{u} against a span of {span:.4g}{u}), so it reads '
            f"small: the best run's RMS error is {rms:.3g}{u}, {100.0 * rms / span:.3g} % of "
            'the span')


def robust_noise_std(measurement: np.ndarray) -> float:
    """Standard deviation of white measurement noise, robust to quantisation and jumps.

    Unlike :func:`estimate_noise_std` (a trimmed RMS that drops only the
    largest 5 % of the differences: the floor of identification), this takes the median absolute
    deviation of the differences of order 1, 2 and 3, so that a stick-slip
    recording, where up to half the differences can be jumps, is still read
    right (``Var = C(2d, d) sigma^2`` for
    white noise), the smallest of the three (a smooth signal inflates the
    low orders, kinks and jumps the high ones; the median ignores up to half
    the samples being stick-slip jumps). On A/D-quantised data the MAD of
    differences is itself one of a few quantised values and jumps between
    them, so the data are first dithered with a seeded uniform noise of one
    step, whose variance ``q^2 / 12`` is then subtracted.
    """
    y = np.asarray(measurement, dtype=np.float64)
    q = quantum(y)
    extra = 0.0
    if q > 0:
        y = y + np.random.default_rng(0).uniform(-0.5 * q, 0.5 * q, y.size)
        extra = q * q / 12.0
    # a reading stuck for a fifth of the record or more (a clip, an end stop, a dead
    # stretch) carries no noise there: its differences are left out
    free = ~_in_repeat_runs(y) if q == 0 and held_share(y) > STUCK_SHARE else None
    est = []
    for order, norm in ((1, 2.0), (2, 6.0), (3, 20.0)):
        d = np.diff(y, n=order)
        if free is not None:
            whole = np.convolve(free, np.ones(order + 1), 'valid') == order + 1
            d = d[whole] if np.count_nonzero(whole) >= 8 else d
        if d.size < 8:
            continue
        mad = float(np.median(np.abs(d - np.median(d))))
        est.append(np.sqrt(max((1.4826 * mad) ** 2 / norm - extra, 0.0)))
    sigma = float(min(est)) if est else float(np.std(y))
    return max(sigma, q / np.sqrt(12.0))
