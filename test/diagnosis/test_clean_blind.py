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

"""Clean blind recordings claim no physics (issue 14).

Recordings #59 and #63 of ``bench/blind_family.py`` (the independent reference
simulator, no effect put in) are members of the paper's chain under the
reference's sensor hold. With the default data-built starts (four splits of
the loop width) the baseline stops at 1.19 x and 1.24 x the held-out floor,
and ``actuator_dynamics`` (#59) and ``dead_time`` (#63) filled the gap. Two
ways now take those claims off:

* by default, the challenge (:mod:`hyst_id.diagnosis.challenge`): a claim
  made against a baseline within 1.5 x the floor must beat the chain alone
  searched again with more data-built starts; unperturbed, on both it does
  not, the claims are withdrawn and the verdict is ``none``. Under round-off
  probes 1, 2 and 3 the verdict is ``none`` too, mostly without the
  challenge: #59's baseline reaches the floor by itself, #63's under probe 1,
  and under probes 2 and 3 it stops at 1.6 x with no claim made (measured
  2026-11-29, see ``FINAL_WITHIN``). Another CPU make is like a probe, so
  the test asserts the verdict, not the withdrawal;
* ``DiagnoseSettings(more_starts=True)`` (five more splits, ranked again under
  the other sensor hold: :func:`hyst_id.identification.incumbent.data_incumbent`),
  with which #59's baseline itself reaches the floor, unperturbed and under
  probes 1, 2 and 3.
"""

from __future__ import annotations

from pathlib import Path
import sys

import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []

#: Baseline judged held-out %e_r over its floor: measured 1.029-1.036 x on #59 unperturbed
#: and under HYST_ID_ROUNDOFF_PROBE=1, 2, 3 with more starts, verdict none in all four
#: (2026-11-29); 1.19 x without.
BASELINE_WITHIN = 1.1

#: Final judged held-out %e_r over its floor with the default settings, verdict none in
#: every run: #59 1.03, 1.04, 1.04, 1.03 x and #63 1.02, 1.01, 1.08, 1.01 x unperturbed and
#: under HYST_ID_ROUNDOFF_PROBE=1, 2, 3 (2026-11-29; under the probes the baselines reach
#: 1.0 x on #59 and 1.0, 1.6, 1.6 x on #63). The claims' finals were 1.04 x: the verdict is
#: what tells; this bound only keeps the final model near the floor.
FINAL_WITHIN = 1.2


@pytest.mark.slow
@pytest.mark.parametrize('index', [pytest.param(59, marks=pytest.mark.thorough), 63])
def test_a_clean_reference_recording_gets_verdict_none(index):
    """No finding at all, and a final model at the floor on the judged held-out part.

    #59 is in the thorough tier: #63 is the case that stays for the default settings
    (its claim withdrawn by the challenge, as #59's ``actuator_dynamics`` is: that
    withdrawal on #59 is checked by ``./run test-all`` only); the default run
    diagnoses #59 with more starts below.
    """
    case = blind_family.draw(index)
    assert case['effects'] == []
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index}')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1))
    assert d.verdict == 'none', d.report()
    assert d.findings == [], d.report()
    j = d.extra['judged_holdout']
    assert j['final_er_percent'] <= FINAL_WITHIN * j['noise_floor_percent'], d.report()


@pytest.mark.slow
def test_a_clean_reference_recording_gets_verdict_none_with_more_starts():
    """No finding at all, and a baseline at the floor on the held-out part."""
    index = 59
    case = blind_family.draw(index)
    assert case['effects'] == []
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index}')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, more_starts=True))
    assert d.verdict == 'none', d.report()
    assert d.findings == [], d.report()
    j = d.extra['judged_holdout']
    assert j['baseline_er_percent'] <= BASELINE_WITHIN * j['noise_floor_percent'], d.report()
