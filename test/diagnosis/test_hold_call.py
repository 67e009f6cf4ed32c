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

"""A lag behind a one-sample hold that a winning dead time also describes is stated.

Figures of blind #134 of ``bench/blind_family.py`` (a 0.5-sample first-order lag in
the reference simulator's hold, position at 10 Hz; 2026-11-28): ``dead_time`` won
with 1.2 samples at judged held-out 0.3918 %, the ``sensor_lag`` fit in the
``after`` hold, dropped as a delay in disguise, reached 0.3904 %.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hyst_id.diagnosis.report import _alternative_lines
from hyst_id.diagnosis.result import Finding
from hyst_id.diagnosis.select import Criteria
from hyst_id.diagnosis.ties import HOLD_CALL_SAMPLES, hold_calls

DT_S = 0.1
DATA = SimpleNamespace(judged_er_percent=lambda fit: fit.er)


def _fit(er: float, delay_s: float = 0.0):
    model = SimpleNamespace(theta=lambda p, mechanism: np.array([delay_s]))
    return SimpleNamespace(er=er, er_holdout_percent=er, model=model, p=None)


def _comp(mechanism: str, er: float, screened: float | None = None, delay_s: float = 0.115):
    return SimpleNamespace(mechanism=mechanism, fit=_fit(er, delay_s),
                           screened=None if screened is None else _fit(screened))


def test_a_dropped_lag_as_good_as_the_winning_dead_time_is_a_judgement_call():
    winner = _comp('dead_time', 0.3918)
    comps = [winner, _comp('sensor_lag', 0.5947, screened=0.3904), _comp('creep', 1.9)]
    (call,) = hold_calls(winner, comps, DATA, Criteria(), DT_S)
    assert call['mechanism'] == 'sensor_lag' and call['kind'] == 'hold'
    assert call['er_judged_after_percent'] == 0.3904
    f = Finding('dead_time', '', '', '', {}, {}, 1.35, 0.40, 2.02, 0.3918, -3421.0, 132.8,
                alternatives=[call])
    text = '\n'.join(_alternative_lines(f))
    assert 'judgement call: sensor_lag behind a one-sample hold' in text


def test_a_dropped_fit_beyond_the_judgement_ratio_or_another_winner_adds_nothing():
    ratio = Criteria().judgement_ratio
    winner = _comp('dead_time', 0.0748)     # blind #84: the dropped lag fit stayed at 0.189
    assert hold_calls(winner, [winner, _comp('sensor_lag', 0.18, screened=0.1887)],
                      DATA, Criteria(), DT_S) == []
    edge = _comp('sensor_lag', 0.5, screened=0.0748 * ratio * 1.001)
    assert hold_calls(winner, [winner, edge], DATA, Criteria(), DT_S) == []
    other = _comp('creep', 0.3918)
    assert hold_calls(other, [other, _comp('sensor_lag', 0.5, screened=0.39)],
                      DATA, Criteria(), DT_S) == []


def test_a_delay_of_many_samples_is_not_a_lag_behind_a_hold():
    lag = _comp('sensor_lag', 0.5947, screened=0.3904)
    for delay_s, called in ((HOLD_CALL_SAMPLES * DT_S * 0.99, True),
                            (HOLD_CALL_SAMPLES * DT_S * 1.01, False), (3.4, False)):
        winner = _comp('dead_time', 0.3918, delay_s=delay_s)
        assert bool(hold_calls(winner, [winner, lag], DATA, Criteria(), DT_S)) is called, delay_s
