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

"""Tests of the CSV and MCAP readers and the bag writer."""

from __future__ import annotations

import os
from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

from hyst_id.errors import ConfigError, MissingTopicError, NoExcitationError, RecordingError
from hyst_id.io.bag import BagWriter, iter_bag_messages, write_recording_bag
from hyst_id.io.csv_reader import read_csv, TIME_UNIT_NOTE
from hyst_id.io.mcap_reader import read_mcap
from hyst_id.io.readers import read_recording
from hyst_id.io.recording import Recording
from hyst_id.io.topics import (load_topic_config, node_parameters_in, parse_field_path,
                               TopicConfig)

__all__: list[str] = []

REPO = Path(__file__).resolve().parents[2]
REAL = Path('/work/shared/data/pneumatic-cylinder-friction')
T0 = 1_767_225_600 * 10**9


def _rec(n: int = 600, channel: str = 'position', dt: float = 0.01) -> Recording:
    t = np.arange(n) * dt
    command = 9.0 + 2.0 * np.sin(2 * np.pi * t / 2.0)
    return Recording(t, command, 0.4 * command + 0.05 * np.cos(t), channel, 'mA', 'x')


def _raises(exc_type: type, func, *args, **kwargs) -> str:
    with pytest.raises(exc_type) as info:
        func(*args, **kwargs)
    msg = str(info.value)
    assert msg and '\n' not in msg, msg
    return msg


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


# --- bags: round trips -------------------------------------------------------------------

