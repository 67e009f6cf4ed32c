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

"""Fuzz-style bad input for the recording reader and the CLI (issue 6).

Every case must end in one clear line on stderr and a non-zero exit, with no
traceback, and must leave every file on disk untouched. The list of cases is
``CASES`` below; ``docs/reliability.md`` lists them for users.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
import re
import subprocess
import sys

import numpy as np
import pytest

from hyst_id.cli import main
from hyst_id.io.bag import BagWriter, write_recording_bag
from hyst_id.io.recording import Recording
from hyst_id.io.topics import TopicConfig

T = np.arange(0.0, 40.0, 0.05)
V = 9 + 2 * np.sin(2 * np.pi * T / 10)
Y = 1.05 * (V - 0.5)


def write_csv(path: Path, t=T, v=V, y=Y, header='t,command,measurement') -> Path:
    rows = [header] if header else []
    rows += [f'{a:.17g},{b:.17g},{c:.17g}' for a, b, c in zip(t, v, y)]
    path.write_text('\n'.join(rows) + '\n')
    return path


def make_bag(path: Path, **changes) -> Path:
    values = {'t_s': T, 'command': V, 'measurement': Y, **changes}
    rec = Recording(values['t_s'], values['command'], values['measurement'], 'position')
    write_recording_bag(path, rec)
    return path


def truncated_bag(tmp: Path) -> Path:
    bag = make_bag(tmp / 'full')
    mcap = next(bag.glob('*.mcap'))
    data = mcap.read_bytes()
    out = tmp / 'truncated.mcap'
    out.write_bytes(data[:len(data) // 2])
    return out


def wrong_type_bag(tmp: Path) -> Path:
    path = tmp / 'wrong_type'
    cfg = TopicConfig.for_channel('position')
    with BagWriter(path) as writer:
        writer.add_topic(cfg.command_topic, 'std_msgs/msg/Float64')
        writer.add_topic(cfg.measurement_topic, 'std_msgs/msg/String')
        for i, t in enumerate(T):
            t_ns = int(1e18 + t * 1e9)
            writer.write(cfg.command_topic, t_ns, {'data': float(V[i])})
            writer.write(cfg.measurement_topic, t_ns, {'data': 'not a number'})
    return path


def _stamped_bag(path: Path, log_ns: np.ndarray, stamp_ns: np.ndarray) -> Path:
    """Command and header-stamped measurement, message ``i`` logged at ``log_ns[i]``."""
    cfg = TopicConfig.for_channel('position')
    with BagWriter(path) as writer:
        writer.add_topic(cfg.command_topic, 'std_msgs/msg/Float64')
        writer.add_topic(cfg.measurement_topic, cfg.measurement_type)
        for i in range(T.size):
            writer.write(cfg.command_topic, int(log_ns[i]), {'data': float(V[i])})
            writer.write(cfg.measurement_topic, int(log_ns[i]), {
                'header': {'stamp': int(stamp_ns[i])}, 'position': [float(Y[i])]})
    return path


def clock_jump_bag(tmp: Path) -> Path:
    """Header stamps set back 5 s from message 400 on (a clock reset), log times in order."""
    log_ns = (10**18 + np.round(T * 1e9)).astype(np.int64)
    return _stamped_bag(tmp / 'clock_jump', log_ns,
                        log_ns - np.where(np.arange(T.size) >= 400, 5 * 10**9, 0))


def zero_stamp_bag(tmp: Path) -> Path:
    """Every message stamped 0 (header and log time): reading keeps one sample."""
    zeros = np.zeros(T.size, dtype=np.int64)
    return _stamped_bag(tmp / 'zero_stamps', zeros, zeros)


def no_topics_bag(tmp: Path) -> Path:
    path = tmp / 'other_topics'
    with BagWriter(path) as writer:
        writer.add_topic('/something/else', 'std_msgs/msg/Float64')
        for t in T[:50]:
            writer.write('/something/else', int(1e18 + t * 1e9), {'data': 1.0})
    return path


def empty_topic_bag(tmp: Path) -> Path:
    path = tmp / 'empty_topic'
    cfg = TopicConfig.for_channel('position')
    with BagWriter(path) as writer:
        writer.add_topic(cfg.command_topic, 'std_msgs/msg/Float64')
        writer.add_topic(cfg.measurement_topic, 'sensor_msgs/msg/JointState')
        for i, t in enumerate(T):
            writer.write(cfg.command_topic, int(1e18 + t * 1e9), {'data': float(V[i])})
    return path


def nan_at(arr, i=10):
    out = np.array(arr, dtype=float)
    out[i] = np.nan
    return out


def with_gap(t):
    out = np.array(t, dtype=float)
    out[400:] += 500.0
    return out


def dup_t(t):
    out = np.array(t, dtype=float)
    out[20] = out[19]
    return out


def back_t(t):
    out = np.array(t, dtype=float)
    out[20], out[21] = out[21], out[20]
    return out


#: (case id, builder(tmp) -> argv after 'identify', expected text in the error line)
CASES = [
    ('missing-file', lambda d: [str(d / 'nope.csv')], 'no such file'),
    ('empty-csv', lambda d: [str(_touch(d / 'empty.csv'))], 'empty'),
    ('header-only-csv', lambda d: [str(_text(d / 'h.csv', 't,command,measurement\n'))],
     'no data'),
    ('missing-column', lambda d: [str(write_csv(d / 'm.csv', header='t,cmd,measurement'))],
     'command'),
    ('non-numeric-cell',
     lambda d: [str(_text(d / 'x.csv', 't,command,measurement\n0,1,2\n0.1,abc,2\n'))], 'line'),
    ('ragged-rows', lambda d: [str(_text(d / 'r.csv', 't,command,measurement\n0,1,2\n0.1,2\n'))],
     'line'),
    ('nan-measurement', lambda d: [str(write_csv(d / 'n.csv', y=nan_at(Y)))], 'NaN'),
    # named as the file names the column, at its line (it had said ``t_s``, the reader's name)
    ('nan-time', lambda d: [str(write_csv(d / 'nt.csv', t=nan_at(T)))], 'column t of'),
    ('inf-command', lambda d: [str(write_csv(d / 'i.csv', v=np.where(T > 3, np.inf, V)))],
     'NaN/inf'),
    ('duplicate-timestamps', lambda d: [str(write_csv(d / 'd.csv', t=dup_t(T)))], 'duplicate'),
    ('backwards-timestamps', lambda d: [str(write_csv(d / 'b.csv', t=back_t(T)))], 'backwards'),
    ('huge-values', lambda d: [str(write_csv(d / 'hv.csv', y=Y * 1e20))], 'beyond'),
    ('gap', lambda d: [str(write_csv(d / 'g.csv', t=with_gap(T)))], 'gap'),
    ('constant-command', lambda d: [str(write_csv(d / 'c.csv', v=np.full_like(V, 9.0)))],
     'constant'),
    ('no-reversal', lambda d: [str(write_csv(d / 'ramp.csv', v=np.linspace(7, 11, T.size)))],
     'reverses'),
    ('too-few-samples', lambda d: [str(write_csv(d / 'few.csv', t=T[:5], v=V[:5], y=Y[:5]))],
     'too few'),
    ('zero-stamps-mcap', lambda d: [str(zero_stamp_bag(d))], 'the stamps repeat'),
    ('random-bytes-mcap', lambda d: [str(_bytes(d / 'junk.mcap', np.random.default_rng(0)
                                                .bytes(4096)))], 'bag'),
    ('zero-byte-mcap', lambda d: [str(_bytes(d / 'zero.mcap', b''))], 'bag'),
    ('bag-without-topics', lambda d: [str(no_topics_bag(d))], '/hyst_id/'),
    ('wrong-message-type', lambda d: [str(wrong_type_bag(d))], 'expected sensor_msgs'),
    ('clock-jump-bag', lambda d: [str(clock_jump_bag(d))], 'stamps jump back by 4.95 s'),
    ('empty-topic', lambda d: [str(empty_topic_bag(d))], '/hyst_id/position'),
    ('nan-in-bag', lambda d: [str(make_bag(d / 'nanbag', measurement=nan_at(Y)))], 'NaN'),
    ('constant-command-bag', lambda d: [str(make_bag(d / 'cbag', command=np.full_like(V, 9.)))],
     'constant'),
    ('inverted-domain', lambda d: [str(write_csv(d / 'ok1.csv')), '--domains',
                                   str(_text(d / 'dom.yaml', 'm_l: [5, 1]\n'))], 'low < high'),
    ('infeasible-domains', lambda d: [str(write_csv(d / 'ok2.csv')), '--domains',
                                      str(_text(d / 'dom2.yaml', 'm_l: [0.1, 0.5]\n'
                                                'm_r: [0.1, 0.5]\nm_t: [1, 2]\n'))],
     'feasible'),
    ('domains-file-missing', lambda d: [str(write_csv(d / 'ok3.csv')), '--domains',
                                        str(d / 'nodomains.yaml')], 'cannot read'),
    ('domains-not-yaml', lambda d: [str(write_csv(d / 'ok4.csv')), '--domains',
                                    str(_text(d / 'bad.yaml', 'm_l: [1, \n'))], 'YAML'),
    ('domain-of-three-numbers', lambda d: [str(write_csv(d / 'ok14.csv')), '--domains',
                                           str(_text(d / 'dom3.yaml', 'm_l: [0, 1, 2]\n'))],
     'each entry must be [low, high]; not so: m_l'),
    ('domains-file-empty', lambda d: [str(write_csv(d / 'ok20.csv')), '--domains',
                                      str(_text(d / 'dom5.yaml', ''))], 'names no parameter'),
    ('domain-given-twice', lambda d: [str(write_csv(d / 'ok15.csv')), '--domains',
                                      str(_text(d / 'dom4.yaml', 'm_l: [0, 1]\nm_l: [0, 2]\n'))],
     "the key 'm_l' is given twice"),
    ('column-name-twice', lambda d: [str(write_csv(d / 'twice.csv', header='t,command,command'))],
     "names 2 columns 'command'"),
    ('huge-population', lambda d: [str(write_csv(d / 'ok16.csv')), '--pop-size', '100000000'],
     'pop size <= 10000'),
    ('huge-hops', lambda d: [str(write_csv(d / 'ok19.csv')), '--hops', '2147483647'],
     'hops <= 100000'),
    ('infinite-er-bound', lambda d: [str(write_csv(d / 'ok17.csv')), '--er-bound', 'inf'],
     'the %e_r bound (--er-bound) must be a finite number'),
    ('negative-global-evals', lambda d: [str(write_csv(d / 'ok6.csv')), '--global-evals',
                                         '-1'], 'global evaluations'),
    ('negative-search-samples', lambda d: [str(write_csv(d / 'ok7.csv')), '--search-samples',
                                           '-5'], 'search samples'),
    ('negative-c', lambda d: [str(write_csv(d / 'ok21.csv')), '--c', '-1'],
     'contraction rate c (--c) must be a finite number > 0'),
    ('xi-above-one', lambda d: [str(write_csv(d / 'ok22.csv')), '--xi', '2'], 'xi (--xi)'),
    ('negative-hops', lambda d: [str(write_csv(d / 'ok8.csv')), '--hops', '-1'], 'hops >= 0'),
    ('bad-columns-option', lambda d: [str(write_csv(d / 'ok5.csv')), '--columns', 't,command'],
     'three'),
    ('same-column-twice', lambda d: [str(write_csv(d / 'ok9.csv')), '--columns',
                                     't,command,command'], 'three different columns'),
    ('near-constant-command', lambda d: [str(write_csv(d / 'nc.csv', v=3.0 + 1e-9 * np.sin(
        2 * np.pi * T / 10)))], 'nothing excites'),
    ('negative-er-bound', lambda d: [str(write_csv(d / 'ok10.csv')), '--er-bound', '-3'],
     'must be a finite number > 0'),
    ('unknown-model', lambda d: [str(write_csv(d / 'ok11.csv')), '--model', 'foo'], 'or auto'),
    ('params-unknown-key', lambda d: [str(write_csv(d / 'ok12.csv')), '--params',
                                      str(_text(d / 'p.yaml', 'seeds: 1\ngenerations: 5\n'))],
     'unknown top-level key'),
    ('plot-folder-is-a-file', lambda d: [str(write_csv(d / 'ok13.csv')), '--plot',
                                         str(_touch(d / 'figs'))], 'not a folder'),
    ('json-under-a-file', lambda d: [str(write_csv(d / 'ok14.csv')), '--json',
                                     str(_touch(d / 'f') / 'r.json')], 'not a folder'),
    ('params-out-is-a-folder', lambda d: [str(write_csv(d / 'ok15.csv')), '--params-out',
                                          str(d)], 'a folder'),
    # identify writes three figures: a figure's file name is refused, no folder x.png made
    ('plot-names-a-figure-file', lambda d: [str(write_csv(d / 'ok16.csv')), '--plot',
                                            str(d / 'loops.png')], 'give a folder name'),
]


def _touch(path: Path) -> Path:
    path.touch()
    return path


def _text(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _bytes(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def snapshot(root: Path) -> dict[str, str]:
    """Hash every file below ``root``."""
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob('*')) if p.is_file()}


@pytest.mark.parametrize('case, build, expected', CASES, ids=[c[0] for c in CASES])
def test_bad_input_gives_one_line_and_nonzero_exit(tmp_path, capsys, case, build, expected):
    argv = build(tmp_path)
    before = snapshot(tmp_path)
    code = main(['identify', *argv, '--quiet', '--seeds', '1', '--generations', '5',
                 '--workers', '1'])
    err = capsys.readouterr().err
    assert code != 0, f'{case}: exit code 0'
    assert 'Traceback' not in err
    error_lines = [line for line in err.splitlines() if line.startswith('hyst-id: ')]
    assert len(error_lines) == 1, f'{case}: stderr was {err!r}'
    assert 'internal error' not in error_lines[0], error_lines[0]
    assert expected.lower() in error_lines[0].lower(), error_lines[0]
    assert snapshot(tmp_path) == before, f'{case}: files on disk changed'


def test_a_killed_recorders_bag_is_read_with_a_note(tmp_path, capsys):
    """A bag cut in half (no MCAP footer) is read from its complete chunks, with a note.

    It was refused with a hint at ``recover_truncated=True``, which no command offers
    (found by an independent review): the recorded data were there but out of reach.
    """
    path = truncated_bag(tmp_path)
    assert main(['identify', str(path), '--quiet', '--seeds', '1', '--generations', '5',
                 '--workers', '1', '--hops', '0', '--global-runs', '0']) == 0
    out = capsys.readouterr()
    assert 'has no MCAP footer' in out.err and 'complete chunks' in out.err
    # what reading did is said (identify printed none of the reader's notes before)
    assert 'is truncated (no footer): recovered' in out.err
    said = re.search(r'(\d+) samples over', out.out + out.err)
    assert said and 0 < int(said.group(1)) < T.size, out


def test_case_list_covers_the_issue():
    names = {c[0] for c in CASES}
    for needed in ('random-bytes-mcap', 'bag-without-topics',
                   'wrong-message-type', 'nan-measurement', 'duplicate-timestamps',
                   'backwards-timestamps', 'gap', 'constant-command', 'huge-values',
                   'empty-csv', 'missing-column'):
        assert needed in names


def test_real_process_exit_code_and_stderr(tmp_path):
    """The installed entry point, as a user runs it: exit 2, one line, no traceback."""
    bad = write_csv(tmp_path / 'nan.csv', y=nan_at(Y))
    proc = subprocess.run([sys.executable, '-m', 'hyst_id.cli', 'identify', str(bad)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.strip().count('\n') == 0, proc.stderr
    assert proc.stderr.startswith('hyst-id: error:')


def test_outputs_go_into_folders_made_for_them(tmp_path, capsys):
    """``--plot out/ --json out/result.json`` (the README's quick start) on a fresh folder."""
    csv = write_csv(tmp_path / 'run.csv')
    code = main(['identify', str(csv), '--quiet', '--seeds', '1', '--generations', '5',
                 '--workers', '1', '--hops', '0', '--plot', str(tmp_path / 'out'), '--json',
                 str(tmp_path / 'out' / 'result.json'), '--params-out',
                 str(tmp_path / 'sets' / 'c.yaml')])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / 'out' / 'result.json').is_file()
    assert sorted(p.name for p in (tmp_path / 'out').glob('*.png'))
    assert (tmp_path / 'sets' / 'c.yaml').is_file()


