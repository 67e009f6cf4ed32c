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

"""A named verdict far above the floor says it is not the whole story.

An independent reviewer's loop widening with accumulated travel (outside the
library) was named ``rate_dependence`` with 37 x the floor left and no word
that most of the mismatch was still unexplained.
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from hyst_id.diagnosis.report import _left_over, FAR_FROM_FLOOR


def _d(verdict: str, ratio: float, findings=('rate_dependence',)):
    return SimpleNamespace(verdict=verdict, findings=list(findings), extra={
        'judged_holdout': {'noise_floor_percent': 0.4, 'final_er_percent': 0.4 * ratio}})


@pytest.mark.parametrize('verdict, ratio, said', [
    ('rate_dependence', 37.9, True), ('rate_dependence', 1.05 * FAR_FROM_FLOOR, True),
    ('rate_dependence', 0.95 * FAR_FROM_FLOOR, False), ('unknown', 37.9, False),
    ('none', 37.9, False)])
def test_left_over(verdict, ratio, said):
    words = _left_over(_d(verdict, ratio))
    if not said:
        assert words == []
        return
    assert len(words) == 1 and words[0].startswith(
        f'what is left after the findings: {ratio:.1f} x the noise floor on the judged '
        'held-out samples: the findings are not the whole story'), words


def test_without_a_judged_part_nothing_is_said():
    d = _d('creep', 10.0)
    d.extra = {}
    assert _left_over(d) == []


def _unknown(run_s: float, independent: bool = True, gain: float = 0.0):
    import numpy as np
    return SimpleNamespace(
        t_s=np.arange(3000) * 0.01, empirical=SimpleNamespace(gain=gain),
        final_localization=SimpleNamespace(independent=independent,
                                           acf={'correlated_for_s': run_s}))


@pytest.mark.parametrize('run_s, independent, gain, said', [
    (0.1, True, 0.0, True), (0.29, True, 0.0, True), (0.4, True, 0.0, False),
    (0.1, False, 0.0, False), (0.1, True, 0.2, False), (0.0, True, 0.0, False)])
def test_an_unknown_that_looks_like_coloured_noise_says_so(run_s, independent, gain, said):
    """Unrelated to the command and correlated over at most 1 % of the record."""
    from hyst_id.diagnosis.report import _coloured_lines
    words = _coloured_lines(_unknown(run_s, independent, gain))
    assert bool(words) == said, words
    if said:
        assert f'correlated over only {run_s:.2g} s: filtered (coloured) measurement noise' \
               in words[0] and 'the miss may be the noise itself rather than physics' in words[0]
