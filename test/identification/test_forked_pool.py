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

"""Ctrl-C in a forked pool (basin hopping's and the incumbent's polishes).

A Ctrl-C while the pool is open is noted and raised at the next wait
(``ForkedPool.result``, or the pool's own wait for the tasks still running
when the block ends), never inside the executor's own calls, and the
workers end with the parent. Each case runs in a fresh process (a pool only
forks with one thread running, and the signal must reach a main thread with
Python's default handler).
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time

from pool_watch import workers_left
import pytest

_SCRIPT = r"""
import os, signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)
from hyst_id.identification.workers import forked_pool


def slow(seconds):
    time.sleep(seconds)
    return seconds


when = sys.argv[1]
try:
    with forked_pool(2) as pool:
        print('pool', pool is not None, flush=True)
        if when == 'early':
            os.kill(os.getpid(), signal.SIGINT)     # before the submits: noted only
        futures = [pool.submit(slow, 30.0) for _ in range(4)]
        print('workers', *pool._processes, flush=True)
        if when != 'closing':       # closing: the block ends with the tasks running
            pool.result(futures[0])
except KeyboardInterrupt:
    print('interrupted', flush=True)
    raise
print('not interrupted', flush=True)
"""


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='fork, /proc')
@pytest.mark.parametrize('when', ['early', 'waiting', 'closing'])
def test_ctrl_c_in_a_forked_pool_is_raised_at_the_wait_and_ends_the_workers(when):
    proc = subprocess.Popen([sys.executable, '-c', _SCRIPT, when], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    try:
        assert proc.stdout.readline().split() == ['pool', 'True']
        workers = [int(p) for p in proc.stdout.readline().split()[1:]]
        assert workers, 'no worker process started'
        t0 = time.monotonic()
        if when != 'early':
            time.sleep(0.5)
            proc.send_signal(signal.SIGINT)
        proc.wait(timeout=20)
        took_s = time.monotonic() - t0
        out = proc.stdout.read()       # after the lines read above (stderr goes here too)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert 'interrupted' in out.split('\n'), out[-2000:]
    assert 'not interrupted' not in out
    assert proc.returncode != 0 and 'KeyboardInterrupt' in out
    assert took_s < 10.0, f'{took_s:.1f} s from the Ctrl-C to the exit (tasks sleep 30 s)'
    left = workers_left(workers)
    assert not left, f'worker(s) {left} outlived the interrupted pool'
