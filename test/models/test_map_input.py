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

"""Every family writes its loop for another command frame: ``H'(a v + b) == H(v)``."""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.models.registry import FAMILIES, get_family

SETS = {
    'tk': [1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0],
    'smooth': [0.5, 0.2, 0.1, 0.1, 0.05, 0.05, 0.1, 2.0, 5.0, 9.0, 3.0],
}


def test_every_registered_family_has_a_set_here():
    assert set(FAMILIES) <= set(SETS)


@pytest.mark.parametrize('family', sorted(SETS))
@pytest.mark.parametrize('a, b', [(0.5, -100.0), (3.0, 7.0), (1.0, 0.0), (0.02, 1.0)])
def test_the_loop_is_the_same_in_another_command_frame(family, a, b):
    fam = get_family(family)
    rng = np.random.default_rng(5)
    v = 9.0 + np.cumsum(rng.normal(0.0, 0.4, 800))          # random walk with minor loops
    p = np.asarray(SETS[family], dtype=float)
    mapped = fam.map_input(p, a, b)
    np.testing.assert_allclose(fam.simulate(mapped, a * v + b), fam.simulate(p, v),
                               rtol=1e-9, atol=1e-9 * np.ptp(fam.simulate(p, v)))
    np.testing.assert_allclose(fam.map_input(mapped, 1.0 / a, -b / a), p, rtol=1e-12,
                               atol=1e-12)
