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

"""``diagnose`` on a real recording of ``../shared/data`` the package did not make.

The M130-27s steel B(H) loops (field H as the command, flux density B as the
response, the sample index as time; loops of growing amplitude, so the
held-out part is the largest loop). Its branches are curved: the verdict a
physicist signs is ``loop_shape``. The single split judges only the first 60
of its 231 held-out samples (the field then leaves the training range), and
on those ``creep`` led (a relaxation with the sample index, which has no
meaning in a quasi-static measurement); blocked cross-validation decides
(:meth:`hyst_id.diagnosis.blocked_cv.BlockedCV.decide`). Measured margins
(``python bench/real_diagnoses.py --only M130``, docs/diagnosis.md): the curved
loop predicts the three judged quarters at 0.53-0.69 of the baseline's error
and every quarter better than creep; the verdict was the same under
``HYST_ID_ROUNDOFF_PROBE=1`` and ``2``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.blocked_cv import confirmed
from hyst_id.io.recording import Recording

__all__: list[str] = []

DATA = Path(__file__).resolve().parents[3] / 'shared' / 'data'


def _bh_loops(path: Path) -> Recording:
    """The loops one after another, as ``bench/real_recordings.py`` reads them."""
    if not path.is_file():
        pytest.skip(f'{path} not found: the shared data sit beside the repository')
    raw = np.loadtxt(path, delimiter=',', skiprows=1)
    order = np.lexsort((raw[:, 1], raw[:, 0]))     # loop, then index within the loop
    h, b = raw[order, 2], raw[order, 3]
    return Recording(np.arange(h.size, dtype=float), h, b, 'position', 'A/m', 'T', path.name)


@pytest.mark.slow
def test_steel_loops_are_named_curved_branches_not_creep():
    rec = _bh_loops(DATA / 'magnetic-bh-loops' / 'M130_27s_steel.csv')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1))
    assert d.verdict == 'loop_shape'
    first = d.findings[0]
    assert confirmed(first.blocked_cv) and first.blocked_cv['worse'] == 0
    assert first.er_holdout_after_percent < 0.6 * d.baseline.er_holdout_percent
    assert 'creep' not in [f.mechanism for f in d.findings]
    # the short split chose otherwise; the time blocks decided, and the report says so
    split, = [a for a in first.alternatives if a['kind'] == 'split']
    assert split['mechanism'] != 'loop_shape' and split['n_judged'] < 0.5 * split['n_holdout']
    assert split['blocked_cv']['better'] == split['blocked_cv']['blocks'] >= 2
    assert f"{split['mechanism']} was the choice of the judged held-out samples" in d.report()