@pytest.mark.parametrize('command', ['identify', 'diagnose'])
def test_an_output_never_overwrites_an_input(tmp_path, capsys, command):
    """``--json run.csv`` on ``run.csv``: refused before any work, the recording intact."""
    csv = write_csv(tmp_path / 'run.csv')
    bag = make_bag(tmp_path / 'bag')
    mcap = next(bag.glob('*.mcap'))
    before = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (csv, mcap)}
    flags = ['--json'] + (['--params-out'] if command == 'identify' else ['--params-out',
                                                                          '--plot'])
    for rec, out in ((csv, csv), (bag, mcap), (bag, bag / 'metadata.yaml')):
        for flag in flags:
            code = main([command, str(rec), '--quiet', '--workers', '1', flag, str(out)])
            err = capsys.readouterr().err
            assert code == 2 and err.count('\n') == 1, (rec, flag, err)
            # a --plot that names no figure is taken as a folder, and a file is none
            assert 'which the output would overwrite' in err or (
                flag == '--plot' and 'is a file, not a folder' in err), err
    (tmp_path / 'figs').mkdir()                       # a figure's name in --plot DIR linked
    (tmp_path / 'figs' / f'{command}_loop.png').hardlink_to(csv)
    (tmp_path / 'figs' / 'other.png').symlink_to(csv)
    code = main([command, str(csv), '--quiet', '--workers', '1', '--plot', str(tmp_path / 'figs')])
    assert code == 2 and 'is the input' in capsys.readouterr().err
    (tmp_path / 'hard.json').hardlink_to(csv)        # another name of the recording's file
    code = main([command, str(csv), '--quiet', '--workers', '1', '--json',
                 str(tmp_path / 'hard.json')])
    assert code == 2 and 'which the output would overwrite' in capsys.readouterr().err
    code = main([command, str(csv), '--quiet', '--json', str(tmp_path / 'a.json'),
                 '--params-out', str(tmp_path / 'a.json')])
    assert code == 2 and 'writes the same file' in capsys.readouterr().err
    assert {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (csv, mcap)} == before
    assert not (tmp_path / 'a.json').exists()


