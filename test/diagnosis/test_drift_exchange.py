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

"""The drift exchange: a changing gain tried in the place of an offset drift at the end.

The step itself: the reference chain (``reference_sim``, written apart) read by a
sensor whose gain grows about a zero five spans below the travel, or whose zero
drifts; ``offset_drift`` forced in as the final model's block; the gain must
replace it in the first case and not in the second (the spread over seeds:
``python bench/drift_exchange_spread.py``). End to end: blind #34
of ``bench/blind_family.py`` (a gain drift that ``offset_drift`` took before the
step) ends with ``gain_drift``, and #89 (an offset drift on pressure) keeps its
``offset_drift``. Where the command's swing trends with time no exchange is made.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
import sys

from drift_cases import forced_offset, GROWTH
import numpy as np
import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.exchange import drift_exchange
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_gain_about_a_distant_zero_replaces_the_offset_drift(seed):
    """The growing gain takes the offset drift's place, with its growth near the truth."""
    x = drift_exchange(**forced_offset('gain', seed))
    assert x is not None and x.replaced == 'offset_drift' and x.index == 0
    assert x.comparison.mechanism == 'gain_drift'
    assert x.against_final.holdout_z > 4.0
    fit = x.comparison.fit
    rate = float(fit.model.theta(fit.p, 'gain_drift')[0])
    # seeds 0-5: 2.8-4.2 % against 4 % (bench/drift_exchange_spread.py)
    assert rate * 120.0 == pytest.approx(GROWTH, rel=0.5)
    assert 'offset' in x.why and 'gain_drift' in x.stale


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_an_offset_drift_is_kept(seed):
    """No gain takes the place of a drift of the zero alone."""
    assert drift_exchange(**forced_offset('offset', seed)) is None


@pytest.mark.slow
@pytest.mark.parametrize('index, effect', [
    (34, 'gain_drift'),
    # thorough tier: the forced offset drifts above already show one kept, in seconds
    pytest.param(89, 'offset_drift', marks=pytest.mark.thorough)])
def test_blind_drifts_end_with_their_own_block(index, effect):
    """#34: a gain drift that ``offset_drift`` took; #89: an offset drift, kept.

    Before the step #34 (random steps) ended with ``offset_drift``; with it ``gain_drift``
    replaces it (training BIC +6, held-out z +6.6; +3, +8.8 under round-off probe 2; under
    probe 1 round 1 takes ``gain_drift`` itself), and ``offset_drift`` is the stated
    alternative where it was exchanged. On #89 the gain in the offset's place predicts the
    held-out part better too (z +7.5), but its own trial refuses it: its rate sits at the
    slowest end of its search, where it is an offset ramp. Both held under
    ``HYST_ID_ROUNDOFF_PROBE=1`` and ``=2`` on 2026-12-02. (#64, a gain drift on a
    decaying sine, is not exchanged: ``test_blind_calls.py``.)
    """
    case = blind_family.draw(index)
    assert case['effects'] == [effect]
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index}')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1))
    assert [f.mechanism for f in d.findings] == [effect], d.report()
    exchanged = [a['mechanism'] for a in d.findings[0].alternatives
                 if a.get('kind') == 'exchanged']
    assert exchanged in ([], ['offset_drift']) if effect == 'gain_drift' else exchanged == []


def test_no_exchange_where_the_commands_swing_trends_with_time():
    """On a decaying sine a gain in time and a shape over the level act alike: no exchange."""
    kw = forced_offset('gain', 0)
    data = kw['data']
    t = data.t_s
    kw['data'] = replace(data, v=np.exp(-t / t[-1] * 2.0) * np.sin(2.0 * np.pi * 0.1 * t))
    said: list[str] = []
    assert drift_exchange(**kw, say=said.append) is None
    assert 'swing trends with time' in said[0]
