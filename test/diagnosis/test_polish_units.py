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

"""The diagnosis's polish fits a measurement in tiny units as in its own (review finding)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from test_blocked_cv import _record, CHAIN

from hyst_id.diagnosis.mechanisms import Context, MECHANISMS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import polish
from hyst_id.identification.chains import chain_spec

__all__: list[str] = []


def test_a_measurement_in_tiny_units_is_polished_as_in_its_own():
    """The same record x 1e-7: the same delay and cost (scaled back).

    Without the residual scale (``refine.residual_scale``) least_squares' absolute gtol
    stopped the tiny one at its start (0.35 s, 15 evaluations); with it both end at
    0.2010 s with costs equal to 1e-12 relative.
    """
    data, _, _ = _record()
    ctx = Context('position', data.t_s, data.n_train)
    model = ComposedModel('position', [MECHANISMS['dead_time']], ctx,
                          chain_spec('position').bounds)
    p0 = np.concatenate([CHAIN * 1.02, [0.35]])
    p1, f1, _ = polish(model, data, p0, max_nfev=400)
    tiny = replace(data, y=data.y * 1e-7, noise_std=data.noise_std * 1e-7)
    p7, f7, _ = polish(model, tiny, p0, max_nfev=400)
    assert abs(p1[-1] - 0.2) < 0.01 and abs(p7[-1] - p1[-1]) < 1e-6, (p1[-1], p7[-1])
    assert abs(f7 * 1e14 / f1 - 1.0) < 1e-6
