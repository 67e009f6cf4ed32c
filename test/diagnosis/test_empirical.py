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

"""The empirical block and the ``unknown`` verdict: physics outside the library is not dressed up.

The recordings come from the independent reference simulator
(``test/reference_sim``), not from the package's chain.
"""

from __future__ import annotations

from pathlib import Path
import sys

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis import diagnose
from hyst_id.diagnosis.empirical import empirical_block, stlsq
from hyst_id.diagnosis.verdict import WHOLE_RECORD_FACTOR
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

T = np.arange(3000) * 0.02
V = 9.0 + 3.0 * np.sin(2 * np.pi * T / 12.0)


def test_stlsq_keeps_the_few_columns_that_matter():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(500, 8))
    r = 2.0 * x[:, 1] - 0.5 * x[:, 6] + rng.normal(0, 0.01, 500)
    coef = stlsq(x, r)
    assert np.flatnonzero(coef).tolist() == [1, 6]
    assert coef[1] == pytest.approx(2.0, abs=0.01) and coef[6] == pytest.approx(-0.5, abs=0.01)


def test_a_gain_drift_is_carried_by_time_x_command():
    y = 0.5 * V + 0.05 * T * (V - 9.0) / 60.0
    y = y + np.random.default_rng(1).normal(0, 0.01, T.size)
    block = empirical_block(T, V, y, 0.5 * V, 2100, 12.0)
    assert block.gain > 0.5 and block.features[0][0] == 'time x command'
    assert 'time x command' in block.summary()


def test_a_white_residual_is_explained_by_nothing():
    y = 0.5 * V + np.random.default_rng(2).normal(0, 0.01, T.size)
    block = empirical_block(T, V, y, 0.5 * V, 2100, 12.0)
    assert block.features == [] and 'explains none' in block.summary()


def _hum_recording(seed: int) -> Recording:
    """The paper's loop and backlash plus a pump pulsation unrelated to the command."""
    rng = np.random.default_rng(seed)
    t = np.arange(2000) * 0.05
    v = 9.0 + 4.0 * np.sin(2 * np.pi * t / 12.0) * (0.6 + 0.4 * np.sin(2 * np.pi * t / 70.0))
    y0 = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                  -0.15, 0.15)
    span = np.ptp(y0)
    hum = 0.03 * span * np.sin(2 * np.pi * t / 1.37 + rng.uniform(0, 2 * np.pi))
    return Recording(t, v, y0 + hum + rng.normal(0, 0.004 * span, t.size), 'position', 'mA',
                     f'hum #{seed}')


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_physics_outside_the_library_is_unknown(seed):
    d = diagnose(_hum_recording(seed))
    # measured over seeds 0-2: 5.3-5.6 x the floor left, no block accepted
    assert d.verdict == 'unknown' and not d.findings, [f.mechanism for f in d.findings]
    assert d.final.er_holdout_percent > 3.0 * d.noise_floor_percent
    # the hum is not the chain's on the whole record either
    whole = d.extra['whole_record']
    assert whole['er_percent'] > 3.0 * whole['noise_floor_percent']
    assert d.empirical is not None and d.empirical.features == []
    assert 'verdict: unknown' in d.report() and d.to_dict()['empirical']['gain'] < 0.05
    assert 'the mismatch is in the data, not only in how the record was split' in d.report()
    assert d.status()[0] == 'warn'


def test_the_chain_makes_blind_60_on_the_whole_record():
    """Blind #60 (clean, minor loops): two training fits at the floor can differ held out.

    On this machine the baseline trained on 70 % ends at 0.98 x its floor and
    misses the held-out part by 18 x; under round-off probes 1 and 2 another
    training fit at the floor predicts it at 1.0 x. The chain identified on
    every sample makes the record at its floor either way.
    """
    from hyst_id.diagnosis import DiagnoseSettings
    from hyst_id.diagnosis.baseline import whole_record_er
    from hyst_id.identification.chains import chain_spec
    from hyst_id.diagnosis.locate import noise_std
    from hyst_id.signals.noise import floor_percent
    case = blind_family.draw(60)
    y = case['measurement']
    rec = Recording(case['t'], case['command'], y, case['channel'], source='blind #60')
    whole = whole_record_er(rec, chain_spec('position'), DiagnoseSettings())
    assert whole <= WHOLE_RECORD_FACTOR * floor_percent(y, noise_std(y))


@pytest.mark.slow
def test_a_held_out_miss_the_chain_makes_on_the_whole_record_is_no_physics(monkeypatch):
    """The hum recording (no block explains it), the whole-record fit replaced by one at 1 x.

    Its real whole-record fit (5 x and more: unknown) is asserted above.
    """
    import hyst_id.diagnosis.verdict as verdict
    from hyst_id.diagnosis.locate import noise_std
    from hyst_id.signals.noise import floor_percent
    rec = _hum_recording(0)
    floor = floor_percent(rec.measurement, noise_std(rec.measurement))
    monkeypatch.setattr(verdict, 'whole_record_er', lambda *a: floor)
    d = diagnose(rec)
    assert not d.findings and d.verdict == 'none'
    assert d.extra['whole_record']['er_percent'] == floor
    assert d.final.er_holdout_percent > 3.0 * d.noise_floor_percent   # the split's miss
    assert 'identified on the whole record' in d.report() and d.status()[0] == 'ok'
