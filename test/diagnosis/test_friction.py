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

"""``friction``: a force band reversing with the motion (issue 14, item 1).

The recordings are made apart from the package: the paper's chain by the
independent reference simulator (``test/reference_sim``), and on its travel a
force that leads the motion, Dahl's friction integrated here by explicit Euler
steps a hundredth of a sample long (the package steps the exact exponential
solution), as a drive moved through a seal reads it.
"""

from __future__ import annotations

from bouc_wen_reference import bouc_wen_recording
from friction_reference import euler_dahl
import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.export import compensator_set
from hyst_id.diagnosis.mechanisms.friction import dahl_state
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.io.recording import Recording

SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1, hops=20)

#: The recordings' friction force (share of the reading's span) and presliding travel
#: (share of the travel).
FORCE_SHARE, PRESLIDING_SHARE = 0.08, 0.03
#: The reading's gain and offset on the travel (um per mA-eq, um).
GAIN, OFFSET = 25.0, -40.0


def friction_recording(seed: int) -> tuple[Recording, float, float]:
    """Two decaying sines through the chain, plus the friction force; 2,000 samples.

    Returns the recording, the friction force (um) and the presliding travel (mA-eq).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(2000) * 0.02
    v = (9.0 + 2.0 * np.sin(2 * np.pi * t / rng.uniform(6.0, 10.0)) * (1.0 - 0.3 * t / t[-1])
         + 0.3 * np.sin(2 * np.pi * t / rng.uniform(2.0, 3.0) + rng.uniform(0, 6)))
    x = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                 -0.15, 0.15)
    force = FORCE_SHARE * GAIN * np.ptp(x)
    length = PRESLIDING_SHARE * np.ptp(x)
    y = GAIN * x + OFFSET + force * euler_dahl(x, length, substeps=100)
    y = y + rng.normal(0.0, 0.003 * np.ptp(y), t.size)
    return Recording(t, v, y, 'position', 'mA', 'um', f'friction #{seed}'), force, length


def test_dahl_state_is_the_exact_solution_and_rate_independent():
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(0.0, 0.05, 400))
    z = dahl_state(x, 0.2)
    assert np.max(np.abs(z - euler_dahl(x, 0.2, substeps=2000))) < 2e-3
    assert np.all(np.abs(z) <= 1.0)
    # the same path sampled ten times more finely (linear in between) ends in the same states
    fine = np.interp(np.arange(0, x.size - 1 + 1e-9, 0.1), np.arange(x.size), x)
    assert np.allclose(dahl_state(fine, 0.2)[::10], z, atol=1e-9)
    # holding still changes nothing
    held = np.repeat(x, 3)
    assert np.allclose(dahl_state(held, 0.2)[::3], z, atol=1e-12)


def test_a_band_lagging_a_sloped_reading_is_the_hysteresis_not_friction():
    m = MECHANISMS['friction']
    labels = ['sensor', 'friction:0', 'offset']
    span = (0.0, 1.0)
    # the reading rises 10 units over the travel; a band of 1 leading it is friction
    assert m.implausible(np.array([0.03]), np.array([10.0, 1.0, 0.0]), span, 0.01,
                         labels=labels) == ''
    # the same band lagging it runs the hysteresis's way (backlash)
    assert 'lags the motion' in m.implausible(np.array([0.03]), np.array([10.0, -1.0, 0.0]),
                                              span, 0.01, labels=labels)
    # on a reading that hardly changes over the travel the band is the loop, either sense
    assert m.implausible(np.array([0.03]), np.array([0.5, -1.0, 0.0]), span, 0.01,
                         labels=labels) == ''
    # the boundary: a lagging band is refused once the reading changes by more than its
    # height (twice the force) over the travel, on any travel span
    for span, gain in (((0.0, 1.0), 1.9), ((0.0, 1.0), 2.1), ((7.0, 11.0), 0.55)):
        reason = m.implausible(np.array([0.03]), np.array([gain, -1.0, 0.0]), span, 0.01,
                               labels=labels)
        assert bool(reason) == (gain * (span[1] - span[0]) > 2.0), (span, gain, reason)
    # with a static curve the basis is z in [-1, 1]: the change is the curve's, 2 (c1 + c3)
    curved = ['sensor', 'quantity:1', 'quantity:2', 'friction:0', 'offset']
    assert m.implausible(np.array([0.03]), np.array([0.9, 0.3, 0.2, -1.0, 0.0]), (7.0, 11.0),
                         0.01, labels=curved)          # 2.2 > 2: lagging and sloped
    assert not m.implausible(np.array([0.03]), np.array([0.9, 0.3, 0.0, -1.0, 0.0]),
                             (7.0, 11.0), 0.01, labels=curved)     # 1.8: nearly flat
    # a band below the noise is none
    assert 'below the measurement noise' in m.implausible(
        np.array([0.03]), np.array([0.5, 0.005, 0.0]), span, 0.01, labels=labels)


def test_friction_is_registered_with_words():
    m = MECHANISMS['friction']
    assert m.stage == 'quantity' and m.n_linear == 1 and m.compensation == 'not in-line'
    assert 'seal' in m.physics


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_force_band_with_the_motion_is_friction(seed):
    """Named with its force and presliding travel, and the held-out error at the floor.

    The presliding travel is reported in command units: the chain's right line and
    backlash move the travel 1.05 x the command there, so the truth is
    ``length / 1.05``. Measured on seeds 0-5 (``python bench/friction_spread.py``):
    named 6/6, force 0.997-1.004 x the truth, presliding 0.995-1.014 x, final held-out
    0.91-1.08 x the floor; seeds 0-2 under round-off probes 1 and 2 the same to three
    digits. The bounds sit outside that. The compensator set is written (friction is
    not in-line).
    """
    rec, force, length = friction_recording(seed)
    d = diagnose(rec, settings=SETTINGS)
    assert d.verdict == 'friction', d.report()
    values = d.findings[0].params
    assert values['friction_force'].value == pytest.approx(force, rel=0.03)
    assert values['friction_force'].unit == 'um'
    assert values['presliding'].value == pytest.approx(length / 1.05, rel=0.04)
    assert values['higher_while_rising'].value == 1.0
    assert values['leads_motion'].value == 1.0
    assert 'sliding-friction force' in d.findings[0].explanation
    assert d.final.er_holdout_percent < 1.3 * d.noise_floor_percent, d.report()
    _, _, applied = compensator_set(d)
    assert dict(applied)['friction'].startswith('no in-line correction'), applied


def flat_friction_recording(seed: int) -> Recording:
    """A force hardly changing with the displacement, plus friction (a cylinder moved by hand).

    The paper's loop cannot make the straight line under the band exactly (its loop
    only thins towards it), so the fit of the line is left to the chain's polish.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(2000) * 0.02
    x = (5.0 + 4.0 * np.sin(2 * np.pi * t / rng.uniform(6.0, 10.0)) * (1.0 - 0.3 * t / t[-1])
         + 0.5 * np.sin(2 * np.pi * t / rng.uniform(2.0, 3.0) + rng.uniform(0, 6)))
    force = 20.0 + 0.3 * x + 2.0 * euler_dahl(x, 0.15, substeps=100)
    return Recording(t, x, force + rng.normal(0.0, 0.02, t.size), 'position', 'mm', 'N',
                     f'flat friction #{seed}')


