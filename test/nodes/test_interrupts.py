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

"""Stops are clean: Ctrl-C gives exit 130, SIGTERM exit 0, no traceback, no hang, no orphan.

A SIGINT that shut the context down while rclpy was making its executor or
its wait set used to end in an ``RCLError`` traceback and exit 1 (seen under
load in CI), and a node without timers could miss it. Each executable is
interrupted at delays from its first log line (the node is built) into its
first spins. A Ctrl-C during Python's own imports, before ``main()`` runs,
is Python's KeyboardInterrupt and is not covered. Worker processes of an
identification end with a cancel and die with their parent. The thorough-tier
test repeats the stops 20 times per executable and counts hangs and orphans
(``bench/stop_stress.py`` prints the same counts and stop times).
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import pytest

__all__: list[str] = []

pytestmark = pytest.mark.ros

DELAYS_S = (0.0, 0.03, 0.3)
#: What each signal must give.
EXPECTED_EXIT = {signal.SIGINT: 130, signal.SIGTERM: 0}
NODES = ['compensator', 'lifecycle_compensator', 'actuator_driver', 'identifier',
         'pipeline_sim', 'excitation', 'recorder', 'replay', 'bringup']


def node_command(node: str, tmp_path) -> list[str]:
    """How to start ``node`` so that it runs until stopped."""
    cmd = [sys.executable, '-m', f'hyst_id.nodes.{node}', '--ros-args']
    if node == 'recorder':
        cmd += ['-p', f'output:={tmp_path / f"bag{time.monotonic_ns()}"}']
    if node == 'replay':
        from hyst_id.io.bag import write_recording_bag
        from hyst_id.io.recording import Recording
        import numpy as np
        bag = tmp_path / 'long_bag'
        if not bag.exists():
            t = np.arange(600) * 0.1
            v = 9.0 + 3.0 * np.sin(t)
            write_recording_bag(bag, Recording(t, v, 0.5 * v, 'position', 'mA', ''))
        cmd += ['-p', f'bag:={bag}']
    if node == 'bringup':
        cmd += ['-p', f'bag:={tmp_path / f"bringup{time.monotonic_ns()}"}']
    return cmd


def stop_once(cmd: list[str], env: dict, sig: int, delay_s: float) -> tuple[str, float]:
    """Start, wait for the first log line and ``delay_s``, signal; return (problem, stop s)."""
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    first = proc.stdout.readline()          # the node's first log line: it is built
    time.sleep(delay_s)
    t0 = time.monotonic()
    proc.send_signal(sig)
    try:
        out, _ = proc.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
        return f'hung after {signal.Signals(sig).name}', math.inf
    elapsed = time.monotonic() - t0
    if proc.returncode != EXPECTED_EXIT[sig] or 'Traceback' in first + out:
        return (f'{signal.Signals(sig).name}: exit {proc.returncode} (expected '
                f'{EXPECTED_EXIT[sig]})\n{first}{out}'), elapsed
    return '', elapsed


@pytest.mark.parametrize('node', NODES)
def test_stops_are_clean(node, ros_domain, tmp_path):
    pytest.importorskip('rclpy')
    env = dict(os.environ, ROS_HOME=str(tmp_path))
    problems = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        for delay in DELAYS_S:
            problem, _ = stop_once(node_command(node, tmp_path), env, sig, delay)
            if problem:
                problems.append(f'{delay} s: {problem}')
    assert not problems, '\n'.join(problems)


@pytest.mark.slow
@pytest.mark.thorough
@pytest.mark.parametrize('node', NODES)
def test_twenty_stops_no_hang_no_orphan(node, ros_domain, tmp_path):
    """Issue 15's count: 20 starts and stops per executable, Ctrl-C and SIGTERM in turn.

    Every stop exits as expected with no traceback within 20 s, and no process the
    runs started (tagged through their environment) is left behind.
    """
    pytest.importorskip('rclpy')
    tag = f'{tmp_path.name}-{node}'
    env = dict(os.environ, ROS_HOME=str(tmp_path), HYST_ID_STOP_TAG=tag)
    problems = []
    for k in range(20):
        sig = (signal.SIGINT, signal.SIGTERM)[k % 2]
        delay = DELAYS_S[k % len(DELAYS_S)]
        problem, _ = stop_once(node_command(node, tmp_path), env, sig, delay)
        if problem:
            problems.append(f'run {k} ({delay} s): {problem}')
    deadline = time.monotonic() + 10.0
    while _tagged(f'HYST_ID_STOP_TAG={tag}') and time.monotonic() < deadline:
        time.sleep(0.1)
    left = _tagged(f'HYST_ID_STOP_TAG={tag}')
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not problems and not left, '\n'.join(problems) + f'\norphans: {left}'


_WORKER_SCRIPT = r"""
import faulthandler, signal, sys, numpy as np
faulthandler.register(signal.SIGUSR1, all_threads=True)
# Ctrl-C as in a terminal: a shell without job control starts background jobs (a CI
# runner's) with SIGINT ignored, and a child would inherit that
signal.signal(signal.SIGINT, signal.default_int_handler)
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording
t = np.arange(4000) * 0.05
v = 9.0 + 4.0 * np.sin(2 * np.pi * t / 20.0) * np.sin(2 * np.pi * t / 170.0)
x = np.array([1.01, 1.05, 0.1, 0.15, -0.25, 0.5, 14.0, 7.0, 1.0, -0.25, 0.25])
y = chain_spec('position').simulate(x, t, v) + np.random.default_rng(0).normal(0, 0.01, t.size)
print('start', flush=True)
identify(Recording(t, v, y, 'position', 'mA', ''),
         settings=IdentifySettings(seeds=tuple(range(8)), workers=2, maxiter=100000))
