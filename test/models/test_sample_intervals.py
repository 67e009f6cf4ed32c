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

"""Sample intervals in one compiled pass: the same bits as numpy's, the same uniform call."""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.errors import RecordingError
from hyst_id.models.sensors import intervals_and_uniform, sample_intervals


def _numpy_intervals(t):
    """The helper the compiled pass replaced (np.diff, first interval repeated)."""
    d = np.diff(np.asarray(t, dtype=np.float64))
    return np.concatenate([d[:1], d]), bool(np.all(np.abs(d - d[0]) <= 1e-9 * abs(d[0])))


CASES = {
    'uniform': np.arange(0.0, 20.0, 0.01),
    'jittered': np.cumsum(0.01 + 1e-4 * np.random.default_rng(3).random(500)),
    'within 1e-9': np.arange(200) * 0.05 * (1.0 + 1e-11 * np.sin(np.arange(200))),
    'decreasing': -np.arange(50) * 0.1,
    'repeated stamp': np.array([0.0, 0.1, 0.1, 0.2]),
    'nan first': np.array([np.nan, 0.1, 0.2, 0.3]),
    'nan inside': np.array([0.0, 0.1, np.nan, 0.3, 0.4]),
    'two samples': np.array([1.0, 1.5]),
}


@pytest.mark.parametrize('name', sorted(CASES))
def test_intervals_equal_numpys_to_the_bit(name):
    t = CASES[name]
    want, uniform = _numpy_intervals(t)
    np.testing.assert_array_equal(sample_intervals(t), want)
    dt, got_uniform = intervals_and_uniform(t)
    np.testing.assert_array_equal(dt, want)
    assert got_uniform == uniform


def test_intervals_call_uniform_as_before():
    assert intervals_and_uniform(CASES['uniform'])[1]
    assert not intervals_and_uniform(CASES['jittered'])[1]


def test_fewer_than_two_samples_is_a_recording_error():
    assert sample_intervals(np.array([3.0])).size == 0
    with pytest.raises(RecordingError, match='two samples'):
        intervals_and_uniform(np.array([3.0]))