@pytest.mark.slow
def test_a_band_on_a_flat_force_is_friction():
    """Named with its force, in either sense (the reading has no slope to compare with).

    Measured on seeds 0-5 and on seeds 0-1 under round-off probes 1 and 2
    (``python bench/friction_spread.py``): named
    10/10, force 1.973-2.003 N (true 2.0). Where the polish leaves the straight line
    under the band moves with round-off (final held-out 1.04-1.47 x the floor
    unperturbed, up to 4.0 x under the probes), so it is not asserted here.
    """
    d = diagnose(flat_friction_recording(0), settings=SETTINGS)
    assert d.verdict == 'friction', d.report()
    assert d.findings[0].params['friction_force'].value == pytest.approx(2.0, rel=0.03)
    assert d.findings[0].params['friction_force'].unit == 'N'
    compensator_set(d)          # H and B are written; the force is left to a feed-forward


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_bouc_wen_restoring_force_is_friction(seed):
    """A Bouc-Wen restoring force (clockwise against its displacement) is named with its band.

    A new-user trial's simulator made this loop and counted ``friction`` a miss: a
    sliding element in parallel with a spring makes it, and ``z`` saturates at 1, so
    the band is ±0.7 (``test/bouc_wen_reference.py``). Measured (seeds 0-2,
    ``python bench/bouc_wen_forms.py``): force 0.699-0.702 N, final held-out 2.18-2.55 x
    the floor (Bouc-Wen's turn-round after a reversal is not Dahl's exponential one).
    """
    d = diagnose(bouc_wen_recording(seed, 'force'), settings=SETTINGS)
    assert d.verdict == 'friction', [f.mechanism for f in d.findings]
    p = d.findings[0].params
    assert p['friction_force'].value == pytest.approx(0.7, rel=0.05)
    assert p['higher_while_rising'].value == 1.0
    assert d.final.er_holdout_percent < 3.5 * d.noise_floor_percent
