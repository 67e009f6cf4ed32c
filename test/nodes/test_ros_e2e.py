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

"""End to end over DDS: every node its own process, one ROS domain, localhost only.

excitation (Eq. 24) -> actuator_driver -> recorder (MCAP) + identifier (live) ->
compensator; then Eq. 25 without and with the compensator (%eps_c of both
printed), then the bag replayed into a fresh identifier must agree with
``hyst-id identify`` on the same file (same settings, same seeds).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import threading
import time

import pytest

rclpy = pytest.importorskip('rclpy')

from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402

from hyst_id.live import SampleBuffer  # noqa: E402
from hyst_id.nodes.bringup import control_error_percent  # noqa: E402
from hyst_id.nodes.support import COMMAND_QOS, LATCHED_QOS, stamp_ns  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]

GAASS = ['-p', 'seeds:=2', '-p', 'generations:=100', '-p', 'domains:=paper', '-p',
         'workers:=1', '-p', 'global_runs:=6', '-p', 'hops:=0']


class Graph:
    """Node processes with their logs, stopped with SIGINT."""

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self.procs: dict[str, subprocess.Popen] = {}

    def start(self, name: str, node: str, *ros_args: str) -> subprocess.Popen:
        log = open(self.tmp / f'{name}.log', 'w')
        proc = subprocess.Popen(
            [sys.executable, '-m', f'hyst_id.nodes.{node}', '--ros-args',
             '-r', f'__node:={name}', *ros_args],
            stdout=log, stderr=subprocess.STDOUT, env=os.environ.copy())
        self.procs[name] = proc
        return proc

    def log(self, name: str) -> str:
        return (self.tmp / f'{name}.log').read_text()

    def wait_log(self, name: str, text: str, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.log(name):
                return
            if self.procs[name].poll() is not None:
                break
            time.sleep(0.1)
        raise AssertionError(f'{name}: no {text!r} within {timeout} s:\n{self.log(name)}')

    def wait_exit(self, name: str, timeout: float) -> int:
        try:
            return self.procs[name].wait(timeout)
        except subprocess.TimeoutExpired:
            raise AssertionError(f'{name} still running:\n{self.log(name)}') from None

    def interrupt(self, name: str, timeout: float = 15.0) -> int:
        self.procs[name].send_signal(signal.SIGINT)
        return self.wait_exit(name, timeout)

    def close(self) -> None:
        for proc in self.procs.values():
            if proc.poll() is None:
                proc.kill()
                proc.wait()


class Observer:
    """In-test node: latched results, and command/desired/position per phase."""

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = Node('observer', context=self.context)
        self.docs: list[dict] = []
        self.phase = ''
        self.buffers = {'uncompensated': SampleBuffer(), 'compensated': SampleBuffer()}
        n = self.node
        n.create_subscription(String, '/hyst_id/identified_params',
                              lambda m: self.docs.append(json.loads(m.data)), LATCHED_QOS)
        deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
        n.create_subscription(JointState, '/hyst_id/position', self._on_position, deep)
        n.create_subscription(Float64, '/hyst_id/command',
                              lambda m, i: self._on_ref('uncompensated', m, i), COMMAND_QOS)
        n.create_subscription(Float64, '/hyst_id/desired',
                              lambda m, i: self._on_ref('compensated', m, i), COMMAND_QOS)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(n)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        while self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.05)
            except Exception:  # noqa: BLE001 - context shut down under us
                return

    def _on_position(self, msg: JointState) -> None:
        if self.phase in self.buffers:
            self.buffers[self.phase].add_measurement(stamp_ns(msg.header.stamp),
                                                     msg.position[0])

    def _on_ref(self, phase: str, msg: Float64, info: dict) -> None:
        if self.phase == phase:
            self.buffers[phase].add_command(info['source_timestamp'], msg.data)

    def wait_doc(self, count: int, timeout: float) -> dict:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and len(self.docs) < count:
            time.sleep(0.1)
        assert len(self.docs) >= count, 'no identified parameters published'
        return self.docs[-1]

    def eps_c(self, phase: str) -> tuple[float, int]:
        rec = self.buffers[phase].recording('position')
        return control_error_percent(rec.measurement, rec.command), rec.n_samples

    def close(self) -> None:
        self.context.try_shutdown()
        self.thread.join(2.0)


def test_live_pipeline_then_replay_agrees_with_cli(ros_domain, tmp_path):
    t_start = time.monotonic()
    bag = tmp_path / 'run_bag'
    graph = Graph(tmp_path)
    obs = Observer()
    try:
        # -- live identification run (Eq. 24, 60 s of profile time at 5x)
        graph.start('actuator_driver', 'actuator_driver')
        graph.start('compensator', 'compensator')
        graph.start('recorder', 'recorder', '-p', f'output:={bag}', '-p',
                    'topics:=[/hyst_id/command, /hyst_id/position]')
        graph.start('identifier', 'identifier', *GAASS, '-p', 'end_of_run_timeout_s:=1.5',
                    '-p', f'params_out:={tmp_path / "live.yaml"}')
        for name in ('actuator_driver', 'compensator', 'recorder', 'identifier'):
            graph.wait_log(name, 'INFO', 30.0)
        graph.wait_log('recorder', 'recording /hyst_id/position', 30.0)
        graph.start('excite_eq24', 'excitation', '-p', 'profile:=eq24', '-p',
                    'duration_s:=60.0', '-p', 'sample_period_s:=0.1', '-p', 'time_scale:=5.0',
                    '-p', 'wait_for_subscribers:=4', '-p', 'start_delay_s:=3.0',
                    '-p', 'shutdown_when_done:=true')
        assert graph.wait_exit('excite_eq24', 60.0) == 0, graph.log('excite_eq24')
        time.sleep(0.5)
        assert graph.interrupt('recorder') == 130, graph.log('recorder')
        assert (bag / 'metadata.yaml').exists(), graph.log('recorder')
        assert 'Traceback' not in graph.log('recorder')

        live = obs.wait_doc(1, 90.0)
        print(f'\nlive identification: %e_r {live["er_percent"]:.3f} from '
              f'{live["n_samples"]} samples')
        # 600 commands are sent. DDS discovery is asynchronous and the excitation can only
        # wait for its own subscribers, so on a loaded CI machine the first samples of the
        # driver -> identifier link can go before it is matched: 591 was seen once in CI,
        # 600-601 locally (also with two CPU hogs). What matters is that the run is
        # identified as one, to well under 1 %; a run split by a stall would be far shorter.
        assert live['n_samples'] >= 570 and live['er_percent'] < 1.0, graph.log('identifier')
        graph.wait_log('compensator', 'applied parameter set', 20.0)
        assert graph.interrupt('identifier') == 130, graph.log('identifier')
        assert (tmp_path / 'live.yaml').exists()

        # -- Eq. 25 without, then with the compensator (60 s at 0.5 s, 10x)
        eq25 = ['-p', 'profile:=eq25', '-p', 'duration_s:=60.0', '-p', 'sample_period_s:=0.5',
                '-p', 'time_scale:=10.0', '-p', 'start_delay_s:=0.5', '-p',
                'shutdown_when_done:=true']
        obs.phase = 'uncompensated'
        graph.start('excite_plain', 'excitation', *eq25, '-p', 'wait_for_subscribers:=2')
        assert graph.wait_exit('excite_plain', 40.0) == 0, graph.log('excite_plain')
        time.sleep(0.3)
        obs.phase = 'compensated'
        graph.start('excite_comp', 'excitation', *eq25, '-p', 'wait_for_subscribers:=2',
                    '-p', 'topics.output_topic:=/hyst_id/desired')
        assert graph.wait_exit('excite_comp', 40.0) == 0, graph.log('excite_comp')
        time.sleep(0.3)
        obs.phase = ''
        plain, n_plain = obs.eps_c('uncompensated')
        comp, n_comp = obs.eps_c('compensated')
        print(f'%eps_c (Eq. 26), Eq. 25: uncompensated {plain:.3f} % ({n_plain} samples), '
              f'compensated {comp:.3f} % ({n_comp} samples)')
        assert n_plain >= 115 and n_comp >= 115
        assert comp < 0.5 * plain
        for name in ('actuator_driver', 'compensator'):
            assert graph.interrupt(name) == 130, graph.log(name)
            assert 'Traceback' not in graph.log(name)

        # -- replay the bag into a fresh identifier; compare with the CLI
        graph.start('identifier_replay', 'identifier', *GAASS, '-p',
                    'end_of_run_timeout_s:=1.5', '-p', 'topics.stamp_source:=log', '-p',
                    'measurement_reliable:=true', '-p', 'recover_on_start:=false', '-p',
                    "compensator_node:=''", '-p', f'params_out:={tmp_path / "replay.yaml"}')
        graph.wait_log('identifier_replay', 'INFO', 30.0)
        graph.start('replay', 'replay', '-p', f'bag:={bag}', '-p', 'rate:=2.0', '-p',
                    'wait_for_subscribers:=4')     # identifier + observer, two topics each
        assert graph.wait_exit('replay', 60.0) == 0, graph.log('replay')
        replayed = obs.wait_doc(2, 90.0)
        cli_json = tmp_path / 'cli.json'
        # The replayed identifier times both streams by the replay's publish times, i.e.
        # the bag's log times; the CLI is told to do the same (by default it times the
        # position by its header stamp, which differs from the log time when the actuator
        # published late, by more than a command period on a loaded machine).
        log_stamps = tmp_path / 'log_stamps.yaml'
        log_stamps.write_text('topics:\n  stamp_source: log\n')
        cli = subprocess.run(
            [sys.executable, '-m', 'hyst_id.cli', 'identify', str(bag), '--channel', 'position',
             '--params', str(log_stamps), '--seeds', '2', '--generations', '100', '--workers',
             '1', '--domains', 'paper', '--global-runs', '6', '--hops', '0', '--quiet',
             '--json', str(cli_json)],
            capture_output=True, text=True, timeout=300)
        assert cli.returncode == 0, cli.stderr
        ref = json.loads(cli_json.read_text())
        print(f'replay identification: %e_r {replayed["er_percent"]:.6f}, '
              f'hyst-id identify: %e_r {ref["er_percent"]:.6f}')
        assert replayed['n_samples'] >= 570   # the bag holds what the recorder received
        for name, value in ref['params'].items():
            assert replayed['params'][name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
        assert replayed['er_percent'] == pytest.approx(ref['er_percent'], rel=1e-9)
        assert graph.interrupt('identifier_replay') == 130
        print(f'end-to-end test: {time.monotonic() - t_start:.1f} s')
    finally:
        obs.close()
        graph.close()


def test_bad_bag_is_one_line_and_nonzero(ros_domain, tmp_path):
    junk = tmp_path / 'junk.mcap'
    junk.write_bytes(b'\x89MCAP0\r\ntruncated')
    out = subprocess.run([sys.executable, '-m', 'hyst_id.nodes.replay', '--ros-args', '-p',
                          f'bag:={junk}'], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    lines = [ln for ln in (out.stdout + out.stderr).splitlines() if ln.strip()]
    assert len(lines) == 1 and 'cannot read bag' in lines[0], lines
