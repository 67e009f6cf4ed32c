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

"""Issue 7: identification in any units, domains from the data, warnings.

One hysteresis shape (the paper's rig, test/conftest.py) recorded in three
unit systems: the command and the output are mapped affinely, so the noise
keeps the same size relative to the loop (0.5 % of the rig's RMS output,
scaled with the output) and the problems differ only in their units.
"""

from __future__ import annotations

from dataclasses import replace

from conftest import CALIBRATION, TRUE_PARAMS
import numpy as np
import pytest

from hyst_id.errors import ConfigError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec, PAPER_DOMAINS
from hyst_id.identification.domains import domains_from_data, preset_spec
from hyst_id.identification.gauge import affine_map_output
from hyst_id.identification.loop import (
    loop_orientation,
    measurement_sign,
    reversal_response,
    steepest_slope,
)
from hyst_id.identification.quality import (
    domain_edge_warnings,
    identification_warnings,
    orientation_warnings,
    poorly_determined_warnings,
)
from hyst_id.io.recording import Recording
from hyst_id.models.tk import simulate_hysteresis
from hyst_id.models.tk_lines import active_lines
from hyst_id.signals.noise import noise_floor_percent

#: (command scale a, command offset c, output span, output low) per unit system:
#: command a * v_mA + c, output mapped onto [low, low + span].
SCALES = {
    'piezo': (75.0, -675.0, 40.0, -20.0),     # +-150 V -> +-20 um
    'valve': (25.0, -175.0, 90.0, 0.0),       # 0-100 % -> 0-90 degrees
    'rig': (1.0, 0.0, None, None),            # the paper's mA rig, as recorded
}
UNITS = {'piezo': ('V', 'um'), 'valve': ('%', 'deg'), 'rig': ('mA', 'mm')}


def simulate_scaled(scale: str, channel: str = 'position', *, gain_sign: float = 1.0,
                    seed: int = 1) -> Recording:
    """Simulate the conftest recording of ``channel`` in another unit system."""
    spec = chain_spec(channel)
    t = np.arange(0.0, 100.0, 0.05)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    y0 = spec.simulate(TRUE_PARAMS[:spec.n_params], t, v, CALIBRATION[channel])
    a, c, span, low = SCALES[scale]
    g, h = (1.0, 0.0) if span is None else (span / np.ptp(y0), low - span / np.ptp(y0) * y0.min())
    g *= gain_sign
    sigma = 0.005 * np.sqrt(np.mean(y0 ** 2)) * abs(g)
    y = g * y0 + h + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    return Recording(t, a * v + c, y, channel, *UNITS[scale], f'simulated {scale}')


@pytest.fixture(scope='module')
def identified():
    """Identifications with default settings and data-derived domains, cached."""
    cache = {}

    def get(scale: str, channel: str = 'position'):
        if (scale, channel) not in cache:
            rec = simulate_scaled(scale, channel)
            spec = domains_from_data(rec)
            cache[scale, channel] = rec, spec, identify(rec, spec=spec,
                                                        settings=IdentifySettings())
        return cache[scale, channel]

    return get


def _ratios(rec, ident):
    return np.array([r.er_percent for r in ident.runs]) / noise_floor_percent(rec.measurement)


@pytest.mark.parametrize('scale', ['piezo', 'valve', 'rig'])
def test_any_units_reach_the_noise_floor_with_default_settings(identified, scale):
    """The core issue's criterion, no hand-set bounds: >= 9 of 10 seeds within 1.1 x floor."""
    rec, spec, ident = identified(scale)
    ratios = _ratios(rec, ident)
    assert np.sum(ratios <= 1.1) >= 9, f'{scale}: %e_r / floor per seed {np.round(ratios, 3)}'
    assert ident.domain_source == 'auto'
    assert ident.to_dict()['domain_source'] == 'auto'
    assert set(ident.to_dict()['domains']) == set(spec.names)