"""


def _tagged(tag: str) -> list[int]:
    """Pids of live processes whose environment carries ``tag``."""
    out = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open(f'/proc/{entry}/environ', 'rb') as f:
                env = f.read()
            with open(f'/proc/{entry}/stat') as f:
                state = f.read().rsplit(')', 1)[1].split()[0]
        except OSError:
            continue
        if tag.encode() in env and state != 'Z':
            out.append(int(entry))
    return out


def _children_running(tag: str, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if len(_tagged(tag)) >= 3:           # the script and its two workers
            return True
        time.sleep(0.1)
    return False


def orphans_after(sig: int, tag_value: str) -> int:
    """Stop an identification with two workers by ``sig``; workers left after 10 s.

    -1 when the workers never started. Leftovers are killed before returning.
    """
    key = 'HYST_ID_ORPHAN_TAG'
    tag = f'{key}={tag_value}'
    proc = subprocess.Popen([sys.executable, '-c', _WORKER_SCRIPT],
                            env={**os.environ, key: tag_value}, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    try:
        if proc.stdout.readline().strip() != b'start' or not _children_running(tag, 60.0):
            return -1
        proc.send_signal(sig)
        try:
            proc.wait(20)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGUSR1)        # every thread's stack, for the report
            time.sleep(1.0)
            proc.kill()
            stacks = proc.stdout.read().decode(errors='replace')[-4000:]
            raise AssertionError(f'no exit 20 s after {sig!r}; threads:\n{stacks}') from None
        deadline = time.monotonic() + 10.0
        while _tagged(tag) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = _tagged(tag)
        for pid in left:
            os.kill(pid, signal.SIGKILL)
        return len(left)
    finally:
        if proc.poll() is None:
            proc.kill()


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='/proc and PR_SET_PDEATHSIG')
@pytest.mark.parametrize('sig', [signal.SIGKILL, signal.SIGINT])
def test_worker_processes_do_not_outlive_their_parent(sig, tmp_path):
    left = orphans_after(sig, f'{tmp_path.name}{sig}')
    assert left != -1, 'the worker processes never started'
    assert left == 0, f'{left} worker process(es) outlived their parent'


def test_a_cancel_ends_worker_processes_at_once():
    import numpy as np

    from hyst_id.identification import IdentifySettings
    from hyst_id.identification.chains import chain_spec
    from hyst_id.io.recording import Recording
    from hyst_id.live import IdentificationJob
    t = np.arange(4000) * 0.05
    v = 9.0 + 4.0 * np.sin(2 * np.pi * t / 20.0) * np.sin(2 * np.pi * t / 170.0)
    spec = chain_spec('position')
    y = spec.simulate(np.array([1.01, 1.05, 0.1, 0.15, -0.25, 0.5, 14.0, 7.0, 1.0, -0.25,
                                0.25]), t, v)
    job = IdentificationJob(Recording(t, v, y, 'position', 'mA', ''), None,
                            IdentifySettings(seeds=tuple(range(8)), workers=2, maxiter=100000))
    time.sleep(3.0)                                  # the workers are in their first seeds
    assert not job.done
    t0 = time.monotonic()
    job.cancel()
    assert job.wait(5.0), 'the job did not end within 5 s of the cancel'
    assert time.monotonic() - t0 < 2.0 and job.cancelled and job.error is None