@pytest.mark.parametrize('text, needle', [
    ('/**:\n  ros__parameters:\n    topics:\n      position_fild: position[5]\n',
     "unknown key(s) ['position_fild']"),
    ('/**:\n  ros__parameters:\n    topics.positon_field: position[5]\n',
     "unknown key(s) ['positon_field']"),
    ('topics:\n  position_fild: position[5]\n', "unknown key(s) ['position_fild']"),
    ('/**:\n  ros__parameters:\n    topics.position_field: velocity[0]\n    topics:\n'
     '      position_field: position[0]\n', 'gives position_field twice')])
def test_a_misspelt_topic_key_is_refused_in_every_layout(tmp_path, capsys, text, needle):
    """A typo, or a key in two spellings, is refused.

    The node layout's typo had only been a note (the default field was read); a key in both
    spellings had been read as the dotted one whatever the order.
    """
    csv = write_csv(tmp_path / 'run.csv')
    params = _text(tmp_path / 'p.yaml', text)
    assert main(['identify', str(csv), '--params', str(params), '--quiet']) == 2
    err = capsys.readouterr().err
    assert needle in err, err


def test_a_node_params_file_names_what_the_cli_does_not_use(tmp_path, capsys):
    """A node's params file reads its topics; its other parameters are named, not applied."""
    csv = write_csv(tmp_path / 'run.csv')
    params = _text(tmp_path / 'node.yaml', '/**:\n  ros__parameters:\n    seeds: 1\n'
                   '    generations: 5\n')
    assert main(['identify', str(csv), '--params', str(params), '--quiet', '--seeds', '1',
                 '--generations', '5', '--workers', '1', '--hops', '0']) == 0
    err = capsys.readouterr().err
    assert 'node parameters generations, seeds are not used' in err


