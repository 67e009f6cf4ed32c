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

"""A chain whose loop the paper's constraints admit and the proper set refuses, and its record.

The parameters are drawn as ``bench/improper_loops.py`` draws (its recording
9) and simulated by the reference written apart from the package
(``test/reference_sim``). Used by ``test/identification/test_loose_loops.py``,
``test/diagnosis/test_loose_baseline.py`` and ``bench/improper_loops.py
--test-record``. :data:`FAR` is draw 1's r1 of ``bench/cmaes_review.py --seeds 1``
(an independent reviewer's draw under the paper's constraints), a loop whose
proper fit ends about 40 x the noise floor.
"""

from __future__ import annotations

import numpy as np
from reference_sim import simulate as reference_simulate

from hyst_id.io.recording import Recording

__all__ = ['FAR', 'far_recording', 'H', 'IMPROPER', 'improper_csv', 'improper_recording',
           'X']

#: A chain drawn as ``bench/improper_loops.py`` draws (its recording 9): the left line meets
#: the bottom line right of where the right line does (A > B) and the top line right of it
#: (D > C).
IMPROPER = {'m_l': 1.063, 'm_r': 1.296, 'm_t': 0.553, 'm_b': 0.362, 'c_l': 0.964,
            'c_r': 1.841, 'c_t': 4.826, 'c_b': 4.485, 'm_bl': 1.388, 'c_bl': -0.158,
            'c_br': 0.158}
H = [IMPROPER[k] for k in ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')]
X = np.array(H + [IMPROPER['m_bl'], IMPROPER['c_bl'], IMPROPER['c_br']])


FAR = {'m_l': 1.117, 'm_r': 2.576, 'm_t': 0.193, 'm_b': 0.288, 'c_l': 1.489, 'c_r': 4.47,
       'c_t': 13.359, 'c_b': 5.045, 'm_bl': 1.955, 'c_bl': -2.984, 'c_br': -2.444}


def far_recording(seed: int) -> tuple[Recording, float]:
    """:data:`FAR` under a decaying sine, 1,500 samples at 0.1 s, noise 0.4 % of the span."""
    t = np.arange(1500) * 0.1
    v = 12.0 + 4.9 * np.exp(-1.2 * t / t[-1]) * np.sin(2 * np.pi * t / 18.0)
    x = reference_simulate('position', FAR, t, v)
    sigma = 0.004 * float(np.ptp(x))
    y = x + np.random.default_rng(seed).normal(0.0, sigma, x.size)
    return Recording(t, v, y, 'position'), sigma


def improper_recording(seed: int) -> tuple[Recording, float]:
    """The improper chain under a decaying sine, 1,500 samples, noise 1 % of the span."""
    t = np.arange(1500) * 0.05
    v = 9.0 + 2.0 * np.exp(-t / 60.0) * np.sin(2 * np.pi * t / 7.0)
    x = reference_simulate('position', IMPROPER, t, v)
    sigma = 0.01 * float(np.ptp(x))
    y = x + np.random.default_rng(seed).normal(0.0, sigma, x.size)
    return Recording(t, v, y, 'position'), sigma


def improper_csv(seed: int, path) -> tuple[Recording, float]:
    """:func:`improper_recording`, also written to ``path`` as a CSV the CLI reads."""
    rec, sigma = improper_recording(seed)
    np.savetxt(path, np.c_[rec.t_s, rec.command, rec.measurement], delimiter=',',
               header='t,command,measurement', comments='')
    return rec, sigma