@pytest.mark.parametrize('channel', ['position', 'pressure', 'flow'])
def test_bag_round_trip(tmp_path: Path, channel: str) -> None:
    rec = _rec(channel=channel)
    rec = Recording(rec.t_s + 2.5, rec.command, rec.measurement, channel)
    write_recording_bag(tmp_path / 'bag', rec)
    assert (tmp_path / 'bag' / 'metadata.yaml').exists()
    got = read_recording(tmp_path / 'bag', channel)
    cfg = TopicConfig.for_channel(channel)
    assert got.n_samples == rec.n_samples
    np.testing.assert_allclose(got.t_s, rec.t_s - rec.t_s[0], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(got.command, rec.command)
    np.testing.assert_array_equal(got.measurement, rec.measurement)
    assert (got.channel, got.command_unit, got.measurement_unit) == (
        channel, cfg.command_unit, cfg.measurement_unit)
    assert cfg.measurement_topic in got.source
    assert any('time origin' in note for note in got.notes)


def test_single_mcap_file_and_dir_without_metadata(tmp_path: Path) -> None:
    rec = _rec()
    write_recording_bag(tmp_path / 'bag', rec)
    mcap = tmp_path / 'bag' / 'bag.mcap'
    got = read_recording(mcap, 'position')
    np.testing.assert_array_equal(got.measurement, rec.measurement)
    (tmp_path / 'bag' / 'metadata.yaml').unlink()
    got = read_recording(tmp_path / 'bag', 'position')
    assert got.n_samples == rec.n_samples
    assert any('no metadata.yaml' in note for note in got.notes)


def test_custom_topics_and_lenient_type(tmp_path: Path) -> None:
    cfg = TopicConfig.for_channel('pressure', {
        'command_topic': '/rig/valve_cmd', 'pressure_topic': '/rig/p1',
        'pressure_type': 'std_msgs/msg/Float32', 'pressure_field': 'data',
        'pressure_unit': 'kPa'})
    rec = _rec(channel='pressure')
    write_recording_bag(tmp_path / 'bag', rec, cfg)
    got = read_recording(tmp_path / 'bag', 'pressure', topics=cfg)
    np.testing.assert_allclose(got.measurement, rec.measurement, rtol=1e-6)
    assert got.measurement_unit == 'kPa'
    # read with the default (FluidPressure) type but the right topic/field: accepted, noted
    other = {'command_topic': '/rig/valve_cmd', 'pressure_topic': '/rig/p1',
             'pressure_field': 'data'}
    got = read_recording(tmp_path / 'bag', 'pressure', topics=other)
    assert any('std_msgs/msg/Float32 (configured sensor_msgs/msg/FluidPressure)' in n
               for n in got.notes)


def test_zero_order_hold_pairing_sort_and_duplicates(tmp_path: Path) -> None:
    t_cmd = np.arange(0, 40) * 0.5
    cmd = 9 + np.sign(np.sin(2 * np.pi * t_cmd / 5.0) + 1e-9)
    t_meas = np.arange(-3, 400) * 0.05 + 0.01          # 3 samples before the first command
    stamps = list(range(len(t_meas)))
    stamps[10], stamps[11] = stamps[11], stamps[10]    # one pair out of order
    stamps.insert(50, stamps[50])                      # one duplicate stamp
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        for t, c in zip(t_cmd, cmd, strict=True):
            bag.write('/hyst_id/command', T0 + int(round(t * 1e9)), {'data': c})
        for k, i in enumerate(stamps):
            stamp = T0 + int(round(t_meas[i] * 1e9))
            bag.write('/hyst_id/position', T0 + 10**9 + k, {
                'header': {'stamp': stamp}, 'position': [float(i)]})
    got = read_recording(tmp_path / 'bag', 'position')
    kept = t_meas[3:]
    assert got.n_samples == len(kept)
    np.testing.assert_allclose(got.t_s, kept - kept[0], atol=1e-9)
    np.testing.assert_array_equal(got.measurement, np.arange(3, len(t_meas)))
    held = cmd[np.searchsorted(t_cmd, kept, side='right') - 1]
    np.testing.assert_array_equal(got.command, held)
    notes = ' | '.join(got.notes)
    assert 'out of order' in notes and 'duplicate stamp' in notes
    assert 'dropped 3 /hyst_id/position samples before the first command' in notes


def test_stamps_that_jump_back_are_refused_not_sorted(tmp_path: Path) -> None:
    """A clock set back mid-run is an error naming the jump; a swapped pair above is sorted.

    An independent reviewer's bag (header stamps set back 5 s from message 600) was
    sorted, lost 50 samples as duplicates and was identified at 137 x the floor.
    """
    t = np.arange(1200) * 0.05
    stamps = T0 + np.round(t * 1e9).astype(np.int64)
    stamps[600:] -= 5 * 10**9
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        for k in range(t.size):
            bag.write('/hyst_id/command', int(T0 + round(t[k] * 1e9)), {'data': np.sin(t[k])})
            bag.write('/hyst_id/position', int(T0 + round(t[k] * 1e9)) + 1000, {
                'header': {'stamp': int(stamps[k])}, 'position': [float(k)]})
    with pytest.raises(RecordingError, match=r'/hyst_id/position in .*: the header stamps '
                       r'jump back by 4.95 s \(99 median intervals\) at message 600 of 1200'):
        read_recording(tmp_path / 'bag', 'position')


@pytest.mark.parametrize('stop, gap, noted', [
    (300, (0, 0), 'ends 15 s (50 % of the record) before /hyst_id/position: its last value '
                  'was held'),
    (600, (180, 420), 'has a gap of 12.1 s (40 % of the record) from t = 8.95 s'),
    (598, (0, 0), ''), (600, (100, 110), '')])
def test_a_command_stream_that_stops_early_is_noted(tmp_path: Path, stop: int, gap: tuple,
                                                    noted: str) -> None:
    """The last command held over a gap or the end is said (it was silent); a short one not."""
    t = np.arange(600) * 0.05
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        for k in range(600):
            stamp = T0 + int(round(t[k] * 1e9))
            if k < stop and not gap[0] <= k < gap[1]:
                bag.write('/hyst_id/command', stamp, {'data': 9 + np.sin(t[k])})
            bag.write('/hyst_id/position', stamp + 1000, {
                'header': {'stamp': stamp + 1000}, 'position': [float(np.cos(t[k]))]})
    notes = ' | '.join(read_recording(tmp_path / 'bag', 'position').notes)
    if noted:
        assert noted in notes, notes
    else:
        assert 'held' not in notes, notes


def test_iter_bag_messages_order_and_filter(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec(50))
    msgs = list(iter_bag_messages(tmp_path / 'bag'))
    assert len(msgs) == 100
    assert [m[2] for m in msgs] == sorted(m[2] for m in msgs)
    only = list(iter_bag_messages(tmp_path / 'bag', ['/hyst_id/command']))
    assert len(only) == 50 and {m[1] for m in only} == {'std_msgs/msg/Float64'}
    assert only[1][3].data == pytest.approx(_rec(50).command[1])
    _raises(MissingTopicError, lambda: list(iter_bag_messages(tmp_path / 'bag', ['/nope'])))


def test_bag_writer_raw_bytes_and_finalise_on_error(tmp_path: Path) -> None:
    with pytest.raises(KeyboardInterrupt):
        with BagWriter(tmp_path / 'bag') as bag:
            bag.add_topic('/x', 'std_msgs/msg/Float64')
            raw = bag.typestore.serialize_cdr(
                bag.typestore.types['std_msgs/msg/Float64'](data=1.5), 'std_msgs/msg/Float64')
            bag.write('/x', 5, raw)
            bag.write('/x', 6, {'data': 2.5})
            raise KeyboardInterrupt
    assert (tmp_path / 'bag' / 'metadata.yaml').exists()
    assert [m[3].data for m in iter_bag_messages(tmp_path / 'bag')] == [1.5, 2.5]


def test_bag_writer_refuses_existing_path(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec())
    _raises(RecordingError, write_recording_bag, tmp_path / 'bag', _rec())
    _raises(ConfigError, BagWriter, tmp_path / 'other', chunk_size=10)


def test_chunk_size_bounds_chunks(tmp_path: Path) -> None:
    from mcap.reader import make_reader
    write_recording_bag(tmp_path / 'small', _rec(3000), chunk_size=4096)
    write_recording_bag(tmp_path / 'big', _rec(3000), chunk_size=2**20)
    counts = {}
    for name in ('small', 'big'):
        with open(tmp_path / name / f'{name}.mcap', 'rb') as fh:
            chunks = make_reader(fh).get_summary().chunk_indexes
        assert max(c.uncompressed_size for c in chunks) < (8192 if name == 'small' else 2**20)
        counts[name] = len(chunks)
    # 3000 samples at 10 ms: 30 s -> about 30 one-second chunks when the size does not bite
    assert counts['small'] > 80 and 25 <= counts['big'] <= 35


# --- bags: crash safety ------------------------------------------------------------------

_KILLED_WRITER = """
import sys, time
import numpy as np
from hyst_id.io.bag import BagWriter
bag = BagWriter(sys.argv[1], chunk_size=4096, chunk_span_s=None).open()
bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
for i in range(2000):
    t = 1_767_225_600 * 10**9 + i * 10**7
    c = 9 + 2 * np.sin(2 * np.pi * i / 300)
    bag.write('/hyst_id/command', t, {'data': c})
    bag.write('/hyst_id/position', t, {'header': {'stamp': t}, 'position': [0.4 * c]})
    if i == 1899:
        bag.flush()    # everything so far reaches the file; the last 100 samples are pending
print('ready', flush=True)
time.sleep(60)
"""


def test_killed_writer_leaves_readable_prefix(tmp_path: Path) -> None:
    env = dict(os.environ, PYTHONPATH=f'{REPO}{os.pathsep}{os.environ.get("PYTHONPATH", "")}')
    proc = subprocess.Popen([sys.executable, '-c', _KILLED_WRITER, str(tmp_path / 'bag')],
                            stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout.readline().strip() == 'ready'
    finally:
        proc.kill()
        proc.wait()
    assert not (tmp_path / 'bag' / 'metadata.yaml').exists()
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert 'recover_truncated' in msg
    got = read_recording(tmp_path / 'bag', 'position', recover_truncated=True)
    # the 4 KiB chunks closed after the flush survive too; only the pending one is lost
    assert 1900 < got.n_samples < 2000
    assert any('truncated' in note for note in got.notes)
    np.testing.assert_allclose(got.t_s[:3], [0.0, 0.01, 0.02], atol=1e-9)


def test_truncated_file_recovers_complete_chunks(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec(3000), chunk_size=8192)
    mcap = tmp_path / 'bag' / 'bag.mcap'
    raw = mcap.read_bytes()
    mcap.write_bytes(raw[:len(raw) // 2])
    got = read_mcap(tmp_path / 'bag', 'position', recover_truncated=True)
    assert 1000 < got.n_samples < 1500
    np.testing.assert_array_equal(got.measurement, _rec(3000).measurement[:got.n_samples])


# --- bags: errors --------------------------------------------------------------------------

def test_truncated_mcap(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec())
    mcap = tmp_path / 'bag' / 'bag.mcap'
    raw = mcap.read_bytes()
    mcap.write_bytes(raw[:len(raw) // 2])
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert msg.startswith('cannot read bag')
    _raises(RecordingError, read_recording, mcap, 'position')


def test_random_bytes_and_empty_mcap(tmp_path: Path) -> None:
    junk = tmp_path / 'junk.mcap'
    junk.write_bytes(np.random.default_rng(0).bytes(5000))
    msg = _raises(RecordingError, read_recording, junk, 'position')
    assert msg.startswith('cannot read bag') and 'recover' not in msg
    _raises(RecordingError, read_recording, junk, 'position', recover_truncated=True)
    empty = tmp_path / 'empty.mcap'
    empty.write_bytes(b'')
    _raises(RecordingError, read_recording, empty, 'position')
    _raises(RecordingError, read_recording, empty, 'position', recover_truncated=True)


def test_corrupt_metadata_yaml(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec())
    (tmp_path / 'bag' / 'metadata.yaml').write_text('rosbag2_bagfile_information: [unclosed')
    _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')


def test_missing_topic(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec())
    msg = _raises(MissingTopicError, read_recording, tmp_path / 'bag', 'pressure')
    assert '/hyst_id/pressure' in msg and '/hyst_id/command, /hyst_id/position' in msg


def test_wrong_message_type(tmp_path: Path) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'std_msgs/msg/String')
        for i in range(30):
            bag.write('/hyst_id/command', T0 + i, {'data': float(i % 7)})
            bag.write('/hyst_id/position', T0 + i, {'data': 'hello'})
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert 'std_msgs/msg/String' in msg and 'position[0]' in msg
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position',
                  topics={'position_field': 'data'})
    assert 'not a number' in msg


def test_empty_position_array(tmp_path: Path) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        bag.write('/hyst_id/command', T0, {'data': 1.0})
        bag.write('/hyst_id/position', T0, {'header': {'stamp': T0}})
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert 'position[0]' in msg


def test_joint_read_by_name_in_any_order(tmp_path: Path) -> None:
    rec = _rec(n=400)
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        for k in range(rec.n_samples):
            t_ns = T0 + int(rec.t_s[k] * 1e9)
            bag.write('/hyst_id/command', t_ns, {'data': float(rec.command[k])})
            names = ['arm', 'valve'] if k % 2 else ['valve', 'arm']   # the driver's order varies
            pos = [-1.0, float(rec.measurement[k])] if k % 2 else [float(rec.measurement[k]), -1.0]
            bag.write('/hyst_id/position', t_ns + 1000,
                      {'header': {'stamp': t_ns + 1000}, 'name': names, 'position': pos})
    got = read_recording(tmp_path / 'bag', 'position',
                         topics={'position_field': 'position[valve]'})
    np.testing.assert_allclose(got.measurement, rec.measurement)
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position',
                  topics={'position_field': 'position[gripper]'})
    assert "no entry named 'gripper'" in msg
    with pytest.raises(ConfigError, match='can be read, not written'):
        write_recording_bag(tmp_path / 'out', rec, TopicConfig.for_channel(
            'position', {'position_field': 'position[valve]'}))


def test_empty_topic(tmp_path: Path) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        bag.write('/hyst_id/command', T0, {'data': 1.0})
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert 'no messages' in msg and '/hyst_id/position' in msg


def test_measurements_all_before_command(tmp_path: Path) -> None:
    rec = _rec()
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', 'std_msgs/msg/Float64')
        bag.add_topic('/hyst_id/position', 'sensor_msgs/msg/JointState')
        for i, (t, c, m) in enumerate(zip(rec.t_s, rec.command, rec.measurement, strict=True)):
            bag.write('/hyst_id/command', T0 + 10**12 + i, {'data': c})
            bag.write('/hyst_id/position', T0 + 10**12 + i,
                      {'header': {'stamp': int(t * 1e9) + 1}, 'position': [m]})
    msg = _raises(RecordingError, read_recording, tmp_path / 'bag', 'position')
    assert 'different clocks' in msg


def test_constant_command(tmp_path: Path) -> None:
    rec = _rec()
    write_recording_bag(tmp_path / 'bag', Recording(rec.t_s, np.full(rec.n_samples, 9.0),
                                                    rec.measurement, 'position'))
    msg = _raises(NoExcitationError, read_recording, tmp_path / 'bag', 'position')
    assert str(tmp_path / 'bag') in msg


def test_csv_options_rejected_for_bags(tmp_path: Path) -> None:
    write_recording_bag(tmp_path / 'bag', _rec())
    _raises(ConfigError, read_recording, tmp_path / 'bag', 'position', columns=(0, 1, 2))
    _raises(ConfigError, read_recording, tmp_path / 'bag', 'torque')


# --- CSV -------------------------------------------------------------------------------------

def test_csv_with_header(tmp_path: Path) -> None:
    rec = _rec()
    lines = ['# rig run 3', 't,command,measurement'] + [
        f'{float(t)!r},{float(c)!r},{float(m)!r}'
        for t, c, m in zip(rec.t_s, rec.command, rec.measurement, strict=True)]
    path = _write(tmp_path / 'run.csv', '\n'.join(lines) + '\n\n')
    got = read_recording(path, 'position')
    np.testing.assert_array_equal(got.t_s, rec.t_s)
    np.testing.assert_array_equal(got.command, rec.command)
    np.testing.assert_array_equal(got.measurement, rec.measurement)
    assert got.source == str(path)
    got = read_recording(path, 'flow', topics={})
    assert (got.command_unit, got.measurement_unit) == ('mA', 'g/s')


def test_csv_named_columns_any_order(tmp_path: Path) -> None:
    path = _write(tmp_path / 'run.tsv', 'y\ttime_ms\tu\textra\n' + ''.join(
        f'{np.sin(i / 5)}\t{10 * i}\t{np.cos(i / 5)}\tok\n' for i in range(100)))
    got = read_recording(path, 'pressure', columns=('time_ms', 'u', 'y'), time_scale=1e-3)
    np.testing.assert_allclose(got.t_s, np.arange(100) * 0.01)
    np.testing.assert_allclose(got.command, np.cos(np.arange(100) / 5))


def test_headerless_ms_csv(tmp_path: Path) -> None:
    path = _write(tmp_path / 'run.txt', ''.join(
        f'{10 * i:.3f}\t{i}\t0\t0\t{np.sin(i / 9):.4f}\t1\t{np.cos(i / 9):.4f}\r\n'
        for i in range(200)))
    got = read_recording(path, 'position', columns=(0, 4, 6), time_scale=0.001)
    assert got.n_samples == 200
    np.testing.assert_allclose(got.t_s[:3], [0.0, 0.01, 0.02])


def _unit_notes(rec: Recording) -> list[str]:
    return [n for n in rec.notes if n.startswith(TIME_UNIT_NOTE)]


@pytest.mark.parametrize('header, step, scale, says', [
    ('time_ms', 10, None, '--time-scale 0.001'),      # the header names the unit
    ('t [us]', 1000, None, '--time-scale 1e-06'),
    ('t', 10, None, 'median sample interval of 10 s'),  # no unit named, slow for an actuator
    ('t', 0.01, None, None),                          # seconds at 100 Hz
    ('t_s', 10, None, None),                          # seconds named: believed
    ('index', 1, None, 'counts samples'),             # a sample counter: no period
    ('sample', 2, None, None),                        # a counter that skips: not one
    ('time_ms', 10, 1e-3, None),                      # the scale given
])
def test_time_unit_hint_for_a_csv_read_as_seconds(
        tmp_path: Path, header: str, step: float, scale: float | None, says: str | None) -> None:
    path = _write(tmp_path / 'run.csv', f'{header},command,measurement\n' + ''.join(
        f'{step * i!r},{np.sin(i / 9):.6f},{np.cos(i / 9):.6f}\n' for i in range(200)))
    got = read_recording(path, 'position', columns=(header, 'command', 'measurement'),
                         time_scale=scale)
    notes = _unit_notes(got)
    if says is None:
        assert notes == []
    else:
        assert len(notes) == 1 and says in notes[0] and repr(header) in notes[0], notes


def test_time_unit_hint_reaches_the_cli(tmp_path: Path, capsys) -> None:
    import argparse
    from hyst_id.commands.common import load_recording
    path = _write(tmp_path / 'run.csv', 't,command,measurement\n' + ''.join(
        f'{10 * i},{np.sin(i / 9):.6f},{np.cos(i / 9):.6f}\n' for i in range(200)))
    args = argparse.Namespace(recording=str(path), channel='position', params=None,
                              columns=None, time_scale=None)
    load_recording(args)
    assert 'note: the time column' in capsys.readouterr().err
    load_recording(argparse.Namespace(**{**vars(args), 'time_scale': 1e-3}))
    assert 'time column' not in capsys.readouterr().err


def test_a_gap_gets_a_note_on_the_cli(tmp_path: Path, capsys) -> None:
    """A 2 s hole in a 0.05 s record: said, with where and how long; jitter is not a gap."""
    import argparse
    from hyst_id.commands.common import load_recording
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.04, 0.06, 800))
    t[400:] += 2.0
    path = _write(tmp_path / 'gap.csv', 't,command,measurement\n' + ''.join(
        f'{a:.4f},{np.sin(a):.6f},{np.cos(a):.6f}\n' for a in t))
    args = argparse.Namespace(recording=str(path), channel='position', params=None,
                              columns=None, time_scale=None)
    load_recording(args)
    err = capsys.readouterr().err
    assert 'note: 1 gap(s) longer than 10 sample intervals, the longest 2.0' in err, err
    assert f't = {t[399]:.6g} s' in err
    t[400:] -= 2.0
    _write(path, 't,command,measurement\n' + ''.join(
        f'{a:.4f},{np.sin(a):.6f},{np.cos(a):.6f}\n' for a in t))
    load_recording(args)
    assert 'gap' not in capsys.readouterr().err


@pytest.mark.parametrize('name, rows, duration_s', [
    ('Circle_1bar.csv', 7139, 73.508), ('Circle_3bar.csv', 7834, 83.239),
    ('Circle_7bar.csv', 8720, 89.999)])
def test_real_pneumatic_csv(name: str, rows: int, duration_s: float) -> None:
    path = REAL / name
    if not path.exists():
        pytest.skip(f'{path} not available')
    got = read_recording(path, 'position', columns=(0, 4, 6), time_scale=0.001)
    # The files have no duplicate and no decreasing stamps (steps 10-287 ms, one 2.66 s
    # gap at 3 bar), so every row is kept and validation passes as is.
    assert got.n_samples == rows
    assert got.duration_s == pytest.approx(duration_s)
    assert _unit_notes(got) == []
    # read as seconds, the file's 10 ms steps are doubted
    assert _unit_notes(read_recording(path, 'position', columns=(0, 4, 6)))
    assert np.diff(got.t_s).min() >= 0.0099
    assert 30.0 < np.ptp(got.command) < 42.0          # piston stroke, mm


# --- CSV: errors -----------------------------------------------------------------------------

def test_missing_file(tmp_path: Path) -> None:
    msg = _raises(RecordingError, read_recording, tmp_path / 'nope.csv', 'position')
    assert msg.startswith('no such file')
    _raises(RecordingError, read_recording, tmp_path / 'nope', 'position')


def test_unrecognised_suffix(tmp_path: Path) -> None:
    _raises(RecordingError, read_recording, _write(tmp_path / 'run.xlsx', 'x'), 'position')


def test_empty_csv(tmp_path: Path) -> None:
    msg = _raises(RecordingError, read_recording, _write(tmp_path / 'e.csv', ''), 'position')
    assert msg.startswith('empty file')
    _raises(RecordingError, read_recording, _write(tmp_path / 'b.csv', '\n# c\n  \n'),
            'position')
    msg = _raises(RecordingError, read_recording,
                  _write(tmp_path / 'h.csv', 't,command,measurement\n'), 'position')
    assert 'only a header' in msg


def test_missing_column(tmp_path: Path) -> None:
    path = _write(tmp_path / 'run.csv', 't,cmd,measurement\n0,1,2\n')
    msg = _raises(MissingTopicError, read_recording, path, 'position')
    assert "'command'" in msg and 't, cmd, measurement' in msg
    msg = _raises(MissingTopicError, read_csv, path, 'position', columns=(0, 1, 7))
    assert 'index 7' in msg
    headerless = _write(tmp_path / 'nh.csv', '0,1,2\n1,2,3\n')
    msg = _raises(MissingTopicError, read_recording, headerless, 'position')
    assert 'no header row' in msg


def test_non_numeric_cell(tmp_path: Path) -> None:
    path = _write(tmp_path / 'run.csv', 't,command,measurement\n0,1,2\n0.1,abc,2\n')
    msg = _raises(RecordingError, read_recording, path, 'position')
    assert "'abc'" in msg and 'line 3' in msg and 'command' in msg


def test_ragged_rows(tmp_path: Path) -> None:
    path = _write(tmp_path / 'run.csv', 't,command,measurement\n0,1,2\n0.1,2\n')
    msg = _raises(RecordingError, read_recording, path, 'position')
    assert 'ragged' in msg and 'line 3' in msg


def _csv(tmp_path: Path, t: np.ndarray, command: np.ndarray, meas: np.ndarray) -> Path:
    return _write(tmp_path / 'run.csv', 't,command,measurement\n' + ''.join(
        f'{float(a)!r},{float(b)!r},{float(c)!r}\n'
        for a, b, c in zip(t, command, meas, strict=True)))


def test_nan_in_csv(tmp_path: Path) -> None:
    rec = _rec()
    meas = rec.measurement.copy()
    meas[17] = np.nan
    msg = _raises(RecordingError, read_recording, _csv(tmp_path, rec.t_s, rec.command, meas),
                  'position')
    # named by the file's column and line (the header is line 1: sample 17 is on line 19)
    assert 'NaN' in msg and 'column measurement of' in msg and 'line 19' in msg, msg


def test_backwards_and_duplicate_time_not_fixed(tmp_path: Path) -> None:
    rec = _rec()
    t = rec.t_s.copy()
    t[40], t[41] = t[41], t[40]
    path = _csv(tmp_path, t, rec.command, rec.measurement)
    msg = _raises(RecordingError, read_recording, path, 'position')
    assert 'backwards' in msg and 'sample 41' in msg
    raw = read_recording(path, 'position', validate=False)
    np.testing.assert_array_equal(raw.t_s, t)           # reported, never reordered
    t = rec.t_s.copy()
    t[40] = t[39]
    msg = _raises(RecordingError, read_recording, _csv(tmp_path, t, rec.command,
                                                       rec.measurement), 'position')
    assert 'duplicate timestamps' in msg


def test_constant_command_csv(tmp_path: Path) -> None:
    rec = _rec()
    _raises(NoExcitationError, read_recording,
            _csv(tmp_path, rec.t_s, np.full(rec.n_samples, 3.0), rec.measurement), 'position')


def test_bad_time_scale(tmp_path: Path) -> None:
    rec = _rec()
    path = _csv(tmp_path, rec.t_s, rec.command, rec.measurement)
    _raises(ConfigError, read_recording, path, 'position', time_scale=0.0)


# --- topic configuration ---------------------------------------------------------------------

@pytest.mark.parametrize('channel', ['position', 'pressure', 'flow'])
def test_shipped_topics_yaml_matches_defaults(channel: str) -> None:
    assert load_topic_config(REPO / 'params' / 'topics.yaml', channel) == \
        TopicConfig.for_channel(channel)


def test_topic_config_layouts(tmp_path: Path) -> None:
    plain = _write(tmp_path / 'a.yaml', 'topics:\n  command_topic: /c\n  flow_field: x.y[2]\n')
    cfg = load_topic_config(plain, 'flow')
    assert (cfg.command_topic, cfg.measurement_field, cfg.measurement_topic) == (
        '/c', 'x.y[2]', '/hyst_id/flow')
    flat = _write(tmp_path / 'b.yaml', 'identify:\n  ros__parameters:\n    rate_hz: 5\n'
                  '    pressure_topic: /p\n    topics.command_field: value\n')
    cfg = load_topic_config(flat, 'pressure')
    assert (cfg.measurement_topic, cfg.command_field) == ('/p', 'value')
    assert load_topic_config(flat, 'pressure', node='other') == \
        TopicConfig.for_channel('pressure')
    assert parse_field_path('a.b[2][3].c') == ('a', 'b', 2, 3, 'c')


@pytest.mark.parametrize('path', sorted((REPO / 'params').glob('*.yaml')), ids=lambda p: p.name)
def test_every_shipped_params_file_gives_its_topics_to_the_cli(path: Path) -> None:
    """``--params`` takes any node's file: its own stream keys and settings are left to it."""
    assert isinstance(load_topic_config(path, 'position'), TopicConfig)


def test_topic_config_namespaces_and_strays(tmp_path: Path) -> None:
    nested = _write(tmp_path / 'n.yaml', '/valve1:\n  identifier:\n    ros__parameters:\n'
                    '      seeds: 2\n      command_topic: /v1/cmd\n      topics:\n'
                    '        identified_params_topic: /x\n')
    assert load_topic_config(nested, 'position').command_topic == '/v1/cmd'
    assert node_parameters_in(nested) == ['seeds', 'topics.identified_params_topic']
    typo = _write(tmp_path / 't.yaml', '/**:\n  ros__parameters:\n    topics:\n'
                  '      comand_topic: /rig/cmd\n    topics.pressure_unit: Pa\n')
    assert node_parameters_in(typo) == ['topics.comand_topic']     # named, not dropped
    stray = _write(tmp_path / 's.yaml', 'seeds: 1\ntopics:\n  command_topic: /c\n')
    assert "unknown top-level key(s) ['seeds']" in _raises(ConfigError, load_topic_config,
                                                           stray, 'flow')


def test_topic_config_errors(tmp_path: Path) -> None:
    bad_key = _write(tmp_path / 'a.yaml', 'topics:\n  comand_topic: /c\n')
    assert 'comand_topic' in _raises(ConfigError, load_topic_config, bad_key, 'flow')
    bad_field = _write(tmp_path / 'b.yaml', 'topics:\n  flow_field: "data[-1]"\n')
    _raises(ConfigError, load_topic_config, bad_field, 'flow')
    _raises(ConfigError, load_topic_config, _write(tmp_path / 'c.yaml', 'topics: [1\n'), 'flow')
    _raises(ConfigError, load_topic_config, tmp_path / 'missing.yaml', 'flow')
    _raises(ConfigError, TopicConfig.for_channel, 'torque')
    _raises(ConfigError, TopicConfig.for_channel, 'flow', {'flow_topic': '/hyst_id/command'})
    _raises(ConfigError, TopicConfig.for_channel, 'flow', {'stamp_source': 'wall'})


def test_a_csv_header_names_the_signals_for_words_and_axes(tmp_path: Path) -> None:
    """The channel names the chain's structure; what was measured is the file's own name."""
    body = ''.join(f'{0.01 * i:.3f},{np.sin(i / 9):.6f},{np.cos(i / 9):.6f}\n'
                   for i in range(200))
    named = read_recording(_write(tmp_path / 'named.csv', 't,stroke_mm,force_N\n' + body),
                           'position', columns=('t', 'stroke_mm', 'force_N'))
    assert (named.command_name, named.measurement_name) == ('stroke_mm', 'force_N')
    assert named.quantity == 'force_N' and named.channel == 'position'
    assert named.window(10, 150).quantity == 'force_N'      # a part keeps the names
    generic = read_recording(_write(tmp_path / 'generic.csv', 't,command,measurement\n' + body),
                             'pressure')
    assert generic.quantity == 'pressure'      # not "the measured measurement"
    bare = read_recording(_write(tmp_path / 'bare.csv', body), 'pressure', columns=(0, 1, 2))
    assert (bare.command_name, bare.measurement_name) == ('', '')
    assert bare.quantity == 'pressure'                      # unnamed: the channel


def test_a_decimal_comma_and_a_unit_row_are_read(tmp_path: Path) -> None:
    """``0,25`` where cells are split by ``;`` or tabs, and a ``[s];[V];[um]`` row."""
    t, v, y = np.arange(200) * 0.05, np.sin(np.arange(200) / 9), np.cos(np.arange(200) / 9)
    rows = [(f'{a:.4f}', f'{b:.6f}', f'{c:.6f}') for a, b, c in zip(t, v, y)]
    comma = _write(tmp_path / 'de.csv', 't;command;measurement\n' + ''.join(
        ';'.join(cell.replace('.', ',') for cell in row) + '\n' for row in rows))
    got = read_recording(comma, 'position')
    np.testing.assert_allclose(got.t_s, t, atol=1e-9)
    np.testing.assert_allclose(got.measurement, y, atol=1e-6)
    headerless = _write(tmp_path / 'de_bare.tsv', ''.join(
        '\t'.join(cell.replace('.', ',') for cell in row) + '\n' for row in rows))
    assert read_recording(headerless, 'position', columns=(0, 1, 2)).n_samples == 200
    with pytest.raises(RecordingError, match="non-numeric value '1,234,5'"):
        read_csv(_write(tmp_path / 'bad.csv', 't;command;measurement\n0;1;2\n0,1;1,234,5;2\n'),
                 'position')
    units = _write(tmp_path / 'units.csv', 't;command;measurement\n[ms];[V];(um)\n' + ''.join(
        f'{1000 * float(a):.1f};{b};{c}\n' for a, b, c in rows))
    got = read_recording(units, 'position')
    assert (got.command_unit, got.measurement_unit) == ('V', 'um')
    assert _unit_notes(got) and '--time-scale 0.001' in _unit_notes(got)[0]   # ms named below
    given = read_csv(units, 'position', time_scale=1e-3, measurement_unit='mm')
    assert given.measurement_unit == 'mm' and _unit_notes(given) == []      # given units win
    np.testing.assert_allclose(given.t_s, t, atol=1e-6)


def test_a_tab_separated_header_with_spaces_and_units_in_brackets(tmp_path: Path) -> None:
    """``time [ms]<TAB>cmd [V]<TAB>pos [um]``: names with spaces, units from the brackets."""
    path = _write(tmp_path / 'run.txt', 'time [ms]\tcmd [V]\tpos [um]\textra\n' + ''.join(
        f'{10.0 * i:.1f}\t{np.sin(i / 9):.6f}\t{np.cos(i / 9):.6f}\t0\n' for i in range(200)))
    got = read_recording(path, 'position', columns=('time [ms]', 'cmd [V]', 'pos [um]'),
                         time_scale=1e-3)
    assert got.n_samples == 200 and got.duration_s == pytest.approx(1.99)
    assert (got.command_name, got.command_unit) == ('cmd', 'V')
    assert (got.measurement_name, got.measurement_unit, got.quantity) == ('pos', 'um', 'pos')
    assert read_recording(path, 'position', columns=(0, 1, 2), time_scale=1e-3).n_samples == 200
