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

"""The measured loop's direction, width and rate signature, from the data alone.

Recordings made apart from the package: the paper's loop by the independent
reference simulator (``test/reference_sim``), Dahl friction by explicit Euler
steps (``test/friction_reference.py``), a viscous and a Coulomb force in closed
form; random excitations and gains over seeds; and the real recordings of
``../shared/data`` (the cylinder's force runs clockwise against its
displacement, the B(H) loops counter-clockwise).
"""

from __future__ import annotations

from pathlib import Path

from friction_reference import euler_dahl
import numpy as np
from play_reference import play
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis.measured_loop import measured_loop
from hyst_id.errors import RecordingError

__all__: list[str] = []

DATA = Path(__file__).resolve().parents[3] / 'shared' / 'data'
SEEDS = range(8)


def _excitation(rng: np.random.Generator, n: int = 2000, dt_s: float = 0.02):
    """A random multisine around mid travel (7-11 mA), with a random slow envelope."""
    t = np.arange(n) * dt_s
    v = 9.0 + np.zeros(n)
    for _ in range(rng.integers(2, 5)):
        v += rng.uniform(0.3, 1.2) * np.sin(2 * np.pi * t / rng.uniform(2.0, 12.0)
                                            + rng.uniform(0, 2 * np.pi))
    return t, np.clip(v, 6.5, 11.5)


def _triangles(spans, periods_s, dt_s: float = 0.01):
    """Triangle sweeps from 0, one per (span, period), one after another."""
    parts = []
    for span, period in zip(spans, periods_s):
        k = int(round(period / dt_s / 2))
        parts += [np.linspace(0.0, span, k, endpoint=False),
                  np.linspace(span, 0.0, k, endpoint=False)]
    v = np.concatenate(parts)
    return np.arange(v.size) * dt_s, v


def papers_chain(v: np.ndarray) -> np.ndarray:
    """The paper's H then B, by the reference simulator, at fixed parameters."""
    return backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                    -0.15, 0.15)


def papers_loop_case(seed: int):
    """A random multisine through the paper's chain, a random gain of either sign, noise."""
    rng = np.random.default_rng(seed)
    t, v = _excitation(rng)
    gain = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 50.0)
    y = gain * papers_chain(v) + rng.uniform(-10, 10)
    return t, v, y + rng.normal(0.0, 0.005 * np.ptp(y), t.size), gain


def staircase_case(seed: int):
    """Random steps held 1 s through the paper's chain, a random gain of either sign."""
    rng = np.random.default_rng(seed)
    v = np.repeat(rng.uniform(6.5, 11.5, 60), 50)
    gain = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 50.0)
    x = papers_chain(v)
    y = gain * x + rng.normal(0.0, 0.005 * abs(gain) * np.ptp(x), v.size)
    return np.arange(v.size) * 0.02, v, y, gain


def dahl_case(seed: int):
    """A random multisine on a spring with a Dahl friction force of random size."""
    rng = np.random.default_rng(seed)
    t, v = _excitation(rng)
    force = rng.uniform(0.05, 0.4) * np.ptp(v)
    y = 2.0 * v + force * euler_dahl(v, 0.01 * np.ptp(v), substeps=50)
    return t, v, y + rng.normal(0.0, 0.005 * np.ptp(y), t.size), force


def noisy_sine_case(seed: int, noise_share: float):
    """A unit sine measured with noise of ``noise_share`` of its span; the clean sine; noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(4000) * 0.01
    clean = np.sin(2 * np.pi * t / 8.0)
    v = clean + rng.normal(0.0, 2.0 * noise_share, t.size)
    return t, v, clean, rng.normal(0.0, 0.01, t.size)


@pytest.mark.parametrize('seed', SEEDS)
def test_the_papers_loop_runs_counter_clockwise_in_either_sign(seed):
    t, v, y, gain = papers_loop_case(seed)
    loop = measured_loop(t, v, y)
    assert loop.direction == 'counter-clockwise', loop
    assert loop.rises_with_command == (gain > 0)
    # measured over seeds 0-29: 4.1-9.8 % of the span (bench/measured_loops.py --spreads)
    assert 0.02 < loop.half_width_share < 0.2, loop
    assert 'counter-clockwise' in loop.words()


@pytest.mark.parametrize('seed', SEEDS)
def test_a_staircase_command_traces_the_papers_loop_too(seed):
    # random steps held 1 s: the holds inside a sweep keep the sweep's direction
    t, v, y, gain = staircase_case(seed)
    loop = measured_loop(t, v, y)
    assert loop.direction == 'counter-clockwise', loop
    assert loop.rises_with_command == (gain > 0)
    # measured over seeds 0-29: 2.4-8.5 % of the span (bench/measured_loops.py --spreads);
    # a thin loop is below 0.5 %
    assert loop.half_width_share > 0.01, loop


def last_bits_moved(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``x`` with up to 4 units in the last place changed per sample (another CPU's sums)."""
    return x * (1.0 + rng.integers(-4, 5, x.size) * np.finfo(float).eps)


