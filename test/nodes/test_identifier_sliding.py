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

"""The identifier node's sliding-window re-identification, in-process.

A set is identified from a stationary run of the reference simulator's
plant; live samples then come from the plant with its gain 20 % lower and
its offset moved. The node must swap the new set in (params file, latched
topic, the decision on ``~/sliding``) and then, on the same window, refuse
a second swap because the newer set is no better.
"""

from __future__ import annotations

import dataclasses
import json

from conftest import make_node, spin_nodes_until
import numpy as np
import pytest
from reference_sim import simulate

rclpy = pytest.importorskip('rclpy')

from rclpy.node import Node  # noqa: E402, I100
from rclpy.parameter import Parameter  # noqa: E402
from std_msgs.msg import String  # noqa: E402

from hyst_id.compensation.params_file import read_compensator_params  # noqa: E402
from hyst_id.nodes.identifier import Identifier  # noqa: E402
from hyst_id.nodes.support import LATCHED_QOS  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]

P = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
     'c_t': 14.0, 'c_b': 7.0, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}
DT_NS = 50_000_000
T0_NS = 1_800_000_000 * 10**9


def _feed(node: Identifier, k0: int, n: int, gain: float, offset: float) -> None:
    t = np.arange(k0 + n) * DT_NS * 1e-9
    v = eq24(t)
    y = gain * simulate('position', P, t, v) + offset
    y = y + np.random.default_rng(k0).normal(0.0, 0.01, y.size)
    for k in range(k0, k0 + n):
        node.buffer.add_command(T0_NS + k * DT_NS, float(v[k]))
        node.buffer.add_measurement(T0_NS + k * DT_NS + 1000, float(y[k]))


def _started(ctx, tmp_path):
    """An identifier with sliding on, a listener, and the first set identified and handed over."""
    out = tmp_path / 'comp.yaml'
    node = make_node(ctx, Identifier, parameter_overrides=[
        Parameter(k, value=v) for k, v in {
            'params_out': str(out), 'end_of_run_timeout_s': 0.0, 'seeds': 2,
            'generations': 100, 'gate_max_uncertainty': 0.0, 'sliding.enabled': True,
            'sliding.window_s': 60.0, 'sliding.holdout_s': 10.0, 'sliding.period_s': 0.5,
            'sliding.cpu_share': 1.0, 'sliding.fresh_seeds': 0}.items()])
    listener = make_node(ctx, Node, 'listener')
    params, decisions = [], []
    listener.create_subscription(String, '/hyst_id/identified_params',
                                 lambda m: params.append(json.loads(m.data)), LATCHED_QOS)
    listener.create_subscription(String, '/identifier/sliding',
                                 lambda m: decisions.append(json.loads(m.data)), LATCHED_QOS)
    spin = [node, listener]
    # (the uncertainty gate is off: eq24 never reaches the top line, so m_t stays loose; the
    # gate's refusals are tested in test/live/test_sliding.py)
    _feed(node, 0, 1200, 1.0, 0.0)                       # 60 s of the plant as identified
    node.set_parameters([Parameter('identify_now', value=True)])
    assert spin_nodes_until(ctx[0], spin, lambda: bool(params), 180.0)
    first = params[-1]
    assert 'sliding' not in first and first['compensator_params'] is not None
    return node, spin, params, decisions


def test_identifier_swaps_in_a_better_set_and_refuses_one_that_is_not(ctx, tmp_path):
    node, spin, params, decisions = _started(ctx, tmp_path)
    out = tmp_path / 'comp.yaml'
    _feed(node, 1200, 1400, 0.8, 0.3)                     # 70 s of the drifted plant
    assert spin_nodes_until(ctx[0], spin, lambda: len(decisions) >= 2, 180.0), decisions
    swap, refusal = decisions[0], decisions[1]
    assert swap['swap'], swap
    assert swap['holdout_er_candidate_percent'] < 0.1 * swap['holdout_er_current_percent']
    assert len(params) == 2 and params[-1]['sliding']['swap']
    assert read_compensator_params(out)['m_l'] == pytest.approx(
        params[-1]['compensator_params']['m_l'])
    assert not refusal['swap'] and refusal['reason'].startswith(
        ('not better', 'not significantly better')), refusal
    assert node.sliding.swaps == 1 and node.sliding.decisions >= 2
    assert node.handed_over is not None and node.handed_over.params == pytest.approx(
        {k: float(v) for k, v in params[-1]['params'].items()})


def test_a_decision_on_a_set_no_longer_in_use_is_discarded(ctx, tmp_path):
    """A set handed over while a window is fitted (a full identification) wins."""
    node, spin, params, decisions = _started(ctx, tmp_path)
    _feed(node, 1200, 1400, 0.8, 0.3)                     # a swap would follow
    assert spin_nodes_until(ctx[0], spin, lambda: node.sliding.job is not None, 60.0)
    node.handed_over = dataclasses.replace(node.handed_over)   # another set handed over
    assert spin_nodes_until(ctx[0], spin, lambda: bool(decisions), 180.0)
    assert not decisions[0]['swap'] and decisions[0]['reason'].startswith('superseded')
    assert len(params) == 1                               # nothing was handed over


def test_sliding_holdout_must_be_shorter_than_the_window(ctx):
    node = make_node(ctx, Identifier)
    res = node.set_parameters_atomically([Parameter('sliding.holdout_s', value=90.0)])
    assert not res.successful and 'sliding.window_s' in res.reason
