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

"""Measurement artefacts: what the sensor or the logger did to a recording, not the plant.

:func:`find_artefacts` reads the measurement (and the command and stamps) for
four things no actuator or sensor model explains, each named as such
(issue 14: artefacts are reported, never dressed as physics):

* ``frozen`` -- the reading repeats one value exactly (to round-off) for
  :data:`FROZEN_MIN_SAMPLES` samples or more while the command moves, on a
  reading that is otherwise noisy and not quantised, and enters it by a noisy
  step or leaves it with a jump (:data:`ENTRY_STEPS`, :data:`EXIT_STEPS`): a
  sensor dropout or a logger holding its last value. A noisy reading never repeats a float
  exactly; a noise-free simulation does wherever the plant holds still (the
  backlash's dead zone), so a reading whose noise is below
  :data:`NOISY_SHARE` of its span is not judged. ``clipped`` is the same at
  the reading's top or bottom value: the sensor's range or an A/D clip (an end
  stop seen through a noisy sensor still shows the noise).
* ``glitch`` -- single samples that leave both neighbours in the same
  direction, by more than :data:`GLITCH_FACTOR` noise standard deviations and
  :data:`GLITCH_SPAN` of the span from the cubic through two neighbours each
  side, and from the line through the two next to it by more than
  :data:`GLITCH_SHAPE` times their own difference (a spike, not a step), the
  largest within two samples (a spike's neighbours see it in their cubic),
  away from the command's reversals and jumps (where a fast plant may turn
  within a sample).
* ``quantised`` -- the reading lies on a grid of
  :func:`~hyst_id.signals.noise.quantum` with at most :data:`COARSE_LEVELS`
  levels over its span where the step sets the noise floor (the noise std at
  most 1.5 x the step's ``q/sqrt(12)``), or at most a quarter of them
  whatever the noise: a coarse A/D.
* ``irregular_sampling`` -- the intervals between stamps (those longer than
  five median intervals left out: gaps, which the reader notes from ten) vary
  with a coefficient of variation above :data:`JITTER_CV`; said as the stamps'
  resolution when they are rounded to a step (intervals of 3 and 4 ms about a
  3.33 ms sampling), else as jitter.

The rules judge repeats to round-off and take no sum whose last bits decide
an answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hyst_id.signals.noise import quantum, repeat_tolerance, robust_noise_std
from hyst_id.signals.reversals import reversal_indices

__all__ = ['Artefact', 'COARSE_LEVELS', 'find_artefacts', 'FROZEN_MIN_SAMPLES', 'GLITCH_FACTOR',
           'GLITCH_SHAPE', 'GLITCH_SPAN', 'JITTER_CV', 'NOISY_SHARE']

#: Fewest exactly repeated samples that count as a frozen stretch.
FROZEN_MIN_SAMPLES = 5
#: A reading whose noise std is below this share of its span is not judged for frozen
#: stretches (a noise-free simulation repeats exactly wherever the plant holds still).
NOISY_SHARE = 3e-4
#: A noise-free sensor that settled exactly enters its stretch by a step under this many
#: median steps of the reading ...
ENTRY_STEPS = 0.1
#: ... and leaves it by one under this many (it starts to move): a stretch that does both
#: is not judged frozen; a dropout of a noisy reading enters by a noisy step or leaves
#: with a jump (the signal moved on meanwhile).
EXIT_STEPS = 4.0
#: Share of the command's span the command must move over a frozen stretch.
COMMAND_MOVES = 0.02
#: A glitch leaves both neighbours by more than this many noise standard deviations ...
GLITCH_FACTOR = 8.0
#: ... and by more than this share of the reading's span (a noise-free simulation's kink
#: leaves its neighbours by many times its tiny noise) ...
GLITCH_SPAN = 0.01
#: ... and by more than this many times the neighbours' own difference (a spike, not a step).
GLITCH_SHAPE = 1.0
#: Samples either side of a command reversal or jump where no glitch is judged.
GLITCH_GUARD = 2
#: Levels over the span at or below which a quantised reading whose step sets the floor
#: is reported (a quarter of them: reported whatever the noise).
COARSE_LEVELS = 256
#: Coefficient of variation of the sampling interval above which sampling is irregular.
JITTER_CV = 0.1


@dataclass(frozen=True)
class Artefact:
    """One kind of artefact found in a recording.

    Attributes
    ----------
    kind : str
        ``frozen``, ``clipped``, ``glitch``, ``quantised`` or ``irregular_sampling``.
    samples : tuple of (int, int)
        ``(first, count)`` of each stretch or sample it concerns (empty for
        ``quantised`` and ``irregular_sampling``, which concern the whole record).
    words : str
        One sentence for the report: what was found, where, and what it means.
    """

    kind: str
    samples: tuple[tuple[int, int], ...]
    words: str

    @property
    def n_samples(self) -> int:
        """Samples it concerns (0 for the whole-record kinds)."""
        return sum(n for _, n in self.samples)

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {'kind': self.kind, 'samples': [list(s) for s in self.samples],
                'n_samples': self.n_samples, 'words': self.words}


def find_artefacts(t_s: np.ndarray, command: np.ndarray, measurement: np.ndarray,
                   unit: str = '') -> list[Artefact]:
    """Artefacts of the sensor or the logger in a recording (module doc for the rules).

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times, seconds (increasing).
    command : numpy.ndarray
        Command samples.
    measurement : numpy.ndarray
        Measured samples.
    unit : str
        The measurement's unit, for the words.

    Returns
    -------
    list of Artefact
        In the order frozen/clipped, glitch, quantised, irregular sampling; empty
        when none is found or the record is too short (under 20 samples) to judge.
    """
    t = np.asarray(t_s, dtype=np.float64)
    v = np.asarray(command, dtype=np.float64)
    y = np.asarray(measurement, dtype=np.float64)
    if y.size < 20 or not (np.all(np.isfinite(y)) and np.all(np.isfinite(v))):
        return []
    span = float(np.ptp(y))
    if not span > 0.0:
        return []
    q = quantum(y)
    sigma = robust_noise_std(y)
    near_turn, reversals = _command_turns(v)
    out = _frozen(t, v, y, span, sigma, q, unit, reversals)
    out += _glitches(t, y, sigma, q, unit, near_turn)
    q_std = q / np.sqrt(12.0)
    levels = int(round(span / q)) + 1 if q > 0.0 else 0
    if 0 < levels <= COARSE_LEVELS and (levels <= COARSE_LEVELS // 4 or sigma <= 1.5 * q_std):
        floor = ('the step, not noise, sets the noise floor' if sigma <= 1.5 * q_std else
                 f'the noise (std {_g(sigma)}{_u(unit)}) is larger and sets the floor')
        out.append(Artefact('quantised', (), (
            f'the reading takes {levels} levels {_g(q)}{_u(unit)} apart (an A/D step of '
            f'{100.0 * q / span:.2g} % of its span, q/sqrt(12) = {_g(q_std)}{_u(unit)}): '
            f'{floor}; changes smaller than a step do not show. A grid is the A/D of the '
            'sensor (or a plant that moves in steps: a stepper, detents), not a loop shape')))
    out += _jitter(t)
    return out


def _frozen(t: np.ndarray, v: np.ndarray, y: np.ndarray, span: float, sigma: float, q: float,
            unit: str, reversals: np.ndarray) -> list[Artefact]:
    if q > 0.0 or not sigma >= NOISY_SHARE * span:
        return []
    tol = repeat_tolerance(y)
    rep = np.abs(np.diff(y)) <= tol
    v_span = float(np.ptp(v))
    typical = float(np.median(np.abs(np.diff(y))))
    found: dict[str, list[tuple[int, int]]] = {'frozen': [], 'clipped': []}
    runs = _runs(rep)
    physics = _holds_at_reversals(np.array([r[0] for r in runs], dtype=int), reversals)
    for (first, count), held in zip(runs, physics):
        n = count + 1                               # samples in a run of ``count`` repeats
        if n < FROZEN_MIN_SAMPLES or not np.ptp(v[first:first + n]) > COMMAND_MOVES * v_span:
            continue
        if held:
            continue    # a noise-free plant holds still in its play after each reversal
        end = first + n - 1
        smooth_in = first == 0 or abs(y[first] - y[first - 1]) < ENTRY_STEPS * typical
        smooth_out = end + 1 < y.size and abs(y[end + 1] - y[end]) < EXIT_STEPS * typical
        if smooth_in and smooth_out:
            continue    # a noise-free signal that settled exactly, then starts to move
        value = y[first]
        at_edge = value >= np.max(y) - tol or value <= np.min(y) + tol
        found['clipped' if at_edge else 'frozen'].append((first, n))
    out = []
    for kind, stretches in found.items():
        if not stretches:
            continue
        total = sum(n for _, n in stretches)
        first, n = max(stretches, key=lambda s: s[1])
        where = (f'{len(stretches)} stretch{"es" if len(stretches) > 1 else ""}, '
                 f'{total} samples ({100.0 * total / y.size:.1f} % of the record); the longest '
                 f'{n} samples from t = {_g(t[first])} s')
        what = ('a sensor dropout or a logger holding its last value' if kind == 'frozen'
                else "the sensor's range or an A/D clip (an end stop seen through a noisy "
                'sensor still shows the noise)')
        out.append(Artefact(kind, tuple(stretches), (
            f'the reading repeats one value exactly while the command moves ({where}), where '
            f'it is otherwise noisy (noise std {_g(sigma)}{_u(unit)}): {what}. No plant model '
            'explains it, and the fit takes these samples as data: identify on a part of the '
            'record without them (or record again) before trusting %e_r or a diagnosis')))
    return out


def _glitches(t: np.ndarray, y: np.ndarray, sigma: float, q: float, unit: str,
              turns: np.ndarray) -> list[Artefact]:
    scale = max(sigma, q)
    if not scale > 0.0:
        return []
    mid = y[2:-2]
    # departure from the cubic through the two neighbours each side (a smooth signal's
    # curvature, a ringing sensor's peak, leave it near zero), ...
    dev = mid - (4.0 * (y[1:-3] + y[3:-1]) - (y[:-4] + y[4:])) / 6.0
    # ... from the line through the neighbours, against their own difference (a step's
    # sample sits on one side of a difference as large as its departure)
    line = np.abs(mid - 0.5 * (y[1:-3] + y[3:-1]))
    shape = np.abs(y[3:-1] - y[1:-3])
    same_side = np.sign(mid - y[1:-3]) == np.sign(mid - y[3:-1])
    least = max(GLITCH_FACTOR * scale, GLITCH_SPAN * float(np.ptp(y)))
    spike = (np.abs(dev) > least) & (line > least) & (line > GLITCH_SHAPE * shape) & same_side
    idx = np.flatnonzero(spike) + 2
    # a spike leaves its neighbours' cubic off by 2/3 of it: keep the largest within two;
    # and it stands alone: ringing that the cubic cannot follow (a lightly damped mode at
    # a few samples per period) repeats it three to six samples away
    mag = np.abs(dev)

    def alone(i: int) -> bool:
        near = mag[max(i - 4, 0):i + 1]
        far = np.r_[mag[max(i - 8, 0):max(i - 4, 0)], mag[i + 1:i + 5]]
        return mag[i - 2] >= np.max(near) and not (far.size and np.max(far) >= 0.5 * least)
    idx = np.array([i for i in idx if alone(int(i)) and not turns[i]], dtype=int)
    if not idx.size:
        return []
    size = np.abs(dev[idx - 2])
    times = ', '.join(f'{_g(t[i])}' for i in idx[:5]) + (' ...' if idx.size > 5 else '')
    return [Artefact('glitch', tuple((int(i), 1) for i in idx), (
        f'{idx.size} single sample{"s" if idx.size > 1 else ""} leave both neighbours and '
        f'come back (up to {_g(float(np.max(size)))}{_u(unit)}, {float(np.max(size)) / scale:.0f} '
        f'x the noise std; at t = {times} s) away from any reversal or jump of the command: '
        'sensor or transmission glitches, not the plant. They weigh in %e_r as squared '
        'errors: remove or replace those samples before trusting the fit'))]


def _command_turns(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Samples within :data:`GLITCH_GUARD` of a command reversal or jump; the reversals.

    Reversals are judged with a band of three noise stds of the command (a measured,
    noisy command turned at every sample and left nothing to judge); a jump is a
    step above five median steps (any step where the command mostly holds). Both
    bands are at least the round-off of the command's values
    (:func:`~hyst_id.signals.noise.repeat_tolerance`): a held command moved in its
    last bits had turned at every sample.
    """
    turn = np.zeros(v.size, dtype=bool)
    roundoff = repeat_tolerance(v)            # last bits are no move
    idx, _ = reversal_indices(v, tolerance=max(3.0 * robust_noise_std(v), roundoff))
    idx = np.array([_plateau_start(v, int(k), roundoff) for k in idx], dtype=int)
    turn[idx] = True
    step = np.abs(np.diff(v))
    turn[1:] |= step > 5.0 * max(float(np.median(step)), roundoff)
    near = turn.copy()
    for k in range(1, GLITCH_GUARD + 1):
        near[k:] |= turn[:-k]
        near[:-k] |= turn[k:]
    return near, idx


