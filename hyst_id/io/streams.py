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

"""Two timestamped message streams (command, measurement) into one Recording.

One implementation for the bag reader (:func:`hyst_id.io.mcap_reader.read_mcap`)
and live collection (:class:`hyst_id.live.buffer.SampleBuffer`): each stream is
sorted by stamp with repeated stamps keeping their last sample
(:func:`tidy_stream`), then each measurement gets the last command at or
before its stamp (the DAC holds a command until the next one), measurements
before the first command are dropped and gaps in the measurement stream are
noted. Every repair is a note in ``Recording.notes``.
"""

from __future__ import annotations

import numpy as np

from hyst_id.errors import RecordingError
from hyst_id.io.recording import Recording

__all__ = ['GAP_NOTE_FACTOR', 'gap_note', 'pair_streams', 'tidy_stream']

#: A measurement interval longer than this many median intervals is noted as a gap.
GAP_NOTE_FACTOR = 5.0


def tidy_stream(t_ns: np.ndarray, values: np.ndarray, name: str,
                notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Sort a stream by stamp and keep the last message of each repeated stamp.

    Parameters
    ----------
    t_ns, values : numpy.ndarray
        Stamps (integer ns) and values, in arrival order.
    name : str
        The stream's name in notes (its topic).
    notes : list of str
        Appended to when anything is sorted or dropped.
    """
    t_ns = np.asarray(t_ns, dtype=np.int64)
    values = np.asarray(values, dtype=np.float64)
    if (np.diff(t_ns) < 0).any():
        notes.append(f'{name}: {int((np.diff(t_ns) < 0).sum())} stamps out of order; '
                     f'sorted by stamp')
        order = np.argsort(t_ns, kind='stable')
        t_ns, values = t_ns[order], values[order]
    keep = np.append(t_ns[1:] != t_ns[:-1], True)
    if not keep.all():
        kept, dropped = np.flatnonzero(keep), np.flatnonzero(~keep)
        other = int(np.sum(values[dropped] != values[kept[np.searchsorted(kept, dropped)]]))
        notes.append(f'{name}: dropped {dropped.size} messages with a duplicate stamp (kept the '
                     'last at each stamp' + (
                         f'; {other} of them carried another value: two messages stamped on '
                         'one clock tick, as messages stamped on arrival under use_sim_time '
                         'can be when they race the /clock of a replay' if other else '') + ')')
        t_ns, values = t_ns[keep], values[keep]
    return t_ns, values


def gap_note(t_s: np.ndarray, name: str) -> str:
    """Describe intervals longer than :data:`GAP_NOTE_FACTOR` median intervals ('' if none)."""
    if t_s.size < 3:
        return ''
    dt = np.diff(t_s)
    median = float(np.median(dt))
    if median <= 0.0:
        return ''
    long = np.flatnonzero(dt > GAP_NOTE_FACTOR * median)
    if long.size == 0:
        return ''
    k = int(long[np.argmax(dt[long])])
    missing = int(np.sum(np.rint(dt[long] / median) - 1))
    return (f'{name}: {long.size} gap(s) longer than {GAP_NOTE_FACTOR:g} median intervals '
            f'({median:.3g} s), about {missing} samples missing; longest {dt[k]:.3g} s after '
            f't={t_s[k]:.6g} s')


def _held_command(cmd_t: np.ndarray, meas_t: np.ndarray, names: tuple[str, str]) -> str:
    """A note when the command's last value is held over a long stretch ('' if not).

    A stretch between two commands, or after the last one, longer than
    :data:`GAP_NOTE_FACTOR` of the command's median intervals and than 5 % of the record:
    the stream stopped or has a gap, or it is sent only on change.
    """
    whole_ns = float(meas_t[-1] - meas_t[0])
    if whole_ns <= 0.0:
        return ''
    median = float(np.median(np.diff(cmd_t))) if cmd_t.size > 1 else 0.0
    limit = max(GAP_NOTE_FACTOR * median, 0.05 * whole_ns)
    tail_ns = float(meas_t[-1] - cmd_t[-1])
    if tail_ns > limit:
        return (f'{names[0]} ends {tail_ns / 1e9:.3g} s ({100.0 * tail_ns / whole_ns:.0f} % of '
                f'the record) before {names[1]}: its last value was held over that stretch (a '
                'stream that stopped, or one sent only on change? trim the record if it '
                'stopped)')
    inside = cmd_t[(cmd_t >= meas_t[0]) & (cmd_t <= meas_t[-1])]
    gaps = np.diff(inside) if inside.size > 1 else np.zeros(0)
    if gaps.size and float(gaps.max()) > limit:
        k = int(np.argmax(gaps))
        return (f'{names[0]} has a gap of {gaps[k] / 1e9:.3g} s ({100.0 * gaps[k] / whole_ns:.0f} '
                f'% of the record) from t = {(inside[k] - meas_t[0]) / 1e9:.6g} s: its value '
                'was held over it (lost messages, or a stream sent only on change?)')
    return ''


def pair_streams(cmd_t_ns: np.ndarray, cmd_v: np.ndarray, meas_t_ns: np.ndarray,
                 meas_v: np.ndarray, channel: str, source: str = '',
                 units: tuple[str, str] = ('', ''),
                 names: tuple[str, str] = ('command', 'measurement'),
                 notes: list[str] | None = None) -> Recording:
    """Pair each measurement with the last command at or before it.

    Parameters
    ----------
    cmd_t_ns, cmd_v, meas_t_ns, meas_v : array_like
        Stamps (integer ns) and values of the two streams, in arrival order.
    channel : str
        Measured channel.
    source : str
        Where the samples came from (for reports).
    units : tuple of str
        Command and measurement units.
    names : tuple of str
        How the two streams are called in notes (e.g. their topics).
    notes : list of str, optional
        Notes gathered before (e.g. by the bag reader); pairing appends to them.

    Returns
    -------
    Recording
        Not validated; ``t_s`` counts from the first kept measurement and
        ``notes`` say what was sorted, dropped or missing, and the stamp of
        ``t_s = 0``.

    Raises
    ------
    RecordingError
        A stream is empty or no measurement follows a command.
    """
    notes = list(notes or [])
    if len(cmd_t_ns) == 0 or len(meas_t_ns) == 0:
        raise RecordingError(f'no samples yet: {len(cmd_t_ns)} commands, '
                             f'{len(meas_t_ns)} measurements')
    cmd_t, cmd_v = tidy_stream(cmd_t_ns, cmd_v, names[0], notes)
    meas_t, meas_v = tidy_stream(meas_t_ns, meas_v, names[1], notes)
    idx = np.searchsorted(cmd_t, meas_t, side='right') - 1
    keep = idx >= 0
    if not keep.any():
        raise RecordingError(
            f'no {names[1]} sample at or after the first {names[0]} message (measurements '
            f'{meas_t[0] / 1e9:.3f}..{meas_t[-1] / 1e9:.3f} s, first command '
            f'{cmd_t[0] / 1e9:.3f} s since the epoch; different clocks? a stream stamped in '
            'its header and one stamped on arrival differ by the age of a replayed bag: '
            'replay with use_sim_time:=true, or stamp both on arrival, topics.stamp_source: '
            'log)')
    if not keep.all():
        notes.append(f'dropped {int((~keep).sum())} {names[1]} samples before the first '
                     f'command')
    meas_t, meas_v, idx = meas_t[keep], meas_v[keep], idx[keep]
    t_s = (meas_t - meas_t[0]).astype(np.float64) * 1e-9
    gap = gap_note(t_s, names[1])
    if gap:
        notes.append(gap)
    held = _held_command(cmd_t, meas_t, names)
    if held:
        notes.append(held)
    notes.append(f'time origin t_s = 0: stamp {meas_t[0] / 1e9:.9f} s since the epoch')
    return Recording(t_s=t_s, command=cmd_v[idx], measurement=meas_v, channel=channel,
                     command_unit=units[0], measurement_unit=units[1], source=source,
                     notes=tuple(notes))