def test_damaged_bags_give_a_clear_error_never_an_internal_one(tmp_path):
    """Bytes of a bag flipped, randomised or zeroed at random places: read, or a RecordingError.

    Found by this kind of damage: a corrupt size field makes rosbags raise
    OverflowError or MemoryError, a short record struct.error.
    """
    from hyst_id.errors import HystIdError
    from hyst_id.io.readers import read_recording
    bag = make_bag(tmp_path / 'good')
    src = next(bag.glob('*.mcap')).read_bytes()
    rng = np.random.default_rng(3)
    outcomes = {'read': 0, 'refused': 0}
    for k in range(60):
        data = bytearray(src)
        start, n = int(rng.integers(0, len(data) - 8)), int(rng.choice([1, 8, 50, 400]))
        for i in range(start, min(len(data), start + n)):
            data[i] = (data[i] ^ 0xFF, int(rng.integers(0, 256)), 0)[k % 3]
        path = tmp_path / f'bad{k}.mcap'
        path.write_bytes(bytes(data))
        try:
            read_recording(str(path), 'position')
            outcomes['read'] += 1
        except HystIdError:
            outcomes['refused'] += 1
    assert outcomes['refused'] > 0, outcomes


def test_damage_in_the_middle_of_a_bag_says_how_much_was_read_before_it(tmp_path):
    """The error names how many messages were read before the damaged record."""
    from hyst_id.errors import RecordingError
    from hyst_id.io.bag import iter_bag_messages
    bag = make_bag(tmp_path / 'good')
    data = bytearray(next(bag.glob('*.mcap')).read_bytes())
    start = len(data) // 4                           # inside a chunk a quarter into the file
    data[start:start + 50] = bytes(b ^ 0xFF for b in data[start:start + 50])
    path = tmp_path / 'mid.mcap'
    path.write_bytes(bytes(data))
    n_read = 0
    with pytest.raises(RecordingError) as err:
        for _ in iter_bag_messages(path):
            n_read += 1
    assert n_read > 0
    assert f'after {n_read} good message(s): the file is damaged there' in str(err.value)


