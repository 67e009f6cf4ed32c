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

"""A searched parameter that ends on an edge of its search is said to be a bound.

An independent reviewer's creep (1.5 s) came back as 2 s, the lower end of its
search, and a width growing with accumulated travel as a rate dependence whose
filter sat at the upper end (a loop period): both were reported as measured.
"""

from __future__ import annotations

import numpy as np

from hyst_id.diagnosis.mechanisms import get_mechanisms
from hyst_id.diagnosis.mechanisms.base import Context, EDGE_FRACTION


def _ctx() -> Context:
    t = np.arange(2000) * 0.02
    return Context('position', t, 1400, extra={'period_s': 10.0})


def _mech(mid: str):
    return next(m for m in get_mechanisms(None, channel='position') if m.id == mid)


def test_a_creep_time_at_the_lower_end_is_a_bound():
    creep, ctx = _mech('creep'), _ctx()
    lo, hi = creep.bounds(ctx)[0]
    words = creep.at_edges(np.array([lo * (1 + 1e-6)]), ctx)
    assert len(words) == 1 and words[0].startswith(f'{creep.names[0]} = {lo:.4g} s sits at '
                                                   'the lower end of its search'), words
    assert 'read it as a bound, not a measurement' in words[0]
    assert creep.at_edges(np.array([0.5 * (lo + hi)]), ctx) == []
    off = lo + 3 * EDGE_FRACTION * (hi - lo)         # a little inside: not on the edge
    assert creep.at_edges(np.array([off]), ctx) == []


def test_an_edge_at_zero_is_the_physics_own_limit():
    rate, ctx = _mech('rate_dependence'), _ctx()
    (w_lo, w_hi), (t_lo, t_hi) = rate.bounds(ctx)
    assert w_lo == 0.0 and t_lo == 0.0
    assert rate.at_edges(np.array([0.0, 0.5 * t_hi]), ctx) == []
    words = rate.at_edges(np.array([0.3 * w_hi, t_hi]), ctx)
    assert len(words) == 1 and 'rate_filter_tau_s = 10 s sits at the upper end' in words[0]
