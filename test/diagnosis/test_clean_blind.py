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

"""A clean blind recording claims no physics with ``more_starts`` (issue 14).

Recording #59 of ``bench/blind_family.py`` (the independent reference
simulator, no effect put in) is a member of the paper's chain under the
reference's sensor hold. With the default data-built starts (four splits of
the loop width) the baseline stops at 1.19 x the held-out floor and
``actuator_dynamics`` fills the gap and is claimed. With
``DiagnoseSettings(more_starts=True)`` (five more splits, ranked again under
the other sensor hold: :func:`hyst_id.identification.incumbent.data_incumbent`)
the baseline reaches the floor and the verdict is ``none``, unperturbed and
under round-off probes 1, 2 and 3 (measured 2026-11-29). #63, the other clean
recording with a claim, gets ``none`` too except under probe 3 (dead_time
again), so it is not asserted here (docs/diagnosis.md).
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
