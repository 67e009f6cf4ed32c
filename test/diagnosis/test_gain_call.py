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

"""A gain drift that an offset drift stood in for is stated as a judgement call.

The finding and the residual's trend are those of blind #64 of
``bench/blind_family.py`` (a 2.9 % gain growth about a zero five spans below
the travel: ``offset_drift`` at 1.03 x the floor, the final residual's
time x level term at t = 7.2; 2026-11-28).
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from hyst_id.diagnosis.exchange import gain_call
from hyst_id.diagnosis.locate import LEVEL_TREND_T
from hyst_id.diagnosis.report import _alternative_lines
from hyst_id.diagnosis.result import Finding

LIBRARY = {'offset_drift', 'gain_drift', 'supply_decay', 'dead_time'}


def _finding(mechanism: str) -> Finding:
    return Finding(mechanism=mechanism, title='', placement='', explanation='', where={},
                   params={}, er_train_before_percent=0.263, er_train_after_percent=0.0835,
                   er_holdout_before_percent=0.6061, er_holdout_after_percent=0.0827,
                   delta_bic=-361.0, holdout_z=181.6)


def _loc(level_t: float):
    return SimpleNamespace(trend={'level_t': level_t})


def test_an_offset_drift_whose_residual_scales_with_the_level_names_a_growing_gain():
    findings = [_finding('offset_drift')]
    gain_call(findings, _loc(7.2), LIBRARY)
    (call,) = findings[0].alternatives
    assert call['mechanism'] == 'gain_drift' and call['kind'] == 'signature'
    text = '\n'.join(_alternative_lines(findings[0]))
    assert 'judgement call' in text and 'gain_drift' in text and 't=7.2' in text


def test_a_falling_level_trend_names_supply_decay_where_the_library_has_it():
    findings = [_finding('offset_drift')]
    gain_call(findings, _loc(-6.0), LIBRARY)
    assert [a['mechanism'] for a in findings[0].alternatives] == ['supply_decay']
    assert 'falling' in '\n'.join(_alternative_lines(findings[0]))
    position = [_finding('offset_drift')]           # no falling-gain block on position
    gain_call(position, _loc(-6.0), LIBRARY - {'supply_decay'})
    assert position[0].alternatives == []


@pytest.mark.parametrize('level_t', [LEVEL_TREND_T, -LEVEL_TREND_T, 0.5])
def test_a_level_trend_within_the_bound_adds_nothing(level_t):
    findings = [_finding('offset_drift')]
    gain_call(findings, _loc(level_t), LIBRARY)
    assert findings[0].alternatives == []


@pytest.mark.parametrize('ids', [['dead_time'], ['offset_drift', 'gain_drift'],
                                 ['supply_decay', 'offset_drift'], []])
def test_only_an_offset_finding_without_a_time_gain_block_gets_the_call(ids):
    findings = [_finding(m) for m in ids]
    gain_call(findings, _loc(9.0), LIBRARY)
    assert all(f.alternatives == [] for f in findings)


def test_a_gain_already_named_as_a_close_call_is_not_named_twice():
    findings = [_finding('offset_drift')]
    findings[0].alternatives = [{'mechanism': 'gain_drift', 'kind': 'close',
                                 'er_holdout_after_percent': 0.083}]
    gain_call(findings, _loc(7.2), LIBRARY)
    assert [a['kind'] for a in findings[0].alternatives] == ['close']
