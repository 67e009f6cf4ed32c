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

"""Whether the true parameters of the reference family lie in identify's feasible set.

For recordings of ``bench/generalisation.py`` this writes the true loop in the
recording's own command units (``command = a v + b``: slopes / a, side lines
at ``b + a c``, top and bottom intercepts ``c - m b / a``; the output side is
unchanged), and prints whether it breaks the paper's ``c_t > c_b`` (which
compares the lines at command 0), whether the chain over the recording's
data-derived domains accepts it, and the %e_r it scores over the true noise
floor in the recording's conventions (initial state, sensor held after its
sample). A truth outside the feasible set is a floor no optimiser can reach.

Run from the repository root (seconds)::

    python bench/truth_feasibility.py                 # the misses of the previous run
    python bench/truth_feasibility.py 177 44 104
"""

from __future__ import annotations

from dataclasses import replace
import json
from pathlib import Path
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from generalisation import draw_case, recording, true_floor  # noqa: E402, I100

from hyst_id.identification.chains import er_percent  # noqa: E402, I100
from hyst_id.identification.domains import domains_from_data  # noqa: E402


def truth_in_user_units(case) -> dict:
    """The true parameters with the loop in the recording's command units."""
    a, b = case.command_map
    p, q = case.params, dict(case.params)
    for s in 'lr':
        q['m_' + s], q['c_' + s] = p['m_' + s] / a, b + a * p['c_' + s]
    for s in 'tb':
        q['m_' + s], q['c_' + s] = p['m_' + s] / a, p['c_' + s] - p['m_' + s] * b / a
    return q


def check(index: int) -> dict:
    """Feasibility and score of the truth of recording ``index``."""
    case = draw_case(index)
    spec = domains_from_data(recording(case))
    q = truth_in_user_units(case)
    x = np.array([q[n] for n in spec.names])
    if x[10] <= x[9]:       # no backlash: the chain needs c_bl < c_br, by a hair
        x[10] = x[9] + 1e-9
    spec = replace(spec, initial=case.note.split(', ')[-1], hold='after')
    f = spec.cost_function(case.t_s, case.command, case.measurement)(x[None, :])[0]
    return {'index': index, 'note': case.note, 'ct_gt_cb': q['c_t'] > q['c_b'],
            'feasible': bool(spec.feasible(x[None, :])[0]),
            'ratio': er_percent(f, case.measurement) / true_floor(case)}


def main(argv: list[str]) -> int:
    """Check the given recordings, or the misses of docs/data/generalisation_200.jsonl."""
    if argv:
        indices = [int(a) for a in argv]
    else:
        rows = [json.loads(line) for line in
                (ROOT / 'docs' / 'data' / 'generalisation_200.jsonl').read_text().splitlines()]
        indices = [r['index'] for r in rows if r['identify'][0] > 1.1]
    broken = 0
    for i in indices:
        r = check(i)
        broken += not r['ct_gt_cb']
        print(f'#{i} ({r["note"]}): c_t > c_b in its units {r["ct_gt_cb"]}, feasible now '
              f'{r["feasible"]}, truth scores {r["ratio"]:.3f} x the true floor', flush=True)
    print(f'the true loop breaks c_t > c_b in its command units on {broken} of {len(indices)}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
