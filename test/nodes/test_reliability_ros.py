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

"""Issue 6 over DDS: a killed recorder, a stopped recorder, a compensator under load.

Every node is its own process (own ROS domain, localhost discovery); the
test publishes and listens in-process.

* Recorder + SIGKILL: the bag is readable with ``recover_truncated=True``
  and holds every message sent up to the loss window before the kill
  (the pending chunk: ``min(chunk_span_s, chunk_size / byte rate)``, plus a
  margin for delivery), without holes.
* Recorder + SIGINT / SIGTERM: exit 130 / 0, ``metadata.yaml`` written, the bag
  reads without recovery and holds every message sent.
* Compensator at 1 kHz for 5 s with valid and invalid parameter updates
  (``bench/compensator_load.py``, whose full run is 60 s): nothing lost, no
  command outside the limits, valid updates applied and invalid ones
  rejected with a reason, every command reproduced by a shadow compensator
  switched at the boundaries the node announced (atomic updates).
"""

from __future__ import annotations

import importlib.util
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
from std_msgs.msg import Float64  # noqa: E402

from hyst_id.errors import RecordingError  # noqa: E402
from hyst_id.io.bag import iter_bag_messages  # noqa: E402
from hyst_id.nodes.support import COMMAND_QOS  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[2]
RATE_HZ = 200.0
CHUNK_SIZE = 65536
CHUNK_SPAN_S = 1.0
FLUSH_PERIOD_S = 1.0
#: Bytes an MCAP message record of a std_msgs/Float64 takes (31 record + 12 CDR).
RECORD_BYTES = 43
#: Delivery and scheduling slack added to the loss window in the check.
MARGIN_S = 0.5


def loss_window_s(rate_hz: float = RATE_HZ) -> float:
    """Log time a SIGKILL can lose: the pending chunk, closed by span or by size."""
    return min(CHUNK_SPAN_S, CHUNK_SIZE / (rate_hz * RECORD_BYTES))


class Talker:
    """In-process publisher of counters 0, 1, 2... on /hyst_id/command."""

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = Node('talker', context=self.context)
        self.pub = self.node.create_publisher(Float64, '/hyst_id/command', COMMAND_QOS)
        self.sent: list[float] = []          # monotonic send time of message k
        self.stop = threading.Event()
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def wait_subscriber(self, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while self.pub.get_subscription_count() < 1:
            assert time.monotonic() < deadline, 'the recorder never subscribed'
            self.executor.spin_once(timeout_sec=0.05)

    def run(self, seconds: float) -> None:
        start = time.monotonic()
        k0 = len(self.sent)
        for k in range(k0, k0 + int(seconds * RATE_HZ)):
            wait = start + (k - k0) / RATE_HZ - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            self.sent.append(time.monotonic())
            self.pub.publish(Float64(data=float(k)))

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


def start_recorder(tmp: Path, bag: Path) -> tuple[subprocess.Popen, Path]:
    log = tmp / 'recorder.log'
    proc = subprocess.Popen(
        [sys.executable, '-m', 'hyst_id.nodes.recorder', '--ros-args', '-p', f'output:={bag}',
         '-p', 'topics:=[/hyst_id/command]', '-p', f'chunk_size:={CHUNK_SIZE}',
         '-p', f'chunk_span_s:={CHUNK_SPAN_S}', '-p', f'flush_period_s:={FLUSH_PERIOD_S}'],
        stdout=open(log, 'w'), stderr=subprocess.STDOUT, env=os.environ.copy())
    return proc, log


def read_counters(bag: Path, **kwargs) -> list[int]:
    return [int(m.data) for _, _, _, m in iter_bag_messages(bag, **kwargs)]


@pytest.fixture
def talker(ros_domain):
    t = Talker()
    yield t
    t.close()


def test_sigkilled_recorder_loses_at_most_the_window(talker, tmp_path):
    bag = tmp_path / 'killed'
    proc, log = start_recorder(tmp_path, bag)
    try:
        talker.wait_subscriber()
        talker.run(3.0)
        t_kill = time.monotonic()
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL
    assert not (bag / 'metadata.yaml').exists()
    with pytest.raises(RecordingError, match='recover_truncated'):
        read_counters(bag)
    got = read_counters(bag, recover_truncated=True)
    window = loss_window_s()
    must_have = sum(1 for t in talker.sent if t <= t_kill - window - MARGIN_S)
    print(f'\nSIGKILL after {len(talker.sent)} messages at {RATE_HZ:g} Hz: recovered '
          f'{len(got)}, lost {len(talker.sent) - len(got)} (window {window:g} s = '
          f'{window * RATE_HZ:.0f} messages; must keep the first {must_have})')
    assert got == list(range(len(got))), 'holes in the recovered messages'
    assert len(got) >= must_have, log.read_text()


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_interrupted_recorder_writes_a_complete_bag(talker, tmp_path, sig):
    bag = tmp_path / 'stopped'
    proc, log = start_recorder(tmp_path, bag)
    try:
        talker.wait_subscriber()
        talker.run(1.0)
        time.sleep(0.5)                       # let the last messages arrive
        proc.send_signal(sig)
        assert proc.wait(15) == (130 if sig == signal.SIGINT else 0), log.read_text()
    finally:
        if proc.poll() is None:
            proc.kill()
    assert (bag / 'metadata.yaml').exists(), log.read_text()
    assert read_counters(bag) == list(range(len(talker.sent)))
    assert 'Traceback' not in log.read_text()


def _load_bench():
    spec = importlib.util.spec_from_file_location('compensator_load',
                                                  ROOT / 'bench' / 'compensator_load.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_compensator_at_1khz_with_updates_loses_nothing(ros_domain, tmp_path):
    bench = _load_bench()
    r = bench.run_load(rate_hz=1000.0, seconds=5.0, update_every_s=0.5,
                       log_path=str(tmp_path / 'compensator.log'))
    print('\n' + bench.report(r))
    log = (tmp_path / 'compensator.log').read_text()
    assert r['sent'] == 5000 and r['received'] == 5000 and r['lost'] == 0, log
    assert r['out_of_limits'] == 0
    assert r['unanswered'] == 0 and not r['wrong_outcome'], r
    assert r['applied'] == r['valid_sent'] >= 4
    assert r['rejected'] == r['updates_sent'] - r['valid_sent'] >= 4
    assert len(r['reasons']) == 4 and all(': ' in why for why in r['reasons'])
    assert r['generations'] == list(range(r['applied'] + 1))
    assert r['shadow_mismatches'] == 0
    assert r['compensator_exit'] == 130 and 'Traceback' not in log