@pytest.mark.parametrize('seed', SEEDS)
def test_a_last_bit_change_moves_nothing(seed):
    # held steps repeat one value exactly: moved last bits must not split them across bins
    # (before, the staircase's half-width moved by up to 10 %)
    for case in (staircase_case, papers_loop_case, dahl_case):
        t, v, y, _ = case(seed)
        a = measured_loop(t, v, y)
        rng = np.random.default_rng(seed)
        b = measured_loop(*(last_bits_moved(x, rng) for x in (t, v, y)))
        assert (a.direction, a.rises_with_command) == (b.direction, b.rises_with_command)
        # measured: at most 1.9e-13 relative over 450 runs (bench/measured_loops.py --spreads)
        assert b.half_width == pytest.approx(a.half_width, rel=1e-9, abs=0.0), case


@pytest.mark.parametrize('seed', SEEDS)
def test_a_friction_force_on_the_travel_runs_clockwise_with_its_size(seed):
    t, v, y, force = dahl_case(seed)
    loop = measured_loop(t, v, y)
    assert loop.direction == 'clockwise', loop
    # measured over seeds 0-29: 0.79-0.89 of the force (the multisine's minor sweeps
    # and the levels next to a reversal see the presliding); never above the force
    assert 0.7 * force < loop.half_width < 1.0 * force, (loop.half_width, force)


@pytest.mark.parametrize('seed', SEEDS)
def test_a_friction_band_with_no_spring_reads_clockwise_as_recorded(seed):
    # no mid-line slope to set the frame: the force is read as recorded, not mirrored
    rng = np.random.default_rng(seed)
    t, v = _triangles([10.0] * 6, [4.0] * 6)
    force = rng.uniform(0.5, 5.0)
    y = force * np.sign(np.gradient(v, t)) + rng.normal(0.0, 0.02 * force, t.size)
    loop = measured_loop(t, v, y)
    assert loop.direction == 'clockwise' and loop.rises_with_command, loop
    assert loop.half_width == pytest.approx(force, rel=0.05)
    assert 'clockwise' in loop.words('force') and '-force' not in loop.words('force')


def _ramp_and_hold(noise: float, rng: np.random.Generator):
    """Ramps 0-10 in 1 s, each followed by a 6 s hold at the extreme, five times."""
    up = np.linspace(0.0, 10.0, 100, endpoint=False)
    down = np.linspace(10.0, 0.0, 100, endpoint=False)
    v = np.tile(np.r_[up, np.full(600, 10.0), down, np.full(600, 0.0)], 5)
    return np.arange(v.size) * 0.01, v + rng.normal(0.0, noise, v.size), v


@pytest.mark.parametrize('command_noise', [0.0, 0.01])
def test_holds_at_the_reversals_make_no_loop_and_keep_a_real_one(command_noise):
    # the holds sit at the extremes: they keep the direction that brought them there
    rng = np.random.default_rng(1)
    t, v, clean = _ramp_and_hold(command_noise, rng)
    single = measured_loop(t, v, clean + rng.normal(0.0, 0.02, t.size))
    assert single.direction == 'thin', single
    band = clean + np.sign(np.gradient(clean, t)) * 0.5 + rng.normal(0.0, 0.02, t.size)
    loop = measured_loop(t, v, band)
    assert loop.direction == 'clockwise'
    assert loop.half_width == pytest.approx(0.5, rel=0.1)


@pytest.mark.parametrize('noise_share', [0.005, 0.01, 0.02, 0.05])
@pytest.mark.parametrize('seed', range(3))
def test_a_noisy_measured_command_keeps_the_direction(noise_share, seed):
    # noise on the command of 0.5-5 % of its span (a measured displacement): reversals
    # need a move beyond 6 x that noise, else noise turns make up sweeps
    t, v, clean, e = noisy_sine_case(seed, noise_share)
    band = measured_loop(t, v, clean + 0.3 * np.sign(np.gradient(clean, t)) + e)
    lag = measured_loop(t, v, play(clean, 0.3, clean[0]) + e)
    assert band.direction == 'clockwise', band
    # measured over seeds 0-9: 0.28-0.296 (bench/measured_loops.py --spreads)
    assert band.half_width == pytest.approx(0.3, rel=0.1)
    assert lag.direction == 'counter-clockwise', lag
    if noise_share <= 0.02:
        # at 5 % the blurred levels leave up to 0.73 % of the span: not asserted
        assert measured_loop(t, v, clean + e).direction == 'thin'


@pytest.mark.parametrize('dead_band', [0.5, 0.8, 0.9])
def test_a_negative_gain_play_near_its_dead_band_is_negated(dead_band):
    # swung 1.11-2 x past its dead band, the play's mid-line is flat between its tips:
    # the tips' fall sets the frame (at 1.05 x it does not: documented)
    t = np.arange(4000) * 0.01
    v = np.sin(2 * np.pi * t / 8.0)
    loop = measured_loop(t, v, -play(v, dead_band, v[0]))
    assert loop.direction == 'counter-clockwise' and not loop.rises_with_command, loop


