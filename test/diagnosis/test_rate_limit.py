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
"""``rate_limit`` on recordings from the independent reference simulator.

Before the block a slew-limited actuator (steps between held levels into the
paper's chain, followed at a fixed top rate) was named
``actuator_dynamics`` with 24-35 x the noise floor left. The slew
here is written apart from the package's (a plain loop over the samples).
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.mechanisms.rate_limit import slew_limited
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.io.recording import Recording

SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1, hops=20)

#: the reference's top rate, mA/s: the command's 4 mA range in 5 s
RATE_MA_S = 0.8


def reference_slew(t_s: np.ndarray, v: np.ndarray, rate: float) -> np.ndarray:
    """Each sample's change of ``v`` clipped to ``rate`` times its interval (written apart)."""
    out = [float(v[0])]
    for k in range(1, len(v)):
        room = rate * float(t_s[k] - t_s[k - 1])
        out.append(out[-1] + min(room, max(-room, float(v[k]) - out[-1])))
    return np.array(out)


def _steps(rng: np.random.Generator, t_s: np.ndarray, dwell_s: float = 5.0) -> np.ndarray:
    """Steps between random levels in 6.5-11.5 mA, each held ``dwell_s``; 6 and 12 mA early.

    The training part (the first 70 %) reaches both ends, so the held-out
    commands lie inside its range and the held-out error is judged whole.
    """
    levels = rng.uniform(6.5, 11.5, int(np.ceil(t_s[-1] / dwell_s)) + 1)
    levels[1], levels[4] = 6.0, 12.0
    return levels[(t_s // dwell_s).astype(int)]


def _recording(seed: int, rate: float | None) -> Recording:
    rng = np.random.default_rng([seed, 31])
    t = np.arange(2400) * 0.05
    v = _steps(rng, t)
    u = reference_slew(t, v, rate) if rate is not None else v
    x = backlash(hysteresis(u, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                 -0.15, 0.15)
    y = 12.0 * x + 3.0
    return Recording(t, v, y + rng.normal(0, 0.004 * np.ptp(y), t.size), 'position', 'mA',
                     'mm', f'rate limit #{seed}')


def test_the_slew_is_the_reference_and_the_identity_without_a_limit():
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.01, 0.1, 300))
    v = np.cumsum(rng.normal(0, 1.0, 300))
    assert np.allclose(slew_limited(t, v, 1.0 / 3.0), reference_slew(t, v, 3.0), atol=1e-12)
    assert np.array_equal(slew_limited(t, v, 0.0), v)
    fastest = float(np.max(np.abs(np.diff(v)) / np.diff(t)))
    assert np.allclose(slew_limited(t, v, 0.999 / fastest), v, atol=1e-12)


def test_the_search_starts_above_the_fastest_command_and_stays_in_its_bounds():
    t = np.arange(1000) * 0.05
    ctx = Context('position', t, 700, extra={'command_span': 4.0, 'command_rate_max': 40.0})
    m = MECHANISMS['rate_limit']
    lo, hi = m.bounds(ctx)[0]
    assert lo == 0.0 and hi == pytest.approx(0.2 * t[699] / 4.0)
    starts = [float(s[0]) for s in m.starts(ctx)]
    assert starts and all(1.0 / 40.0 < s < hi for s in starts)
    assert m.null(ctx)[0] == 0.0


def test_rate_limit_is_registered_with_words():
    m = MECHANISMS['rate_limit']
    assert m.stage == 'command' and m.compensation == 'not in-line'
    assert 'ramp' in m.physics


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_slew_limited_actuator_is_named_with_its_rate(seed):
    """Named, with its top rate, the held-out error near the floor.

    Measured on seeds 0-3 with these settings, unperturbed and under round-off probes 1
    and 2 (``python bench/rate_limit_spread.py --seeds 4 --drawn 0 [--probes 1 2]``):
    ``rate_limit`` 12/12, the rate 0.9999-1.0005 x the true one, the final held-out error
    0.96-1.03 x the floor except seed 0 under the probes, 3.27 and 3.79 x (its chain lands
    in another basin; without the limit that chain alone ends at 1.66 and 7.63 x there).
    Before the block (``--without``): ``actuator_dynamics`` at 35.02 and 24.22 x.
    """
    d = diagnose(_recording(seed, RATE_MA_S), settings=SETTINGS)
    assert d.verdict == 'rate_limit', [f.mechanism for f in d.findings]
    f = d.findings[0]
    assert f.params['max_rate'].value == pytest.approx(RATE_MA_S, rel=0.005)
    assert f.params['max_rate'].unit == 'mA/s'
    assert 'no faster than' in f.explanation
    assert d.extra['judged_holdout']['n_samples'] == d.extra['judged_holdout']['n_holdout']
    assert d.final.er_holdout_percent < 5.0 * d.noise_floor_percent, d.report()


@pytest.mark.slow
def test_without_a_limit_nothing_is_claimed():
    """The same recording without the limit: no finding (seeds 0-3 x probes 0-2: 12/12)."""
    d = diagnose(_recording(0, None), settings=SETTINGS)
    assert d.findings == [], [f.mechanism for f in d.findings]