@pytest.mark.slow
@pytest.mark.parametrize('scale', ['piezo', 'valve', 'rig'])
def test_any_units_reach_the_noise_floor_pressure(identified, scale):
    rec, _, ident = identified(scale, 'pressure')
    ratios = _ratios(rec, ident)
    assert np.sum(ratios <= 1.1) >= 9, f'{scale}: %e_r / floor per seed {np.round(ratios, 3)}'


def test_same_shape_gives_the_same_loop_in_every_unit_system(identified):
    """The identified outputs agree once mapped back to the rig's units."""
    rec_rig, _, rig = identified('rig')
    y_rig = rig.spec().simulate(rig.x, rec_rig.t_s, rec_rig.command)
    for scale in ('piezo', 'valve'):
        rec, _, ident = identified(scale)
        y = ident.spec().simulate(ident.x, rec.t_s, rec.command)
        back = np.polyfit(rec.measurement, rec_rig.measurement, 1)   # exact affine map
        err = np.polyval(back, y) - y_rig
        assert np.sqrt(np.mean(err ** 2)) < 0.02 * np.ptp(y_rig), scale


@pytest.mark.parametrize('scale', ['piezo', 'valve', 'rig'])
def test_auto_domains_contain_the_true_chain_in_the_virtual_scale(scale):
    """The true loop, output mapped onto the command span around 0, has a twin inside."""
    rec = simulate_scaled(scale, 'pressure')
    spec = domains_from_data(rec)
    a, c = SCALES[scale][:2]
    x = TRUE_PARAMS[:12].copy()
    x[[0, 1, 2, 3]] /= a                              # slopes per command unit
    x[4] = a * x[4] + c                               # c_l, c_r in command units
    x[5] = a * x[5] + c
    x[6] -= x[2] * c                                  # c_t, c_b: intercepts at command 0
    x[7] -= x[3] * c
    t = rec.t_s
    s_true = chain_spec('pressure').signal(TRUE_PARAMS[:12], t, (rec.command - c) / a)
    lo, hi = s_true.min(), s_true.max()
    alpha = np.ptp(rec.command) / (hi - lo)
    x = affine_map_output(x, alpha, -alpha * 0.5 * (lo + hi))
    # The top line is never reached (as on the paper's rig): any c_t above the data
    # gives the same output, so lower it into the domain and check nothing changed.
    top = spec.names.index('c_t')
    x_in = x.copy()
    x_in[top] = min(x[top], spec.bounds[top, 1])
    np.testing.assert_allclose(spec.signal(x_in, t, rec.command),
                               spec.signal(x, t, rec.command), rtol=0, atol=1e-9 * np.ptp(s_true))
    inside = (x_in >= spec.bounds[:, 0]) & (x_in <= spec.bounds[:, 1])
    assert inside.all(), dict(zip(np.array(spec.names)[~inside], x_in[~inside]))
    assert spec.feasible(x_in[None, :])[0]


def test_given_domains_win_and_the_paper_preset_stays_available(simulated):
    rec, _ = simulated('pressure')
    spec = domains_from_data(rec, overrides={'tau_s': (0.1, 2.0)})
    assert spec.domain_source == 'auto+given'
    assert tuple(spec.bounds[spec.names.index('tau_s')]) == (0.1, 2.0)
    paper = preset_spec('paper', 'pressure')
    assert paper.domain_source == 'paper'
    np.testing.assert_array_equal(paper.bounds, [PAPER_DOMAINS[n] for n in paper.names])
    with pytest.raises(ConfigError, match='unknown domain preset'):
        preset_spec('lab', 'pressure')


