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

"""The fleet runner: many bags, bad ones among them, resume, trends, a Dask cluster.

Recordings are simulated with the independent reference simulator
(``test/reference_sim``), not with the package's own chain: valve A's
backlash widens over four recordings a week apart, valve B's stays; a bag
with a corrupt file, a directory with a broken ``metadata.yaml`` and a CSV
without excitation are in the same fleet.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
from pool_watch import workers_left
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.cli import main as cli_main
from hyst_id.fleet import find_recordings, FleetOptions, loop_trends, run_fleet
from hyst_id.fleet.table import fleet_rows
from hyst_id.io.bag import write_recording_bag
from hyst_id.io.recording import Recording

WEEK_NS = 7 * 86400 * 10**9
FAST = FleetOptions(seeds=1, generations=80)


def _recording(half_band: float, seed: int) -> Recording:
    t = np.arange(1200) * 0.05
    v = 9.0 + 4.0 * np.sin(2 * np.pi * t / 15.0) * (0.5 + 0.5 * np.exp(-t / 40.0))
    u = hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)
    y = backlash(u, 1.0, -half_band, half_band)
    y = y + np.random.default_rng(seed).normal(0.0, 0.01, t.size)
    return Recording(t, v, y, 'position', 'mA', '')


@pytest.fixture(scope='module')
def fleet_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp('fleet')
    for k, band in enumerate((0.10, 0.13, 0.16, 0.19)):          # valve A wears
        write_recording_bag(root / 'valve_a' / f'week{k}', _recording(band, k),
                            start_ns=1_800_000_000 * 10**9 + k * WEEK_NS)
    for k in range(3):                                          # valve B does not
        write_recording_bag(root / 'valve_b' / f'week{k}', _recording(0.15, 10 + k),
                            start_ns=1_800_000_000 * 10**9 + k * WEEK_NS)
    bad = root / 'bad'
    (bad / 'broken_bag').mkdir(parents=True)
    (bad / 'broken_bag' / 'metadata.yaml').write_text('rosbag2_bagfile_information: [\n')
    (bad / 'junk.mcap').write_bytes(b'\x89MCAP0\r\n' + bytes(range(200)))
    t = np.arange(200) * 0.1
    np.savetxt(bad / 'flat.csv', np.c_[t, np.full(t.size, 9.0), np.sin(t)], delimiter=',',
               header='t,command,measurement', comments='')
    return root


def test_find_recordings(fleet_dir):
    found = find_recordings([str(fleet_dir)])
    assert len(found) == 10
    assert {p.name for p in found} >= {'week0', 'broken_bag', 'junk.mcap', 'flat.csv'}
    assert find_recordings([str(fleet_dir / 'valve_*' / 'week0')]) == [
        fleet_dir / 'valve_a' / 'week0', fleet_dir / 'valve_b' / 'week0']

    notes = fleet_dir / 'notes.txt'        # a .txt beside recordings is not one; named, it is
    notes.write_text('t,command,measurement\n')
    assert notes not in find_recordings([str(fleet_dir)])
    assert find_recordings([str(notes)]) == [notes]
    notes.unlink()


def test_a_bag_without_metadata_is_one_bag_of_its_valve(tmp_path):
    """A killed recorder's directory (MCAP named after it, no metadata.yaml) is its bag.

    An independent reviewer's ``fleetin/trunc/trunc.mcap`` had been expanded into its file,
    whose valve became ``trunc``; a folder of runs named otherwise is still searched.
    """
    bag = tmp_path / 'valve_c' / 'week0'
    write_recording_bag(bag, _recording(0.15, 3))
    (bag / 'metadata.yaml').unlink()
    names = [m.name for m in bag.glob('*.mcap')]
    runs = tmp_path / 'valve_d'
    runs.mkdir()
    for k in range(2):
        (runs / f'run{k}.mcap').write_bytes((bag / names[0]).read_bytes())
    found = find_recordings([str(tmp_path)])
    assert found == [bag, runs / 'run0.mcap', runs / 'run1.mcap'], (found, names)
    assert [r['valve'] for r in fleet_rows({'recording': str(p)} for p in found)] == [
        'valve_c', 'valve_d', 'valve_d']


def test_fleet_rows_errors_resume_and_trends(fleet_dir, tmp_path):
    recs = find_recordings([str(fleet_dir)])
    seen = []
    docs = run_fleet(recs, tmp_path, FAST, workers=2,
                     progress=lambda k, n, d: seen.append(d['recording']))
    assert len(seen) == 10
    rows = fleet_rows(docs)
    bad = {r['recording'].split('/')[-1]: r['error'] for r in rows if r['status'] != 'ok'}
    assert set(bad) == {'broken_bag', 'junk.mcap', 'flat.csv'}, bad
    assert all(bad.values()) and 'nothing excites' in bad['flat.csv']
    good = [r for r in rows if r['status'] == 'ok']
    assert all(r['er_over_floor'] < 1.5 for r in good), [r['er_over_floor'] for r in good]
    a = sorted((r for r in good if r['valve'] == 'valve_a'), key=lambda r: r['start_epoch_s'])
    # the whole loop's width in command units grows by the backlash's 0.06 a week (the
    # chain's slopes are near 1), whichever share of it the fits give H and B
    widths = np.array([r['loop_width'] for r in a])
    assert np.allclose(np.diff(widths), 0.06, atol=0.015), widths
    trends = {(t['valve'], t['metric']): t for t in loop_trends(rows)}
    assert trends[('valve_a', 'loop_width')]['flagged']
    assert not trends[('valve_b', 'loop_width')]['flagged']
    assert {m for _, m in trends} == {'loop_width'}
    # resume: the good ones are not run again, the bad ones are retried
    seen.clear()
    again = run_fleet(recs, tmp_path, FAST, workers=2,
                      progress=lambda k, n, d: seen.append(d['recording']))
    assert len(seen) == 3 and sum(bool(d.get('resumed')) for d in again) == 7
    # a recording changed since, or other options: run again (a stale row had been kept)
    good = next(r for r in recs if r.name not in set(bad))
    for f in [good] if good.is_file() else list(good.iterdir()):
        os.utime(f, ns=(f.stat().st_atime_ns, f.stat().st_mtime_ns + 10**9))
    seen.clear()
    run_fleet(recs, tmp_path, FAST, workers=2,
              progress=lambda k, n, d: seen.append(d['recording']))
    assert str(good) in seen and len(seen) == 4, seen
    seen.clear()
    other = dataclasses.replace(FAST, generations=FAST.generations + 1)
    run_fleet(recs, tmp_path, other, workers=2,
              progress=lambda k, n, d: seen.append(d['recording']))
    assert len(seen) == 10


def test_cli_fleet_writes_table_and_trends(fleet_dir, tmp_path, capsys):
    code = cli_main(['fleet', str(fleet_dir / 'valve_a'), str(fleet_dir / 'bad' / 'flat.csv'),
                     '--out', str(tmp_path), '--seeds', '1', '--generations', '80',
                     '--workers', '2', '--no-progress'])
    out = capsys.readouterr().out
    assert code == 1                                   # one recording failed
    assert '4 identified' in out and '1 failed' in out and 'flat.csv' in out
    assert 'trend: valve valve_a: loop_width' in out
    header = (tmp_path / 'fleet.csv').read_text().splitlines()[0].split(',')
    assert {'recording', 'valve', 'status', 'er_percent', 'p.c_br', 'loop_width', 'h_width',
            'backlash_width'} <= set(header)
    trends = json.loads((tmp_path / 'trends.json').read_text())
    assert any(t['flagged'] for t in trends)


def test_cli_fleet_reads_headerless_csv_columns_and_refuses_bad_options(tmp_path, capsys):
    """``--columns``/``--time-scale`` as identify's (the shared cylinder files' layout)."""
    rec = _recording(0.15, 3)
    folder = tmp_path / 'in'
    folder.mkdir()
    np.savetxt(folder / 'run.csv', np.c_[rec.t_s * 1000.0, rec.measurement, rec.command],
               delimiter='\t', fmt='%.9g')
    out = tmp_path / 'out'
    args = ['fleet', str(folder), '--out', str(out), '--seeds', '1', '--generations', '40',
            '--workers', '1', '--no-progress']
    write_recording_bag(folder / 'bag', rec)        # a bag in the same fleet: read by topics
    assert cli_main(args + ['--columns', '0,2,1', '--time-scale', '0.001']) == 0
    docs = [json.loads(f.read_text()) for f in (out / 'recordings').glob('*.json')]
    assert len(docs) == 2 and all(d['status'] == 'ok' for d in docs), docs
    assert all(d['duration_s'] == pytest.approx(rec.duration_s) for d in docs)
    capsys.readouterr()
    for extra, needle in ((['--seeds', '0'], 'seeds >= 1'), (['--workers', '-1'], 'workers'),
                          (['--columns', '0,1,1'], 'three different columns'),
                          (['--time-scale', '0'], '--time-scale must be'),
                          (['--out', str(folder / 'run.csv')], 'a file, not a folder'),
                          (['--out', str(folder / 'run.csv' / 'sub')], 'a file, not a folder')):
        assert cli_main(args + extra) == 2, extra
        err = capsys.readouterr().err
        assert needle in err and 'internal error' not in err, err
    # results written among the inputs are not taken for recordings on the next run
    inside = ['fleet', str(folder), '--out', str(folder / 'results')] + args[4:]
    assert cli_main(inside + ['--columns', '0,2,1', '--time-scale', '0.001']) == 0
    assert (folder / 'results' / 'fleet.csv').is_file()
    capsys.readouterr()
    assert cli_main(inside + ['--columns', '0,2,1', '--time-scale', '0.001']) == 0
    assert 'fleet.csv' in capsys.readouterr().err     # named as skipped, not read
    # the ms column read as seconds: the fleet says so, as identify does
    fresh = ['fleet', str(folder), '--out', str(tmp_path / 'out2')] + args[4:]
    assert cli_main(fresh + ['--columns', '0,2,1']) == 1    # the results' fleet.csv: no time
    said = capsys.readouterr().out
    assert "note: run.csv: the time column '#0' is read as seconds" in said, said
    import shutil
    shutil.rmtree(folder / 'results')
    assert cli_main(fresh + ['--columns', '0,2,1']) == 0
    said = capsys.readouterr().out
    assert "note: run.csv: the time column '#0' is read as seconds" in said, said
    assert cli_main(args + ['--columns', '0,2,1', '--time-scale', '0.001']) == 0
    assert 'time column' not in capsys.readouterr().out


@pytest.mark.slow
def test_fleet_on_a_local_dask_cluster(fleet_dir, tmp_path):
    pytest.importorskip('distributed')
    recs = find_recordings([str(fleet_dir / 'valve_b'), str(fleet_dir / 'bad')])
    docs = run_fleet(recs, tmp_path, FAST, workers=2, address='local')
    status = {d['recording'].split('/')[-1]: d['status'] for d in docs}
    assert status == {'week0': 'ok', 'week1': 'ok', 'week2': 'ok', 'broken_bag': 'error',
                      'junk.mcap': 'error', 'flat.csv': 'error'}


_INTERRUPTED_FLEET = r"""
import os, signal, sys, time
from pathlib import Path
signal.signal(signal.SIGINT, signal.default_int_handler)   # Ctrl-C as in a terminal
from hyst_id.fleet import FleetOptions, run as fleet_run


