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

"""The measured loop in words, from the data alone (before any model).

Which way the loop runs says what kind of physics makes it, and a physicist
reads that first. In the frame where the loop's mid-line rises with the
command (the measurement is read negated when its mid-line falls with the
command by more than the loop's full width; a flat band, whose mid-line
does not decide, is read as recorded):

* **counter-clockwise** (lower while the command rises, higher while it
  falls): the measurement *lags* the command, as a play, magnetic domains,
  a piezo stack or any lagging dynamics make it (the paper's model makes
  these loops);
* **clockwise** (higher while the command rises): the measurement *leads*
  the motion, as a force against the motion does (friction in a seal,
  a damper): the cylinder's force against its displacement;
* **thin**: no loop to speak of (half-width below :data:`THIN_SHARE` of
  the measurement's span).

The direction of each sample is its sweep's (between the command's
reversals beyond 2 % of its span and beyond 6 x its noise, so noise on a
measured command does not flip it); a hold at a reversal, before the
command has left the extreme by more than its noise, keeps the direction
that brought it there, and a hold inside a sweep (a staircase) the
sweep's. The mid-line's fall is the larger of its fall through the levels
and the fall between the tips (the mean measurement over the command's top
and bottom :data:`TIP_SHARE`, both directions together): a play barely
swung past its dead band has a mid-line flat between its tips. The
half-width is measured level by level: the command's range is cut into :data:`N_LEVELS` bins of
equal counts of distinct command values (so a long hold does not swallow
the bins), and in each the rising samples are set against the falling ones
at the same command (one straight line through the bin for both, shifted
apart by the gap, so where each direction's samples fall inside the bin
does not count). Half the gap, averaged over the bins (weighted by the
samples of the rarer direction), is the loop's half-width, signed by the
direction (a sum of signed area would be spoiled by loops that do not
close, as in a record of loops of growing amplitude one after another).
The samples split at their sweeps' median rate (each direction at its own,
as a drive may move out and back at different speeds) give the half-width
of the slow and of the fast sweeps: the same for a loop that does not
depend on the rate (a friction band, a play), larger at the fast sweeps
for viscous drag or lagging dynamics. The two are compared only when the
slow and the fast sweeps span about the same range (a larger sweep makes a
wider loop at any rate) and their rates differ by :data:`RATE_SPREAD`. All
are measured signatures, not fits; the diagnosis's blocks say the rest.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from hyst_id.errors import RecordingError
from hyst_id.signals.noise import repeat_tolerance, robust_noise_std
from hyst_id.signals.reversals import reversal_indices

__all__ = ['MeasuredLoop', 'measured_loop', 'MIN_SAMPLES', 'N_LEVELS', 'RATE_GROWTH',
           'RATE_SPREAD', 'SPAN_MATCH', 'THIN_SHARE']

#: Fast-sweep over slow-sweep half-width above which the loop is said to grow with the rate.
RATE_GROWTH = 1.3
#: Half-width, as a share of the measurement's span, below which the loop is thin.
THIN_SHARE = 0.005
#: Slow and fast sweeps are compared only when their median spans are within this ratio.
SPAN_MATCH = 1.25
#: Fast sweeps' median rate over the slow sweeps' needed to compare their loops.
RATE_SPREAD = 1.5
#: Levels (bins of equal counts of distinct command values) the half-width is measured at.
N_LEVELS = 12
#: Samples of each direction in a level needed to count it.
MIN_SAMPLES = 3
#: A hold at a reversal lasts while the command stays within this many noise sigmas.
HOLD_SIGMAS = 8.0
#: Share of the command's range at each end whose measurement marks the loop's tips.
TIP_SHARE = 0.05
#: A reversal is a move back by this share of the command's span ...
REVERSAL_SHARE = 0.02
#: ... and by this many of the command's noise sigmas (a measured command's noise).
REVERSAL_SIGMAS = 6.0

NO_SWEEP = 'the command does not sweep both ways, so the record traces no loop'
FEW_SAMPLES = ('too few samples of each direction at the same command levels to measure '
               'a loop')


@dataclass(frozen=True)
class MeasuredLoop:
    """What the measured loop looks like.

    Attributes
    ----------
    direction : str
        ``'counter-clockwise'``, ``'clockwise'`` or ``'thin'``, in the frame
        where the loop's mid-line rises with the command.
    rises_with_command : bool
        False when the measurement is read negated (its mid-line falls with
        the command by more than the loop's full width); True otherwise,
        also for a flat band.
    half_width : float
        Mean half-gap between the rising and the falling samples at the
        same command, over the command's levels, in measurement units;
        positive for the loop's own direction (a thin loop's is signed as
        a counter-clockwise one's); NaN when no loop could be measured
        (``reason`` says why).
    half_width_share : float
        ``|half_width|`` over the measurement's span.
    half_width_slow, half_width_fast : float
        The same over the sweeps slower and faster than their median rate.
    rate_slow, rate_fast : float
        Median rate of those sweeps (command units per second).
    span_slow, span_fast : float
        Median span of those sweeps (command units).
    reason : str
        Why no loop was measured (empty when one was).
    """

    direction: str
    rises_with_command: bool
    half_width: float
    half_width_share: float
    half_width_slow: float
    half_width_fast: float
    rate_slow: float
    rate_fast: float
    span_slow: float
    span_fast: float
    reason: str = ''

    @property
    def rates_comparable(self) -> bool:
        """Whether slow and fast sweeps span about the same range at rates that differ."""
        vals = (self.half_width_slow, self.half_width_fast, self.span_slow, self.span_fast,
                self.rate_slow, self.rate_fast)
        if not all(np.isfinite(vals)) or min(self.span_slow, self.span_fast) <= 0.0:
            return False
        return (max(self.span_slow, self.span_fast) <= SPAN_MATCH * min(self.span_slow,
                                                                        self.span_fast)
                and self.rate_fast >= RATE_SPREAD * self.rate_slow)

    @property
    def grows_with_rate(self) -> bool | None:
        """Whether the fast sweeps' loop is wider by :data:`RATE_GROWTH` (None: not compared)."""
        if self.direction == 'thin' or not self.rates_comparable or self.half_width_slow <= 0:
            return None
        return bool(self.half_width_fast > RATE_GROWTH * self.half_width_slow)

    def to_dict(self) -> dict:
        """The ``--json`` entry."""
        return {**asdict(self), 'rates_comparable': self.rates_comparable,
                'grows_with_rate': self.grows_with_rate}

    def words(self, quantity: str = 'measurement', unit: str = '') -> str:
        """One sentence for the report."""
        u = f' {unit}' if unit else ''
        if not np.isfinite(self.half_width):
            return self.reason or NO_SWEEP
        width = f'half-width {abs(self.half_width):.3g}{u}, {100 * self.half_width_share:.1f} %'
        if self.direction == 'thin':
            return (f'the measured loop is thin ({width} of the span): the {quantity} is '
                    'nearly a single-valued function of the command')
        q = quantity if self.rises_with_command else f'-{quantity}'
        frame = ('' if self.rises_with_command else
                 f' (read as -{quantity}: the {quantity} falls as the command rises)')
        if self.direction == 'counter-clockwise':
            kind = (f'counter-clockwise{frame}: the {q} lags the command (lower while it '
                    'rises), as a play, magnetic domains, a piezo stack or lagging dynamics '
                    'make it')
        else:
            kind = (f'clockwise{frame}: the {q} leads the motion (higher while the command '
                    'rises), as a force against the motion does (friction in a seal, a damper); '
                    "the paper's loop runs the other way")
        out = f'the measured loop runs {kind} ({width} of the span)'
        if np.isfinite(self.half_width_slow) and np.isfinite(self.half_width_fast):
            out += (f'; {self.half_width_slow:.3g}{u} over the slow sweeps '
                    f'({self.rate_slow:.3g}/s, spanning {self.span_slow:.3g}), '
                    f'{self.half_width_fast:.3g}{u} over the fast ({self.rate_fast:.3g}/s, '
                    f'{self.span_fast:.3g})')
            grows = self.grows_with_rate
            if grows is None:
                out += ': not compared, the sweeps differ in span or their rates are too alike'
            elif grows:
                out += ': the loop grows with the rate (viscous drag or lagging dynamics)'
            else:
                out += ': rate independent (a band or a play)'
        return out


def _sweeps(v: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per sample: its sweep's direction (+1, -1, 0), mean rate and span."""
    sigma = robust_noise_std(v) if v.size >= 4 else 0.0
    # a reversal is a move beyond 2 % of the span, and beyond the command's noise
    idx, dirs = reversal_indices(v, tolerance=max(REVERSAL_SHARE * float(np.ptp(v)),
                                                  REVERSAL_SIGMAS * sigma))
    n = v.size
    direction = np.zeros(n)
    rate = np.full(n, np.nan)
    span = np.full(n, np.nan)
    if idx.size == 0:
        return direction, rate, span
    edges = [0] + [int(i) for i in idx] + [n - 1]
    signs = [-int(dirs[0])] + [int(d) for d in dirs]
    hold_tol = max(HOLD_SIGMAS * sigma, 1e-12 * float(np.ptp(v)))
    for k, d in enumerate(signs):
        a, b = edges[k], edges[k + 1]
        if b <= a:
            continue
        direction[a + 1:b + 1] = d
        if k > 0:   # a hold at the reversal keeps the direction that brought it there
            left = np.flatnonzero(d * (v[a + 1:b + 1] - v[a]) > hold_tol)
            stop = a + 1 + (int(left[0]) if left.size else b - a)
            direction[a + 1:stop] = signs[k - 1]
        dv = abs(float(v[b] - v[a]))
        dt = float(t[b] - t[a])
        span[a + 1:b + 1] = dv
        rate[a + 1:b + 1] = dv / dt if dt > 0 else np.nan
    return direction, rate, span


def _level_edges(v: np.ndarray) -> np.ndarray:
    """Edges of :data:`N_LEVELS` bins of equal counts of distinct command values.

    Values within round-off (:func:`~hyst_id.signals.noise.repeat_tolerance`)
    count as one (a held step stays one value when its last bits move), and
    each inner edge lies midway between two distinct values, so no sample
    sits on an edge where a last-bit change would move it to the next bin.
    """
    x = np.sort(v)
    if x.size == 0:
        return x
    keep = np.r_[True, np.diff(x) > repeat_tolerance(x)]
    d = x[keep]
    if d.size < 2:
        return d
    at = np.unique(np.round(np.linspace(0, d.size - 1, N_LEVELS + 1)).astype(int))[1:-1]
    return np.unique(np.r_[d[0], 0.5 * (d[at] + d[at + 1]), d[-1]])


def _levels(v: np.ndarray, y: np.ndarray, direction: np.ndarray, edges: np.ndarray,
            keep: np.ndarray) -> list[tuple[float, float, float, float]]:
    """Per level with both directions: (weight, mean command, rising and falling value).

    The two values are those of one straight line through the level's
    samples, shifted apart for the two directions, at the level's mean
    command (so where each direction's samples lie inside the level does
    not count).
    """
    level = np.clip(np.searchsorted(edges, v, side='right') - 1, 0, edges.size - 2)
    out = []
    for b in range(edges.size - 1):
        at = keep & (level == b)
        up, down = at & (direction > 0), at & (direction < 0)
        w = min(int(np.count_nonzero(up)), int(np.count_nonzero(down)))
        if w < MIN_SAMPLES:
            continue
        vu, vd, yu, yd = v[up], v[down], y[up], y[down]
        sxx = float(np.sum((vu - vu.mean()) ** 2) + np.sum((vd - vd.mean()) ** 2))
        sxy = float(np.sum((vu - vu.mean()) * (yu - yu.mean()))
                    + np.sum((vd - vd.mean()) * (yd - yd.mean())))
        slope = sxy / sxx if sxx > 0 else 0.0
        vm = float(np.mean(v[up | down]))
        out.append((float(w), vm, float(yu.mean() + slope * (vm - vu.mean())),
                    float(yd.mean() + slope * (vm - vd.mean()))))
    return out


def _half_gap(levels: list[tuple[float, float, float, float]]) -> float:
    """Weighted mean over the levels of half (rising - falling)."""
    den = sum(w for w, *_ in levels)
    if den <= 0:
        return float('nan')
    return sum(w * 0.5 * (up - down) for w, _, up, down in levels) / den


def _midline_rise(levels: list[tuple[float, float, float, float]]) -> float:
    """How much the loop's mid-line rises over the levels (a weighted straight line)."""
    if len(levels) < 2:
        return 0.0
    w, vm, up, down = (np.array(x) for x in zip(*levels))
    if np.ptp(vm) <= 0:
        return 0.0
    slope = np.polyfit(vm, 0.5 * (up + down), 1, w=np.sqrt(w))[0]
    return float(slope * np.ptp(vm))


def _tips_rise(v: np.ndarray, y: np.ndarray, keep: np.ndarray) -> float:
    """Mean measurement at the command's top :data:`TIP_SHARE` less that at its bottom.

    Both directions together, so a band's two sides cancel; a loop whose
    mid-line is flat between its tips (a play barely swung past its dead
    band) still shows here which way its ends go.
    """
    vk, yk = v[keep], y[keep]
    lo, hi = float(vk.min()), float(vk.max())
    top, bottom = vk >= hi - TIP_SHARE * (hi - lo), vk <= lo + TIP_SHARE * (hi - lo)
    if not (np.any(top) and np.any(bottom)):
        return 0.0
    return float(np.mean(yk[top]) - np.mean(yk[bottom]))


def measured_loop(t_s: np.ndarray, command: np.ndarray, measurement: np.ndarray
                  ) -> MeasuredLoop:
    """Describe the loop a recording traces (see the module docstring).

    Parameters
    ----------
    t_s, command, measurement : numpy.ndarray
        The recording (finite, time increasing).

    Returns
    -------
    MeasuredLoop
        Direction and half-widths (positive in the loop's own direction).

    Raises
    ------
    RecordingError
        When the arrays differ in length or hold a NaN or an infinity.
    """
    t = np.asarray(t_s, dtype=np.float64)
    v = np.asarray(command, dtype=np.float64)
    y = np.asarray(measurement, dtype=np.float64)
    if not t.shape == v.shape == y.shape or t.ndim != 1:
        raise RecordingError(f'measured loop: time, command and measurement differ in shape '
                             f'({t.shape}, {v.shape}, {y.shape})')
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v)) and np.all(np.isfinite(y))):
        raise RecordingError('measured loop: the recording holds a NaN or an infinity')
    direction, rate, span = _sweeps(v, t)
    moving = direction != 0
    nan = float('nan')
    if not np.any(direction > 0) or not np.any(direction < 0):
        return MeasuredLoop('thin', True, nan, nan, nan, nan, nan, nan, nan, nan, NO_SWEEP)
    edges = _level_edges(v[moving])
    levels = _levels(v, y, direction, edges, moving) if edges.size >= 2 else []
    raw_gap = _half_gap(levels)
    if not np.isfinite(raw_gap):
        return MeasuredLoop('thin', True, nan, nan, nan, nan, nan, nan, nan, nan, FEW_SAMPLES)
    rise = min(_midline_rise(levels), _tips_rise(v, y, moving))
    rises = not rise < -2.0 * abs(raw_gap)
    ys = y if rises else -y
    gap = raw_gap if rises else -raw_gap
    y_span = float(np.ptp(y))
    share = abs(gap) / y_span if y_span > 0 else 0.0
    kind = ('thin' if not share >= THIN_SHARE else
            'clockwise' if gap > 0 else 'counter-clockwise')
    sign = 1.0 if kind == 'clockwise' else -1.0   # the loop's own direction
    slow = np.zeros(v.size, dtype=bool)
    for d in (-1.0, 1.0):   # each direction at its own median (strokes out and in differ)
        this = (direction == d) & np.isfinite(rate)
        if np.any(this):
            slow |= this & (rate <= float(np.median(rate[this])))
    fast = moving & ~slow
    w_slow = sign * _half_gap(_levels(v, ys, direction, edges, slow))
    w_fast = sign * _half_gap(_levels(v, ys, direction, edges, fast))

    def med(x: np.ndarray) -> float:
        x = x[np.isfinite(x)]
        return float(np.median(x)) if x.size else nan

    return MeasuredLoop(kind, bool(rises), float(sign * gap), float(share), float(w_slow),
                        float(w_fast), med(rate[slow]), med(rate[fast]), med(span[slow]),
                        med(span[fast]))
