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

"""The bringup's answer does not depend on load: a stalled node only makes it slower.

Two short bringup runs, the second with the compensator and the actuator
stalling (a cold numba cache or a busy CPU, several times the wall-clock
sample period): both must print the same %e_r and %eps_c to every digit.
Without the lockstep, a compensator that answers a sample late pairs each
measurement with the wrong desired value (the README's 0.504 % became
2.394 % on a cold cache, issue 11).
"""

from __future__ import annotations

import functools
import re
import time

import pytest

from hyst_id.nodes.bringup import Lockstep

__all__: list[str] = []

PARAMS = """
bringup:
  ros__parameters:
    time_scale: 20.0
    identify_duration_s: 30.0
    identify_sample_period_s: 0.1
    compensate_duration_s: 20.0
    compensate_sample_period_s: 0.5
    bag: {bag}
    settle_s: 0.1
    timeout_s: 300.0
identifier:
  ros__parameters:
    pop_size: 10
    generations: 60
    seeds: 2
    workers: 1
    global_runs: 6
    hops: 0
"""


def _run_bringup(tmp_path, name: str, capfd) -> tuple[int, dict[str, str]]:
    from hyst_id.nodes import bringup
    params = tmp_path / f'{name}.yaml'
    params.write_text(PARAMS.format(bag=tmp_path / f'bag_{name}'))
    code = bringup.main(['--ros-args', '--params-file', str(params)])
    out = capfd.readouterr().out
    figures = dict(re.findall(r'(%e_r|uncompensated|compensated)\s+([0-9.]+) %', out))
    return code, figures


def _stall(cls, method: str, first: int, seconds: float):
    """Wrap ``cls.method`` so that its first ``first`` calls sleep ``seconds``."""
    original = getattr(cls, method)
    calls = {'n': 0}

    @functools.wraps(original)    # rclpy reads the callback's signature (message info)
    def slow(self, *args, **kwargs):
        calls['n'] += 1
        if calls['n'] <= first:
            time.sleep(seconds)
        return original(self, *args, **kwargs)
    return slow


@pytest.mark.ros
@pytest.mark.slow
def test_stalled_nodes_give_the_same_answer(ros_domain, tmp_path, monkeypatch, capfd):
    pytest.importorskip('rclpy')
    from hyst_id.nodes.actuator_driver import ActuatorDriver
    from hyst_id.nodes.compensator import Compensator
    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    code, calm = _run_bringup(tmp_path, 'calm', capfd)
    assert code == 0 and len(calm) == 3, calm
    # 0.5 s of profile time is 25 ms of wall clock here: stall for 4-8 samples' worth
    monkeypatch.setattr(Compensator, '_on_desired', _stall(Compensator, '_on_desired', 5, 0.2))
    monkeypatch.setattr(ActuatorDriver, '_on_command',
                        _stall(ActuatorDriver, '_on_command', 3, 0.1))
    code, stalled = _run_bringup(tmp_path, 'stalled', capfd)
    assert code == 0, stalled
    assert stalled == calm


def test_lockstep_holds_until_answered_then_counts_a_loss(monkeypatch):
    clock = {'t': 100.0}
    monkeypatch.setattr(time, 'monotonic', lambda: clock['t'])
    gate = Lockstep(timeout_s=1.0)
    assert gate.ready(0)               # a run's first sample always goes out
    assert not gate.ready(1)           # ... the next waits for its answer
    gate.answered()
    assert gate.ready(1)
    assert not gate.ready(2)
    clock['t'] += 0.5
    assert not gate.ready(2)
    clock['t'] += 0.6                  # the answer never came: counted lost, run goes on
    assert gate.ready(2) and gate.lost == 1
    gate.answered()                    # ... and the count stays in step after the loss
    assert gate.ready(3) and not gate.ready(4)
    assert gate.ready(0)               # a new run starts from its own count
    assert not gate.ready(1)
