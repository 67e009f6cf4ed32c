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

"""The compensator node's ``augment.*`` parameters: a diagnosis's corrections in-line."""

from __future__ import annotations

import json
import math

from conftest import make_node
import pytest

rclpy = pytest.importorskip('rclpy')

from rclpy.parameter import Parameter  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402

from hyst_id.compensation.augment import Augmentation  # noqa: E402
from hyst_id.compensation.params_file import (read_compensator_params,  # noqa: E402
                                              write_compensator_params)
from hyst_id.nodes.actuator_driver import PAPER_HYSTERESIS  # noqa: E402
from hyst_id.nodes.compensator import Compensator  # noqa: E402

pytestmark = pytest.mark.ros

PAPER = {**PAPER_HYSTERESIS, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}


def _node(ctx, **values):
    return make_node(ctx, Compensator, parameter_overrides=[
        Parameter(k, value=v) for k, v in {**PAPER, **values}.items()])


def test_corrections_from_a_params_file_reach_the_model(ctx, tmp_path):
    aug = Augmentation(dead_time_s=0.3, gain_law='linear', gain_rate_per_s=-0.001,
                       gain_centre=2.0, max_command=15.0)
    path = write_compensator_params({'channel': 'position', **PAPER, 'augment': aug},
                                    tmp_path / 'c.yaml')
    values = {k: v for k, v in read_compensator_params(path).items()
              if k.startswith('augment.')}
    # a ROS params file gives a stop at .nan, which the node reads as no stop
    values = {k: (math.nan if isinstance(v, float) and math.isinf(v) else v)
              for k, v in values.items()}
    comp = _node(ctx, **values)
    assert comp._comp.augmentation == aug
    assert comp._comp.limits.max_command == 15.0
    comp._on_desired(Float64(data=9.0))
    assert 4.0 <= comp._comp.state[0] <= 15.0


def test_bad_corrections_are_refused_and_the_last_good_ones_kept(ctx):
    comp = _node(ctx, **{'augment.dead_time_s': 0.2})
    for params, reason in (
            ([Parameter('augment.gain_law', value='cubic')], 'gain_law'),
            ([Parameter('augment.min_command', value=25.0)], 'leave no command'),
            ([Parameter('augment.dead_time_s', value=-1.0)], 'dead_time_s')):
        result = comp.set_parameters_atomically(params)
        assert not result.successful and reason in result.reason, result.reason
    assert comp._comp.augmentation == Augmentation(dead_time_s=0.2)


def test_a_change_of_corrections_is_applied_and_published(ctx):
    comp = _node(ctx)
    sets = []
    comp._set_pub.publish = lambda msg: sets.append(json.loads(msg.data))
    result = comp.set_parameters_atomically([
        Parameter('augment.offset_rate_per_s', value=0.01),
        Parameter('augment.schedule_horizon_s', value=100.0)])
    assert result.successful
    assert comp._comp.augmentation == Augmentation(offset_rate_per_s=0.01,
                                                   schedule_horizon_s=100.0)
    assert sets and sets[-1]['augment']['augment.offset_rate_per_s'] == 0.01
    assert sets[-1]['augment']['augment.min_command'] is None


def test_limits_that_the_stops_leave_empty_are_refused_not_raised(ctx):
    comp = _node(ctx, **{'augment.min_command': 6.0})
    result = comp.set_parameters_atomically([Parameter('max_command', value=5.0)])
    assert not result.successful and 'leave no command' in result.reason
    result = comp.set_parameters_atomically([Parameter('min_command', value=30.0),
                                             Parameter('max_command', value=40.0),
                                             Parameter('augment.min_command', value=32.0),
                                             Parameter('augment.max_command', value=38.0)])
    assert result.successful, result.reason
    assert (comp._comp.limits.min_command, comp._comp.limits.max_command) == (32.0, 38.0)


def test_tracking_runs_on_top_of_the_corrections_and_restarts_with_them(ctx):
    comp = _node(ctx, **{'augment.offset_rate_per_s': 0.01})
    result = comp.set_parameters_atomically([Parameter('tracking.enabled', value=True)])
    assert result.successful, result.reason
    adaptive = comp._tracking.adaptive
    assert adaptive.compensator is comp._comp          # the prediction is the augmented one
    y = comp._comp.augmentation.reading(9.0, 100.0)
    assert y == pytest.approx(9.0 + 0.01 * 100.0)
    adaptive.tracker.gain = 0.9                        # an estimate on the old corrections
    result = comp.set_parameters_atomically([Parameter('augment.offset_rate_per_s',
                                                       value=0.02)])
    assert result.successful, result.reason
    restarted = comp._tracking.adaptive
    assert restarted is not adaptive and restarted.tracker.gain == 1.0
    result = comp.set_parameters_atomically([Parameter('max_command', value=19.0)])
    assert result.successful and comp._tracking.adaptive is restarted   # same corrections


def test_a_set_without_its_output_map_is_refused_while_one_is_in_force(ctx):
    comp = _node(ctx, **{'augment.poly_c2': 0.1})
    result = comp.set_parameters_atomically([Parameter('c_t', value=14.5)])
    assert not result.successful and 'augment.poly_' in result.reason
    result = comp.set_parameters_atomically([Parameter('c_t', value=14.5),
                                             Parameter('augment.poly_c2', value=0.0)])
    assert result.successful, result.reason
    assert not comp._comp.augmentation.has_output_map


def test_a_non_finite_desired_value_holds_the_command_and_reports_an_error(ctx, monkeypatch):
    """A NaN in: the last command is held, and the next /diagnostics status is an ERROR."""
    comp = _node(ctx)
    sent: list[tuple[int, str, dict]] = []
    monkeypatch.setattr(comp, 'publish_diagnostics',
                        lambda level, msg, values=None, **kw: sent.append((level, msg, values)))
    comp._on_desired(Float64(data=9.0))
    held = comp._comp.state[0]
    comp._on_desired(Float64(data=math.nan))
    assert comp._comp.state[0] == held and comp.non_finite_seen == 1
    comp._publish_status()
    assert sent[-1][0] == 2 and '1 non-finite input value(s)' in sent[-1][1], sent[-1]
    assert sent[-1][2]['non_finite_inputs'] == 1
    comp._publish_status()                          # none since: back to the usual status
    assert sent[-1][0] != 2 or 'non-finite' not in sent[-1][1]