def _plateau_start(v: np.ndarray, k: int, roundoff: float) -> int:
    """First sample of the plateau the extremum ``k`` lies on (to round-off).

    The extremum of a held command is any sample of the hold, whichever the last
    bits make largest; its first sample is the same on every machine.
    """
    while k > 0 and abs(v[k - 1] - v[k]) <= roundoff:
        k -= 1
    return k


def _holds_at_reversals(starts: np.ndarray, reversals: np.ndarray) -> np.ndarray:
    """Whether each run start is within :data:`GLITCH_GUARD` samples after a reversal.

    All False unless at least half the reversals (two or more) are followed so:
    a noise-free plant then holds exactly still in its play after every turn
    (physics); a noisy reading does not, and a dropout there is still one.
    """
    if reversals.size < 2 or not starts.size:
        return np.zeros(starts.size, dtype=bool)
    k = np.searchsorted(reversals, starts, side='right') - 1
    after = (k >= 0) & (starts - reversals[np.maximum(k, 0)] <= GLITCH_GUARD)
    followed = np.unique(k[after]).size
    return after if followed >= 0.5 * reversals.size else np.zeros(starts.size, dtype=bool)


def _jitter(t: np.ndarray) -> list[Artefact]:
    dt = np.diff(t)
    med = float(np.median(dt))
    if not med > 0.0:
        return []
    regular = dt[dt <= 5.0 * med]
    if regular.size < 10:
        return []
    cv = float(np.std(regular) / np.mean(regular))
    if cv <= JITTER_CV:
        return []
    step = _stamp_step(t, regular, med)
    if step:                          # rounded stamps: a few interval values a step apart
        values = ', '.join(_g(1e3 * x) for x in np.unique(np.round(regular / step)) * step)
        return [Artefact('irregular_sampling', (), (
            f'the stamps are rounded to {_g(1e3 * step)} ms: the intervals take the values '
            f'{values} ms about a median of {_g(1e3 * med)} ms (coefficient of variation '
            f'{100.0 * cv:.0f} %), a timing error of up to half a step in each stamp, not '
            'jitter of the sampling; finer stamps remove it'))]
    return [Artefact('irregular_sampling', (), (
        f'the sampling interval varies from {_g(1e3 * float(np.min(regular)))} to '
        f'{_g(1e3 * float(np.max(regular)))} ms (median {_g(1e3 * med)} ms, coefficient of '
        f'variation {100.0 * cv:.0f} %): the models run on the stamps, so this is fitted as '
        'recorded; if the stamps are arrival times rather than sampling times, their jitter '
        'is error the fit cannot remove (stamp at the source)'))]


def _stamp_step(t: np.ndarray, regular: np.ndarray, med: float) -> float:
    """The stamps' resolution when they are rounded to it (0 when not).

    Rounded: the intervals take at most four values, consecutive multiples of
    one step, and every stamp lies on that step's grid (to 1e-3 of it).
    """
    keys, which = np.unique(np.round(regular / med, 6), return_inverse=True)
    if not 2 <= keys.size <= 4:
        return 0.0
    values = np.array([float(np.mean(regular[which == j])) for j in range(keys.size)])
    steps = np.diff(values)
    step = float(np.min(steps))
    if not step > 0.0 or np.max(np.abs(steps / step - np.round(steps / step))) > 1e-3:
        return 0.0
    k = (t - t[0]) / step
    return step if float(np.max(np.abs(k - np.round(k)))) < 1e-3 else 0.0


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """``(first, length)`` of each run of True."""
    padded = np.concatenate([[False], flags, [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2])]


def _g(x: float) -> str:
    return f'{x:.4g}'


def _u(unit: str) -> str:
    return f' {unit}' if unit else ''
