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

"""The family swap's kept search: reused only for the same samples, spec and settings.

:func:`hyst_id.diagnosis.baseline.quick_starts` stands in for a repeated
search, so it must search again whenever anything the search depends on
differs, and hand out copies the caller may change.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hyst_id.diagnosis import baseline
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording, ROUNDOFF_PROBE_ENV


@pytest.fixture
def searches(monkeypatch):
    """Count the searches; each returns arrays made from its call number."""
    calls = []

    def fake(rec_train, spec, settings, *, thorough=True, global_phase=None):
        calls.append(thorough)
        k = float(len(calls))
        return [np.full(11, k)], [np.full(11, -k), np.full(11, 2 * k)]

    monkeypatch.setattr(baseline, 'baseline_starts', fake)
    return calls


def _rec(shift: float = 0.0) -> Recording:
    t = np.arange(0.0, 10.0, 0.05)
    v = 9.0 + np.sin(t)
    return Recording(t, v, 0.5 * v + shift, 'position')


def test_the_same_search_is_made_once(searches):
    spec, settings = chain_spec('position'), DiagnoseSettings()
    a = baseline.quick_starts(_rec(), spec, settings)
    b = baseline.quick_starts(_rec(), spec, settings)
    assert searches == [False]                       # once, and the quick one
    for x, y in zip(a[0] + a[1], b[0] + b[1]):
        np.testing.assert_array_equal(x, y)
    a[0][0][:] = 99.0                                # the caller's copy, not the kept one
    assert baseline.quick_starts(_rec(), spec, settings)[0][0][0] == 1.0
    # the number of worker processes does not change the search
    baseline.quick_starts(_rec(), spec, replace(settings, workers=2))
    assert len(searches) == 1


@pytest.mark.parametrize('change', ['samples', 'seeds', 'generations', 'bounds', 'probe'])
def test_anything_the_search_depends_on_searches_again(searches, monkeypatch, change):
    spec, settings, rec = chain_spec('position'), DiagnoseSettings(), _rec()
    baseline.quick_starts(rec, spec, settings)
    if change == 'samples':
        rec = _rec(shift=1e-12)
    elif change == 'seeds':
        settings = replace(settings, seeds=(0, 2))
    elif change == 'generations':
        settings = replace(settings, generations=201)
    elif change == 'bounds':
        spec = spec.with_bounds({'m_l': (0.2, 5.0)})
    else:
        monkeypatch.setenv(ROUNDOFF_PROBE_ENV, '1')
    got = baseline.quick_starts(rec, spec, settings)
    assert len(searches) == 2
    assert got[0][0][0] == 2.0


def test_at_most_quick_kept_searches_are_held(searches):
    spec = chain_spec('position')
    for i in range(baseline.QUICK_KEPT + 3):
        baseline.quick_starts(_rec(shift=float(i)), spec, DiagnoseSettings())
    assert len(baseline.quick_memo()) == baseline.QUICK_KEPT
    baseline.quick_starts(_rec(shift=0.0), spec, DiagnoseSettings())   # the oldest went
    assert len(searches) == baseline.QUICK_KEPT + 4
    baseline.forget_quick()
    assert baseline.quick_memo() == {}