@pytest.mark.parametrize('channel', ['pressure', 'flow'])
def test_sensor_domains_follow_timing(simulated, channel):
    rec, _ = simulated(channel)
    spec = domains_from_data(rec)
    half = spec.extra['half_period_s']
    assert 4.0 < half < 6.0                            # 10 s period
    bounds = dict(zip(spec.names, map(tuple, spec.bounds)))
    fast = replace(rec, t_s=rec.t_s / 100.0)           # same data, 100 x faster
    fast_bounds = dict(zip(spec.names, map(tuple, domains_from_data(fast).bounds)))
    if channel == 'flow':
        assert bounds['omega_n'][0] < 0.6 < bounds['omega_n'][1] <= np.pi / 0.05
        assert fast_bounds['omega_n'][1] == pytest.approx(100.0 * bounds['omega_n'][1])
    else:
        # four half periods (~4.8 s each): a sensor slower than the excitation is common
        assert bounds['tau_s'][0] == 0.0 and 0.5 < bounds['tau_s'][1] < 25.0
        assert fast_bounds['tau_s'][1] == pytest.approx(bounds['tau_s'][1] / 100.0)


def test_negative_gain_sensor_is_identified_and_reported():
    """A reading that falls as the output rises: identified with output sign -1."""
    rec = simulate_scaled('valve', gain_sign=-1.0)
    assert measurement_sign(rec) == -1
    spec = domains_from_data(rec)
    ident = identify(rec, spec=spec, settings=IdentifySettings(seeds=(0, 1, 2)))
    assert ident.output_sign == -1.0
    assert min(_ratios(rec, ident)) <= 1.1
    y_fit = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    assert np.sqrt(np.mean((y_fit - rec.measurement) ** 2)) < 0.03 * np.ptp(rec.measurement)


def test_unexcited_top_line_is_reported(identified):
    """As in the paper's Table 1: the command never drives the loop onto its top line."""
    rec, spec, ident = identified('rig')
    warnings = identification_warnings(ident, rec, spec)
    assert any('top line' in w and 'c_t' in w for w in warnings), warnings
    assert not any('edge of its search domain' in w for w in warnings), warnings


def test_active_lines_of_the_true_loop():
    rec = simulate_scaled('rig')
    masks = active_lines(TRUE_PARAMS[:8], rec.command,
                         simulate_hysteresis(TRUE_PARAMS[:8], rec.command))
    assert not masks['top'].any()                      # top-right corner at 15.3 mA
    for line in ('left', 'right', 'bottom', 'rising', 'falling'):
        assert masks[line].sum() > 10, line
    total = sum(m.astype(int) for m in masks.values())
    assert total.max() == 1                            # one line per sample


def test_narrow_domain_is_reported_on_its_edge(simulated):
    """tau_s has no gauge freedom: a domain that excludes the truth (0.5 s) binds.

    Four seeds: with two, one round-off probe in five stopped short of the best fit
    with tau_s 2 % inside the edge (%e_r 1.195 x the floor; four seeds reach 1.18 x with
    tau_s within 0.3 % of it under every probe tried).
    """
    rec, _ = simulated('pressure')
    spec = chain_spec('pressure', domains={'tau_s': (1.0, 20.0)})
    # GAASS and the refinement only: a bound that excludes the truth keeps the fit off the
    # floor, and the global phase spends two minutes on longer runs that end on the same
    # edge (passes in 4 s under probes 1-3 at 1e-12 and 4 at 1e-10)
    ident = identify(rec, spec=spec, settings=IdentifySettings(
        seeds=(0, 1, 2, 3), restarts=0, global_evals=0, hops=0))
    warnings = domain_edge_warnings(ident, rec, spec)
    assert any(w.startswith('tau_s sits on the lower edge') for w in warnings), warnings


def test_spread_over_seeds_marks_parameters_poorly_determined(identified):
    rec, _, ident = identified('rig')
    i = ident.names.index('m_b')
    runs = []
    for k, run in enumerate(ident.runs):
        x = run.x.copy()
        x[i] *= 1.0 + 0.3 * (-1) ** k                 # m_b spread +-30 %
        runs.append(replace(run, x=x))
    warnings = poorly_determined_warnings(replace(ident, runs=runs), rec)
    assert warnings and 'm_b (spread' in warnings[0], warnings


