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

"""The typed messages of interfaces/hyst_id_interfaces in the ROS-free core (issue 15).

The core holds the message definitions for rosbags (``hyst_id.io.interface_types``);
they must stay those of the package colcon builds. A bag whose commands are
``StampedValue`` is timed by the stamps, not by when the messages were logged.
"""

from __future__ import annotations

from pathlib import Path
import re

import numpy as np

from hyst_id.io.bag import BagWriter, default_typestore
from hyst_id.io.interface_types import INTERFACE_MSGS, STAMPED_VALUE_TYPE
from hyst_id.io.readers import read_recording
from hyst_id.io.topics import load_topic_config

__all__: list[str] = []

MSG_DIR = Path(__file__).resolve().parents[2] / 'interfaces' / 'hyst_id_interfaces' / 'msg'
T0 = 1_767_225_600 * 10**9


def _definition(text: str) -> str:
    lines = (re.sub(r'\s+', ' ', line.split('#', 1)[0]).strip() for line in text.splitlines())
    return '\n'.join(line for line in lines if line) + '\n'


def test_core_definitions_are_the_interface_package_files():
    files = {f'hyst_id_interfaces/msg/{p.stem}': _definition(p.read_text())
             for p in sorted(MSG_DIR.glob('*.msg'))}
    assert files == {k: _definition(v) for k, v in INTERFACE_MSGS.items()}
    cmake = (MSG_DIR.parent / 'CMakeLists.txt').read_text()
    assert all(f'"msg/{name.rsplit("/", 1)[1]}.msg"' in cmake for name in files)


def test_stamped_value_serialises_with_rosbags():
    store = default_typestore()
    cls = store.types[STAMPED_VALUE_TYPE]
    header = store.types['std_msgs/msg/Header'](
        stamp=store.types['builtin_interfaces/msg/Time'](sec=12, nanosec=34), frame_id='')
    raw = store.serialize_cdr(cls(header=header, value=-2.5), STAMPED_VALUE_TYPE)
    back = store.deserialize_cdr(raw, STAMPED_VALUE_TYPE)
    assert (back.header.stamp.sec, back.header.stamp.nanosec, back.value) == (12, 34, -2.5)


def test_stamped_commands_are_timed_by_their_stamps_not_the_log(tmp_path):
    # a bag recorded from a replay at rate 4: every message logged 4 x sooner than its
    # stamp; commands and flow stamped, so the recording keeps the 0.1 s sample period
    n, dt_ns = 200, 100_000_000
    t = np.arange(n) * dt_ns
    command = 9.0 + 2.0 * np.sin(2 * np.pi * t * 1e-9 / 5.0)
    flow = 0.3 * command
    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', STAMPED_VALUE_TYPE)
        bag.add_topic('/hyst_id/flow', STAMPED_VALUE_TYPE)
        for k in range(n):
            log_ns = T0 + t[k] // 4
            bag.write('/hyst_id/command', log_ns,
                      {'header': {'stamp': T0 + t[k]}, 'value': command[k]})
            bag.write('/hyst_id/flow', log_ns + 1000,
                      {'header': {'stamp': T0 + t[k] + 1000}, 'value': flow[k]})
    topics = {'command_type': STAMPED_VALUE_TYPE, 'command_field': 'value',
              'flow_type': STAMPED_VALUE_TYPE, 'flow_field': 'value'}
    got = read_recording(tmp_path / 'bag', 'flow', topics=topics)
    assert got.n_samples == n
    np.testing.assert_allclose(np.diff(got.t_s), 0.1, atol=1e-6)
    np.testing.assert_allclose(got.measurement, flow, rtol=1e-12)
    np.testing.assert_allclose(got.command, command, rtol=1e-12)
    # hyst-id identify --topics params/stamped.yaml: the nodes' stream keys are ignored,
    # and a StampedValue is read at its value field without naming it
    cfg = load_topic_config(MSG_DIR.parents[2] / 'params' / 'stamped.yaml', 'flow')
    assert (cfg.command_field, cfg.measurement_field) == ('value', 'value')
    again = read_recording(tmp_path / 'bag', 'flow', topics=cfg)
    np.testing.assert_array_equal(again.t_s, got.t_s)
    lean = read_recording(tmp_path / 'bag', 'flow', topics={
        'command_type': STAMPED_VALUE_TYPE, 'flow_type': STAMPED_VALUE_TYPE})
    np.testing.assert_array_equal(lean.measurement, got.measurement)


def test_an_empty_bag_starts_at_zero_and_names_its_distro(tmp_path):
    import yaml

    with BagWriter(tmp_path / 'bag') as bag:
        bag.add_topic('/hyst_id/command', STAMPED_VALUE_TYPE)
    meta = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())
    info = meta['rosbag2_bagfile_information']
    assert info['starting_time']['nanoseconds_since_epoch'] == 0      # not INT64_MAX (2262)
    assert info['ros_distro'] not in ('', 'rosbags') and info['message_count'] == 0
