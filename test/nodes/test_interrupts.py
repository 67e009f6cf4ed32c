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

"""Ctrl-C right after a node has started gives a clean exit: no traceback, no hang.

A SIGINT that shut the context down while rclpy was making its executor or
its wait set used to end in an ``RCLError`` traceback and exit 1 (seen under
load in CI). Each node is interrupted at delays from its first log line (the
node is built) into its first spins. A Ctrl-C during Python's own imports,
before ``main()`` runs, is Python's KeyboardInterrupt and is not covered.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

__all__: list[str] = []

pytestmark = pytest.mark.ros

DELAYS_S = (0.0, 0.01, 0.03, 0.1, 0.3, 0.6)


@pytest.mark.parametrize('node', ['compensator', 'actuator_driver', 'identifier'])
def test_interrupt_during_start_is_clean(node, ros_domain, tmp_path):
    pytest.importorskip('rclpy')
    env = dict(os.environ, ROS_HOME=str(tmp_path))
    problems = []
    for delay in DELAYS_S:
        proc = subprocess.Popen([sys.executable, '-m', f'hyst_id.nodes.{node}'], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        first = proc.stdout.readline()          # the node's first log line: it is built
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        try:
            out, _ = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, _ = proc.communicate()
            problems.append(f'{delay} s: hung after SIGINT')
            continue
        if proc.returncode not in (0, 130) or 'Traceback' in first + out:
            problems.append(f'{delay} s: exit {proc.returncode}\n{first}{out}')
    assert not problems, '\n'.join(problems)