def test_diagnose_names_the_training_part_when_only_it_lacks_reversals(tmp_path, capsys):
    """A record that reverses twice, once in its first 70 %: the error says which part."""
    t = np.arange(200) * 0.01
    v = np.sin(2 * np.pi * 0.5 * t)                       # reversals at 0.5 s and 1.5 s
    y = np.clip(v, -0.5, 0.5) + np.random.default_rng(0).normal(0, 0.01, t.size)
    csv = write_csv(tmp_path / 'two.csv', t, v, y)
    assert main(['diagnose', str(csv)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert str(csv) in err and 'its training part (the first 70% of its duration' in err, err
    assert 'command reverses 1 time(s)' in err


def test_whole_record_turns_the_start_state_retry_off_in_identify_and_diagnose(tmp_path):
    from hyst_id.cli import build_parser
    from hyst_id.commands.common import make_settings
    from hyst_id.commands.diagnose import _settings
    parser = build_parser()
    for flags, expected in (([], True), (['--whole-record'], False)):
        args = parser.parse_args(['identify', 'run.csv'] + flags)
        assert make_settings(args).start_state is expected
        args = parser.parse_args(['diagnose', 'run.csv'] + flags)
        assert _settings(args).start_state is expected


def test_experiment_out_that_is_a_file_is_refused_before_the_work(tmp_path, capsys):
    """``experiment --out FILE``: one line, exit 2, before any run (it was an internal error)."""
    taken = _text(tmp_path / 'taken.csv', 't,command,measurement\n')
    assert main(['experiment', '--quick', '--out', str(taken)]) == 2
    err = capsys.readouterr().err
    assert 'is a file, not a folder' in err and 'internal error' not in err
    assert taken.read_text() == 't,command,measurement\n'


@pytest.mark.parametrize('scale, code, needle', [
    (1e-200, 2, 'measurement spans only'),       # an internal error (division by zero) before
    (1e-160, 2, 'below 1e-12: wrong units?'),     # a wrong result, exit 0, before
    (1e-7, 0, 'search domains (auto)'),          # fitted as in its own units
])
def test_a_measurement_in_tiny_units_is_refused_or_fitted(tmp_path, capsys, scale, code, needle):
    """Far below unit scale: refused where the sums of squares underflow, else fitted."""
    csv = write_csv(tmp_path / 'tiny.csv', y=Y * scale)
    got = main(['identify', str(csv), '--quiet', '--seeds', '1',
                '--generations', '5', '--workers', '1', '--hops', '0', '--global-evals', '0'])
    err = capsys.readouterr().err
    assert got == code and needle in err, err
    assert 'internal error' not in err and 'Traceback' not in err


def test_huge_generations_are_refused_before_any_work(tmp_path, capsys):
    """--generations 10^8 ended in a MemoryError (exit 3); refused up front, one line."""
    csv = write_csv(tmp_path / 'run.csv')
    assert main(['identify', str(csv), '--quiet', '--generations', '100000000']) == 2
    err = capsys.readouterr().err
    assert 'generations <= 1000000' in err and 'internal error' not in err


@pytest.mark.parametrize('flag, value', [('--c', '-1'), ('--c', 'nan'), ('--xi', '0')])
def test_bad_gaass_rates_are_refused_before_the_domains_are_printed(tmp_path, capsys, flag, value):
    """``--c -1`` was refused by GAASS itself, after the domains and a bar were printed."""
    csv = write_csv(tmp_path / 'run.csv')
    assert main(['identify', str(csv), flag, value]) == 2
    err = capsys.readouterr().err
    assert flag + ')' in err and 'search domains' not in err and 'GAASS seeds' not in err, err
