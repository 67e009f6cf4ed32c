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

"""The exchange step: a lag block chosen early is tried again with the later blocks in.

The step itself: the reference chain with a static curve and a lag, the wrong lag
block forced into the final model (each way round) and replaced, the right one kept.
End to end: blind #24 (``bench/blind_family.py``, the independent reference
simulator) has a sensor lag of 1.9 samples and a static curve; the first round, with
the curve still missing, named ``dead_time``. Its mirror, the same draw with a dead
time of two samples in place of the lag, must get no sensor lag: the exchange is
made on the data's say, not for a favourite block.
"""

from __future__ import annotations

from pathlib import Path
import sys

from lag_cases import forced, mirror_of_24
import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.exchange import exchanges, LAGS
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []

SETTINGS = DiagnoseSettings(workers=1)


@pytest.mark.parametrize('lag, wrong', [('sensor_lag', 'dead_time'),
                                        ('dead_time', 'sensor_lag')])
def test_a_wrong_lag_block_forced_in_is_exchanged_for_the_records_own(lag, wrong):
    """The record's own lag block replaces a wrong one the later curve had hidden."""
    made = exchanges(**forced(lag, wrong))
    assert [(x.index, x.replaced, x.comparison.mechanism) for x in made] == [(1, wrong, lag)]
    x = made[0]
    assert x.against_final.delta_bic < -10.0 and x.against_final.holdout_z > 4.0
    assert 'static_nonlinearity' in x.comparison.fit.model.ids


@pytest.mark.parametrize('lag', ['sensor_lag', 'dead_time'])
def test_the_records_own_lag_block_is_kept(lag):
    """Nothing is exchanged when the finding is the record's own lag block."""
    assert exchanges(**forced(lag, lag)) == []


@pytest.mark.slow
def test_blind_24_ends_with_its_lag_and_its_curve():
    """#24: a sensor lag and a static curve, both named, whatever round 1 took.

    Without the exchange ``dead_time`` took round 1 and stayed (final 1.07 x the floor).
    Here round 1 takes ``dead_time`` and the exchange puts ``sensor_lag`` in its place
    (training BIC -120, held-out z 7.1, final 1.03 x); under round-off probe 1
    (``HYST_ID_ROUNDOFF_PROBE``) round 1 takes ``actuator_dynamics`` and the exchange
    does the same (BIC -101, z 7.2, 1.03 x); under probes 0 and 2 round 1 takes
    ``sensor_lag`` itself. The replaced block, where there is one, is stated beside it.
    """
    case = blind_family.draw(24)
    assert case['effects'] == ['sensor_lag', 'static_nonlinearity']
    rec = Recording(case['t'], case['command'], case['measurement'], 'position',
                    source='blind #24')
    d = diagnose(rec, settings=SETTINGS)
    assert [f.mechanism for f in d.findings] == ['sensor_lag', 'static_nonlinearity'], d.report()
    calls = d.findings[0].alternatives
    assert 'sensor_lag' not in [a['mechanism'] for a in calls]
    for a in calls:
        if a.get('kind') == 'exchanged':
            assert a['mechanism'] in LAGS and a is calls[0]
            assert 'took its round around the chain of that round' in d.report()
    tau = d.findings[0].params['tau_lag_s'].value
    assert tau == pytest.approx(case['magnitudes']['sensor_lag'], rel=0.25)
    assert d.final.er_holdout_percent < 1.15 * d.noise_floor_percent


@pytest.mark.slow
@pytest.mark.thorough
def test_a_dead_time_beside_a_static_curve_gets_no_sensor_lag():
    """The mirror of #24: no sensor lag is put in where the record has a dead time.

    Thorough tier: the default run checks the exchange's rule beside a static curve
    with the blocks forced in (``test_the_records_own_lag_block_is_kept[dead_time]``,
    ``test_a_wrong_lag_block_forced_in_is_exchanged_for_the_records_own[dead_time-
    sensor_lag]``); this diagnosis end to end, where round 1 takes
    ``actuator_dynamics``, runs in ``./run test-all`` only.

    Round 1 takes ``actuator_dynamics`` here (damping at its 0.7 bound, 0.92 Hz: a
    second order standing in for a two-sample delay, final 1.05 x the floor); the
    exchange tries ``dead_time`` in its place (training BIC -43, held-out z -3.2: not
    better) and ``sensor_lag`` (BIC +172), and keeps it; under round-off probe 1 round 1
    takes ``dead_time`` (1.07 x). A limit the exchange does not mend, stated in
    docs/diagnosis.md; ``python bench/exchange_trial.py`` prints these figures.
    """
    d = diagnose(mirror_of_24(), settings=SETTINGS)
    found = [f.mechanism for f in d.findings]
    assert 'sensor_lag' not in found and 'static_nonlinearity' in found, d.report()
    assert found[0] in LAGS
    assert not [a for f in d.findings for a in f.alternatives
                if a.get('kind') == 'exchanged' and f.mechanism == 'sensor_lag']
    assert d.final.er_holdout_percent < 1.15 * d.noise_floor_percent