def _stop_operator_loop(n: int = 4000) -> Recording:
    """Simulate a friction force against displacement (clockwise, jumps after reversals)."""
    t = np.arange(n) * 0.01
    x_mm = 18.0 + 18.0 * np.sin(2 * np.pi * t / 8.0)
    force = np.empty(n)
    f = 0.0
    for j in range(n):
        f = np.clip(f + 50.0 * (x_mm[j] - x_mm[j - 1] if j else 0.0), -7.0, 7.0)
        force[j] = 148.0 + f
    force += np.random.default_rng(0).normal(0.0, 0.05, n)
    return Recording(t, x_mm, force, 'position', 'mm', 'N', 'stop operator')


def test_friction_loop_is_recognised():
    rec = _stop_operator_loop()
    assert loop_orientation(rec.command, rec.measurement) > 0.3        # clockwise
    assert measurement_sign(rec) == -1
    assert reversal_response(rec.command, -rec.measurement) == 1.0
    assert steepest_slope(rec) > 10.0
    warnings = orientation_warnings(rec, sign=-1.0)
    assert any('moves against the command' in w for w in warnings), warnings
    assert any('clockwise' in w for w in orientation_warnings(rec, sign=1.0))


def test_smooth_loop_is_not_flagged():
    rec = simulate_scaled('piezo')
    assert loop_orientation(rec.command, rec.measurement) < -0.05     # counter-clockwise
    assert orientation_warnings(rec) == []
    assert steepest_slope(rec) < 5.0


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_measurement_that_does_not_follow_the_command_is_said_so(seed):
    """A disconnected sensor (noise) fitted at '1.00 x the floor' is named, a response is not.

    A new user's pure-noise measurement was reported as a fit at the noise floor with a
    loop's parameters (found by an independent review): the floor comes from the
    measurement's own differences, so for noise the ratio means nothing.
    """
    from hyst_id.identification.quality import explained_share, response_warnings
    rng = np.random.default_rng(seed)
    t = np.arange(2000) * 0.05
    v = 10.0 + 8.0 * np.sin(2 * np.pi * 0.1 * t)
    noise = rng.standard_normal(t.size)
    flat = 100.0 * np.sqrt(np.mean((noise - noise.mean()) ** 2) / np.mean(noise ** 2))
    assert explained_share(flat, noise) == pytest.approx(0.0, abs=1e-9)
    words = response_warnings(0.999 * flat, noise)
    assert len(words) == 1 and 'does not follow the command' in words[0]
    follows = 0.5 * v + 3.0 + rng.normal(0.0, 0.5, t.size)     # signal std 2.8 x the noise
    fit = 100.0 * np.sqrt(np.mean((follows - 0.5 * v - 3.0) ** 2) / np.mean(follows ** 2))
    assert response_warnings(fit, follows) == []


@pytest.mark.parametrize('offset, named', [(1000.0, True), (-300.0, True), (30.0, False)])
def test_an_offset_far_from_zero_says_what_er_reads(offset, named):
    """%e_r (Eq. 7) divides by the RMS about zero: far from zero the error is also in units.

    An independent reviewer's reading of 1000 kPa swinging by about 100 was fitted to
    0.5 % of its span and reported as %e_r 0.046 with nothing said.
    """
    from hyst_id.signals.noise import offset_words
    t = np.arange(2000) * 0.05
    y = offset + 48.0 * np.sin(2 * np.pi * 0.1 * t)
    e = np.random.default_rng(3).normal(0.0, 0.48, t.size)      # 0.5 % of the span
    er = 100.0 * np.sqrt(np.mean(e ** 2) / np.mean(y ** 2))
    words = offset_words(er, y, 'kPa')
    if not named:
        assert words == ''
        return
    rms = float(np.sqrt(np.mean(e ** 2)))
    assert (f"the best run's RMS error is {rms:.3g} kPa, {100 * rms / np.ptp(y):.3g} % of the "
            'span') in words, words
    assert f'mean {np.mean(y):.4g} kPa against a span of {np.ptp(y):.4g} kPa' in words