def task(path, options):
    if path.endswith('fast'):
        return {'recording': path, 'status': 'ok'}
    # one write(2) of a short line to a pipe is atomic: print's separate writes from the two
    # workers once interleaved into 'slowslow 12494' on a CI machine
    os.write(1, f'slow {os.getpid()}\n'.encode())
    time.sleep(60.0)


fleet_run.fleet_task = task
out = Path(sys.argv[1])
fleet_run.run_fleet([out / 'fast', out / 'slow1', out / 'slow2'], out, FleetOptions(),
                    workers=2)
"""


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='fork, /proc')
def test_an_interrupted_local_fleet_keeps_what_arrived_and_ends_its_workers(tmp_path):
    """Ctrl-C: the parent ends its workers at once (they ignore it) and keeps finished rows."""
    proc = subprocess.Popen([sys.executable, '-c', _INTERRUPTED_FLEET, str(tmp_path)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        # the two workers' 'slow PID' lines; anything else the process says is kept for
        # the message (a CI run under load once read a line without a PID here)
        said, workers = [], []
        while len(workers) < 2:
            line = proc.stdout.readline()
            if not line:
                break
            said.append(line)
            words = line.split()
            if len(words) == 2 and words[0] == 'slow' and words[1].isdigit():
                workers.append(int(words[1]))
        assert len(workers) == 2, said
        deadline = time.monotonic() + 20.0      # the fast row written (its result read)
        while not list((tmp_path / 'recordings').glob('*.json')) and \
                time.monotonic() < deadline:
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        t0 = time.monotonic()
        proc.wait(timeout=20)
        took_s = time.monotonic() - t0
        out = proc.stdout.read()
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0 and 'KeyboardInterrupt' in out, out[-2000:]
    assert took_s < 10.0, f'{took_s:.1f} s from the Ctrl-C to the exit (tasks sleep 60 s)'
    left = workers_left(workers)
    assert not left, f'worker(s) {left} outlived the interrupted fleet'
    kept = [json.loads(f.read_text()) for f in (tmp_path / 'recordings').glob('*.json')]
    assert [d['recording'] for d in kept] == [str(tmp_path / 'fast')]
