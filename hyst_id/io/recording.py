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

"""The :class:`Recording` value object and its validation.

A recording is one command/response run: sample times in seconds, the
command applied to the actuator and one measured channel. Readers for CSV
and rosbag2 MCAP files live in :mod:`hyst_id.io.readers`; everything they
return passes through :func:`validate_recording` once, here.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import os

import numpy as np

from hyst_id.errors import NoExcitationError, RecordingError
from hyst_id.signals.reversals import count_reversals
from hyst_id.signals.split import split_index

__all__ = [
    'CHANNELS',
    'gap_note',
    'Recording',
    'ROUNDOFF_PROBE_ENV',
    'roundoff_probe',
    'validate_part',
    'validate_recording',
]

#: Measured channels the chains know about.
CHANNELS = ('position', 'pressure', 'flow')

#: Fewest samples an identification can work with.
MIN_SAMPLES = 20

#: Largest magnitude accepted in any column; beyond it squares overflow.
MAX_ABS_VALUE = 1e15

#: Smallest span accepted for the command and the measurement: below it the sums of
#: squares the fits compare underflow (a review's measurement in units 1e-200 too small ended
#: in a division by zero, 1e-160 in a wrong result); such a span means wrong units.
MIN_SPAN = 1e-12

#: A gap longer than this many median sample intervals means the file holds
#: more than one run (or lost data) and is refused.
MAX_GAP_FACTOR = 1000.0

#: A step longer than this many median sample intervals is a gap worth a note.
GAP_NOTE_FACTOR = 10.0

#: A command whose range is below this share of its largest magnitude excites
#: nothing (a float32 reading resolves about 6e-8 of its value).
MIN_RELATIVE_COMMAND_RANGE = 1e-6


@dataclass(frozen=True)
class Recording:
    """One command/response run.

    Attributes
    ----------
    t_s : numpy.ndarray
        Sample times in seconds, strictly increasing.
    command : numpy.ndarray
        Command applied to the actuator at each sample (held until the
        next sample), in ``command_unit`` (mA on the paper's rig).
    measurement : numpy.ndarray
        The measured channel at each sample, in ``measurement_unit``.
    channel : str
        One of :data:`CHANNELS`.
    command_unit, measurement_unit : str
        Free-text units, for reports only.
    source : str
        Where the data came from (path, topic names), for reports only.
    notes : tuple of str
        What the reader noticed (column mapping, a time-unit hint).
    command_name, measurement_name : str
        What the file calls the two signals (a CSV header's column names),
        for reports only; empty when unknown.
    """

    t_s: np.ndarray
    command: np.ndarray
    measurement: np.ndarray
    channel: str = 'position'
    command_unit: str = ''
    measurement_unit: str = ''
    source: str = ''
    notes: tuple = field(default=())
    command_name: str = ''
    measurement_name: str = ''

    @property
    def quantity(self) -> str:
        """What the measurement is, for words and axes: its name in the file, else the channel.

        The channel names the chain's structure (``position``: no sensor
        dynamics), which for a user's file need not be what was measured
        (a force, a flux density).
        """
        return self.measurement_name or self.channel

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.t_s.shape[0])

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample, in seconds."""
        return float(self.t_s[-1] - self.t_s[0])

    @property
    def dt_s(self) -> np.ndarray:
        """Sample intervals in seconds, ``dt_s[0]`` repeated first (length n)."""
        d = np.diff(self.t_s)
        return np.concatenate([d[:1], d])

    def window(self, start: int, stop: int) -> 'Recording':
        """Return samples ``start:stop`` as a new recording."""
        return replace(self, t_s=self.t_s[start:stop], command=self.command[start:stop],
                       measurement=self.measurement[start:stop])

    def split(self, train_fraction: float = 0.7) -> tuple['Recording', 'Recording']:
        """Split in time into a training part and the held-out rest.

        Parameters
        ----------
        train_fraction : float
            Fraction of the *duration* (not of the samples) used for training.

        Returns
        -------
        tuple of Recording
            ``(train, holdout)``.
        """
        k = split_index(self.t_s, train_fraction)
        return self.window(0, k), self.window(k, self.n_samples)


def validate_recording(rec: Recording, *, min_samples: int = MIN_SAMPLES,
                       min_reversals: int = 2,
                       max_gap_factor: float = MAX_GAP_FACTOR) -> Recording:
    """Check a recording and return it with float64 arrays.

    Parameters
    ----------
    rec : Recording
        The recording to check.
    min_samples : int
        Fewest samples accepted.
    min_reversals : int
        Fewest command reversals accepted (a loop needs a rise and a fall).
    max_gap_factor : float
        Largest sample interval accepted, in median intervals.

    Returns
    -------
    Recording
        The same data as contiguous float64 arrays.

    Raises
    ------
    RecordingError
        Wrong channel, mismatched lengths, too few samples, NaN/inf, values
        too large to square, duplicate or decreasing timestamps, a gap longer
        than ``max_gap_factor`` median intervals.
    NoExcitationError
        The command does not reverse often enough to excite the loop.
    """
    if rec.channel not in CHANNELS:
        raise RecordingError(f'unknown channel {rec.channel!r}; expected one of {CHANNELS}')
    arrays = {}
    for name in ('t_s', 'command', 'measurement'):
        if np.iscomplexobj(getattr(rec, name)):
            raise RecordingError(f'{name} is complex: give its real values (a measured '
                                 'signal has no imaginary part to drop silently)')
        try:
            arr = np.ascontiguousarray(np.asarray(getattr(rec, name), dtype=np.float64))
        except (TypeError, ValueError) as exc:
            raise RecordingError(f'{name} is not numeric: {exc}') from None
        if arr.ndim != 1:
            raise RecordingError(f'{name} must be one-dimensional, got shape {arr.shape}')
        arrays[name] = arr
    n = arrays['t_s'].shape[0]
    if arrays['command'].shape[0] != n or arrays['measurement'].shape[0] != n:
        raise RecordingError(
            f'length mismatch: {n} times, {arrays["command"].shape[0]} commands, '
            f'{arrays["measurement"].shape[0]} measurements')
    if n < min_samples:
        dropped = [str(note) for note in rec.notes if 'duplicate stamp' in str(note)]
        why = (f' after reading: {"; ".join(dropped)} (the stamps repeat: all zero, or the '
               'streams stamped by different clocks? give header.stamp or record with source '
               'time)' if dropped else '')
        raise RecordingError(f'too few samples: {n} (need at least {min_samples}){why}')
    for name, arr in arrays.items():
        bad = ~np.isfinite(arr)
        if bad.any():
            first = int(np.argmax(bad))
            raise RecordingError(
                f'{name} has {int(bad.sum())} NaN/inf values (first at sample {first})')
    for name, arr in arrays.items():
        peak = float(np.max(np.abs(arr)))
        if peak > MAX_ABS_VALUE:
            raise RecordingError(f'{name} has values up to {peak:.3g}, beyond {MAX_ABS_VALUE:.0e}:'
                                 ' wrong units or a corrupt file?')
    dt = np.diff(arrays['t_s'])
    if (dt == 0).any():
        first = int(np.argmax(dt == 0)) + 1
        raise RecordingError(
            f'duplicate timestamps: {int((dt == 0).sum())} (first at sample {first}, '
            f't={arrays["t_s"][first]:.6g} s)')
    if (dt < 0).any():
        first = int(np.argmax(dt < 0)) + 1
        raise RecordingError(
            f'time goes backwards at {int((dt < 0).sum())} samples (first at sample {first}, '
            f't={arrays["t_s"][first]:.6g} s)')
    median_dt = float(np.median(dt))
    if dt.max() > max_gap_factor * median_dt:
        first = int(np.argmax(dt)) + 1
        raise RecordingError(
            f'gap of {dt.max():.6g} s at sample {first} (t={arrays["t_s"][first]:.6g} s) is '
            f'{dt.max() / median_dt:.0f} x the median interval {median_dt:.3g} s: '
            'split the recording or pass a larger max_gap_factor')
    if np.ptp(arrays['command']) <= 0.0:
        raise NoExcitationError('command is constant: nothing excites the hysteresis loop')
    level = float(np.max(np.abs(arrays['command'])))
    if np.ptp(arrays['command']) <= MIN_RELATIVE_COMMAND_RANGE * level:
        raise NoExcitationError(
            f'command varies by {np.ptp(arrays["command"]):.3g} at magnitudes up to '
            f'{level:.6g}, less than {MIN_RELATIVE_COMMAND_RANGE:g} of them (finer than a '
            'float32 reading resolves): nothing excites the hysteresis loop')
    reversals = count_reversals(arrays['command'])
    if reversals < min_reversals:
        raise NoExcitationError(
            f'command reverses {reversals} time(s); identification needs at least '
            f'{min_reversals} reversals to excite the hysteresis loop')
    if np.ptp(arrays['measurement']) <= 0.0:
        raise RecordingError('measurement is constant: the sensor shows no response')
    for name in ('command', 'measurement'):
        span = float(np.ptp(arrays[name]))
        if span < MIN_SPAN:
            raise RecordingError(f'{name} spans only {span:.3g}, below {MIN_SPAN:.0e}: wrong '
                                 'units? give it in a unit with larger numbers (um rather '
                                 'than m)')
    return replace(rec, **arrays)


def validate_part(part: Recording, what: str) -> Recording:
    """:func:`validate_recording` of a part of a record; an error names the part and file.

    ``what`` says which part (e.g. the training part of a split and what sets it), so
    that a record that passes as a whole is not refused for a reason it does not have.
    """
    try:
        return validate_recording(part)
    except RecordingError as exc:
        where = f'{part.source}: ' if part.source else ''
        raise type(exc)(f'{where}{what}: {exc}') from None


#: Environment variable of the round-off probe (``<seed>`` or ``<seed>:<relative size>``).
ROUNDOFF_PROBE_ENV = 'HYST_ID_ROUNDOFF_PROBE'


def roundoff_probe(rec: Recording) -> Recording:
    """Perturb a validated recording at round-off level when the probe is switched on.

    Another CPU make sums in another order and differs in the last bits of
    every result; this imitates it. With ``HYST_ID_ROUNDOFF_PROBE=<seed>``
    (optionally ``<seed>:<size>``, default size ``1e-12``) every measurement
    sample is multiplied by ``1 + size * z`` (``z`` standard normal, drawn
    from ``seed``) and the whole command by one such factor (held commands
    stay equal, their order is kept). Unset or empty: the recording is returned
    unchanged. The numeric stages call it on the recordings they are given
    (identification and diagnosis); reading and writing files do not (they
    are exact on every CPU). ``bench/roundoff_verdicts.py`` runs the suite
    under it.

    Parameters
    ----------
    rec : Recording
        A validated recording.

    Returns
    -------
    Recording
        The same recording, perturbed when the probe is on.
    """
    setting = os.environ.get(ROUNDOFF_PROBE_ENV, '').strip()
    if not setting:
        return rec
    seed, _, size = setting.partition(':')
    try:
        rng = np.random.default_rng(int(seed))
        eps = float(size) if size else 1e-12
    except ValueError:
        raise RecordingError(f'{ROUNDOFF_PROBE_ENV}={setting!r}: expected <seed>[:<size>]') \
            from None
    y = rec.measurement
    return replace(rec, measurement=y * (1.0 + eps * rng.standard_normal(y.shape[0])),
                   command=rec.command * (1.0 + eps * float(rng.standard_normal())))


def gap_note(t_s: np.ndarray, factor: float = GAP_NOTE_FACTOR) -> str | None:
    """Words on the steps longer than ``factor`` median intervals, or None when there are none.

    What the command did over such a gap is not recorded; the chain holds the
    sample before it, so a sensor's or actuator's dynamics fitted across it
    take the difference (a lag comes out longer).
    """
    dt = np.diff(np.asarray(t_s, dtype=float))
    if dt.size == 0:
        return None
    median_dt = float(np.median(dt))
    long = np.flatnonzero(dt > factor * median_dt)
    if long.size == 0:
        return None
    k = int(long[np.argmax(dt[long])])
    return (f'{long.size} gap(s) longer than {factor:g} sample intervals, the longest '
            f'{dt[k]:.3g} s ({dt[k] / median_dt:.0f} x the median {median_dt:.3g} s) at '
            f't = {t_s[k]:.6g} s: the command over a gap is not recorded and is held at '
            'its last sample, which biases fitted dynamics (a lag comes out longer); split '
            'the record there or give it without gaps')
