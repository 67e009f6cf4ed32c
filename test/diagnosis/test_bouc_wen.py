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

"""``bouc_wen``: a Dahl state lagging the travel, the piezo form of a Bouc-Wen loop.

The recordings come from ``test/bouc_wen_reference.py`` (a Bouc-Wen state
integrated by explicit Euler substeps, with its own beta and gamma, written apart
from the package's exact Dahl steps).
"""

from __future__ import annotations

from bouc_wen_reference import bouc_wen_recording
import numpy as np
import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms import get_mechanisms
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.errors import ConfigError

SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1, hops=20)
#: Final held-out %e_r over the floor with these settings: 1.19, 1.70 and 1.27 on seeds 0-2
#: (``python bench/bouc_wen_forms.py``, quick rows; 1.02-1.16 with the defaults)
BOUND_FINAL = 2.2


def test_the_state_lags_a_sloped_reading_and_friction_leads_it():
    """The two blocks share the math and split the sense: each refuses the other's."""
    bw, fr = MECHANISMS['bouc_wen'], MECHANISMS['friction']
    span, th = (0.0, 1.0), np.array([0.03])
    lagging, leading = np.array([10.0, -1.0, 0.0]), np.array([10.0, 1.0, 0.0])
    labels, fr_labels = ['sensor', 'bouc_wen:0', 'offset'], ['sensor', 'friction:0', 'offset']
    assert bw.implausible(th, lagging, span, 0.01, labels=labels) == ''
    assert 'friction force' in bw.implausible(th, leading, span, 0.01, labels=labels)
    assert fr.implausible(th, leading, span, 0.01, labels=fr_labels) == ''
    assert 'lags the motion' in fr.implausible(th, lagging, span, 0.01, labels=fr_labels)
    # on a nearly flat reading a band is friction's (or the loop), not a share of the travel
    assert 'hardly changes' in bw.implausible(th, np.array([1.9, -1.0, 0.0]), span, 0.01,
                                              labels=labels)
    assert 'below the measurement noise' in bw.implausible(
        th, np.array([10.0, -0.005, 0.0]), span, 0.01, labels=labels)


def test_bouc_wen_is_registered_for_the_position_reading():
    m = MECHANISMS['bouc_wen']
    assert m.stage == 'quantity' and m.n_linear == 1 and m.compensation == 'not in-line'
    assert 'piezo' in m.physics
    assert 'bouc_wen' in [x.id for x in get_mechanisms(channel='position')]
    assert 'bouc_wen' not in [x.id for x in get_mechanisms(channel='pressure')]
    with pytest.raises(ConfigError, match='cannot act on the pressure channel'):
        get_mechanisms(['bouc_wen'], channel='pressure')


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_piezo_loop_is_a_bouc_wen_state_not_creep(seed):
    """The piezo form ``x = V - 0.4 z``: named ``bouc_wen``, its state lagging the travel.

    Before the block the same recordings were named ``creep`` (final held-out 1.74-1.91 x
    the floor, seeds 0-2, ``python bench/bouc_wen_forms.py``). With it (the same bench):
    ``bouc_wen`` on seeds 0-2 with these settings and with the defaults, its height
    0.19-0.43 um against the reference's 0.4 (the chain's own loop takes a share of the
    width), final held-out as :data:`BOUND_FINAL` says.
    """
    d = diagnose(bouc_wen_recording(seed, 'piezo'), settings=SETTINGS)
    assert d.verdict == 'bouc_wen', [f.mechanism for f in d.findings]
    p = d.findings[0].params
    assert p['state_height'].unit == 'um' and 0.1 < p['state_height'].value < 0.6
    assert 'lags the motion' in d.findings[0].explanation
    assert d.final.er_holdout_percent < BOUND_FINAL * d.noise_floor_percent