def test_a_falling_measurement_is_read_negated_and_said_so():
    t, v = _triangles([10.0] * 6, [4.0] * 6)
    loop = measured_loop(t, v, -(v + np.sign(np.gradient(v, t))))
    assert loop.direction == 'clockwise' and not loop.rises_with_command
    words = loop.words('force', 'N')
    assert 'read as -force' in words and 'the -force leads the motion' in words


def test_rate_signature_tells_a_band_from_viscous_drag_at_equal_spans():
    t, v = _triangles([10.0] * 6, [4.0, 12.0] * 3)
    rng = np.random.default_rng(0)
    rate = np.gradient(v, t)
    noise = rng.normal(0.0, 0.02, t.size)
    band = measured_loop(t, v, v + 1.0 * np.sign(rate) + noise)
    drag = measured_loop(t, v, v + 0.5 * rate + noise)
    assert band.rates_comparable and drag.rates_comparable
    assert band.direction == drag.direction == 'clockwise'
    assert band.grows_with_rate is False and band.half_width == pytest.approx(1.0, abs=0.05)
    assert drag.grows_with_rate is True
    assert drag.half_width_fast == pytest.approx(3 * drag.half_width_slow, rel=0.1)
    assert 'rate independent' in band.words() and 'grows with the rate' in drag.words()


def test_sweeps_of_other_spans_are_not_compared_for_rate():
    # larger sweeps at the higher rate, as in loops of growing amplitude
    t, v = _triangles([2.0, 10.0] * 3, [4.0, 4.0] * 3)
    loop = measured_loop(t, v, v - 0.3 * np.sign(np.gradient(v, t)))
    assert loop.direction == 'counter-clockwise'
    assert not loop.rates_comparable and loop.grows_with_rate is None
    assert 'not compared' in loop.words()


def test_a_single_valued_curve_is_thin_and_a_ramp_traces_no_loop():
    rng = np.random.default_rng(3)
    t, v = _excitation(rng)
    curve = measured_loop(t, v, 0.1 * v ** 2 + rng.normal(0.0, 0.01, t.size))
    assert curve.direction == 'thin' and 'thin' in curve.words()
    ramp = measured_loop(t, t, 2 * t)
    assert ramp.direction == 'thin' and np.isnan(ramp.half_width)
    assert 'no loop' in ramp.words()


def test_too_few_samples_a_flat_measurement_and_bad_input_are_said():
    t = np.arange(40.0)
    v = np.r_[np.linspace(0.0, 1.0, 20), np.linspace(1.0, 0.0, 20)]
    once = measured_loop(t, v, v + 0.2 * np.sign(np.gradient(v)))
    assert np.isnan(once.half_width) and 'too few samples' in once.words()
    t, v = _triangles([10.0] * 6, [4.0] * 6)
    flat = measured_loop(t, v, np.zeros(t.size))
    assert flat.direction == 'thin' and 'nan' not in flat.words()
    y = v.copy()
    y[5] = np.nan
    with pytest.raises(RecordingError, match='NaN'):
        measured_loop(t, v, y)
    with pytest.raises(RecordingError, match='shape'):
        measured_loop(t, v[:-1], v)


def _need(path: Path) -> Path:
    if not path.is_file():
        pytest.skip(f'{path} not found: the shared data sit beside the repository')
    return path


@pytest.mark.parametrize('bar', [1, 3, 7])
def test_the_cylinders_force_runs_clockwise_against_its_displacement(bar):
    raw = np.loadtxt(_need(DATA / 'pneumatic-cylinder-friction' / f'Circle_{bar}bar.csv'))
    loop = measured_loop(raw[:, 0] / 1000.0, raw[:, 4], raw[:, 6])
    assert loop.direction == 'clockwise' and loop.rises_with_command
    # measured: 5.37, 7.23 and 10.5 N (the friction band grows with the pressure)
    assert 4.0 < loop.half_width < 13.0
    # the strokes run at nearly one speed: the rate signature is not claimed
    assert loop.grows_with_rate is None


@pytest.mark.parametrize('name', ['M130_27s_steel', 'MnZn_ferrite'])
def test_bh_loops_run_counter_clockwise(name):
    raw = np.loadtxt(_need(DATA / 'magnetic-bh-loops' / f'{name}.csv'), delimiter=',',
                     skiprows=1)
    order = np.lexsort((raw[:, 1], raw[:, 0]))
    loop = measured_loop(np.arange(order.size, dtype=float), raw[order, 2], raw[order, 3])
    assert loop.direction == 'counter-clockwise' and loop.rises_with_command
    # loops of growing amplitude: their faster sweeps are the larger ones
    assert loop.grows_with_rate is None
