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

"""The section 4 experiment: definitions, a quick end-to-end run, the paper's numbers (slow)."""

from __future__ import annotations

from dataclasses import replace
import json
from pathlib import Path

import numpy as np
import pytest

from hyst_id.cli import main
from hyst_id.commands.experiment import QUICK_DIAGNOSIS, QUICK_SETTINGS
from hyst_id.compensation import CommandLimits, Compensator, InverseModel
from hyst_id.errors import ConfigError
from hyst_id.experiment.report import format_markdown, headline, PAPER, write_outputs
from hyst_id.experiment.result import Calibration, CHANNELS, MODES
from hyst_id.experiment.run import (
    eps_c_percent,
    fit_position_calibration,
    ideal_actuator_params,
    run_experiment,
    to_backlash_gauge,
    to_position_units,
)
from hyst_id.identification import IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.gauge import canonical_gauge
from hyst_id.models.sensors import simulate_first_order
from hyst_id.rig import load_rig_params, simulate_rig
from hyst_id.signals.excitation import eq24, eq25

PARAMS = Path(__file__).resolve().parents[2] / 'params' / 'paper_rig.yaml'
RIG_X = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.10, 0.54, 1.09])


def _t_v():
    t = np.arange(0.0, 100.0, 0.05)
    return t, eq24(t)


def test_backlash_gauge_is_the_inverse_of_the_canonical_gauge():
    x = canonical_gauge(RIG_X)
    np.testing.assert_allclose(to_backlash_gauge(x, 1.10, 0.815), RIG_X, atol=1e-12)
    t, v = _t_v()
    pos = chain_spec('position', calibration=(1.0, 0.0))
    np.testing.assert_allclose(pos.simulate(to_backlash_gauge(x, 2.0, -0.3), t, v),
                               pos.simulate(RIG_X, t, v), atol=1e-9)


def test_position_units_map_undoes_the_calibration():
    """A reading ``k position + b`` (k < 0) identified in its own units maps back."""
    t, v = _t_v()
    pos = chain_spec('position', calibration=(1.0, 0.0))
    k, b = -4.0e4, 7.0e5
    x_canon = canonical_gauge(RIG_X, (k, b))          # H in (negated) reading units
    reading = -pos.simulate(x_canon, t, v)            # output_sign -1
    np.testing.assert_allclose(reading, k * pos.simulate(RIG_X, t, v) + b, rtol=1e-10)
    x_pos = to_position_units(x_canon, -1.0, Calibration('pressure', k, b))
    np.testing.assert_allclose(pos.simulate(x_pos, t, v), pos.simulate(RIG_X, t, v),
                               atol=1e-8)
    np.testing.assert_allclose(x_pos, canonical_gauge(RIG_X), atol=1e-9)


def test_calibration_recovers_gain_offset_and_lag():
    t, v = _t_v()
    position = chain_spec('position', calibration=(1.0, 0.0)).simulate(RIG_X, t, v)
    rng = np.random.default_rng(3)
    reading = -5.0e4 * simulate_first_order(position, t, 1.4) + 7.5e5
    reading += rng.normal(0.0, 300.0, t.size)
    cal = fit_position_calibration('pressure', t, position, reading)
    assert cal.k == pytest.approx(-5.0e4, rel=1e-3)
    assert cal.b == pytest.approx(7.5e5, rel=1e-3)
    assert cal.dynamics['tau_s'] == pytest.approx(1.4, rel=1e-2)
    np.testing.assert_allclose(cal.to_position(cal.from_position(position)), position)
    assert fit_position_calibration('position', t, position, position).k == 1.0


@pytest.mark.parametrize('law', ['exponential', 'linear', 'offset'])
def test_calibration_with_a_drift_holds_at_the_run_start(law):
    """(b)'s calibration: the drift fitted with it, the start's k and b returned."""
    t, v = _t_v()
    position = chain_spec('position', calibration=(1.0, 0.0)).simulate(RIG_X, t, v)
    s = simulate_first_order(position, t, 1.4)
    el = t - t[0]
    if law == 'offset':
        reading = -5.0e4 * s + 7.5e5 - 300.0 * el
    else:
        g = np.exp(-0.004 * el) if law == 'exponential' else 1.0 - 0.003 * el
        reading = g * (-5.0e4 * s + 2.0e5) + 5.5e5
    reading = reading + np.random.default_rng(4).normal(0.0, 300.0, t.size)
    cal = fit_position_calibration('pressure', t, position, reading, gain_law=law)
    assert cal.k == pytest.approx(-5.0e4, rel=3e-3) and cal.b == pytest.approx(7.5e5, rel=1e-3)
    assert cal.dynamics['tau_s'] == pytest.approx(1.4, rel=2e-2)
    rate = {'offset': ('offset_rate_per_s', -300.0), 'exponential': ('gain_rate_per_s', 0.004),
            'linear': ('gain_rate_per_s', -0.003)}[law]
    assert cal.dynamics[rate[0]] == pytest.approx(rate[1], rel=3e-2)
    plain = fit_position_calibration('pressure', t, position, reading)
    assert abs(plain.b - 7.5e5) > 10 * abs(cal.b - 7.5e5)     # the average, not the start
    with pytest.raises(ConfigError, match='gain law'):
        fit_position_calibration('pressure', t, position, reading, gain_law='cubic')


def test_ideal_actuator_follows_the_command_with_regulated_supply():
    rig = ideal_actuator_params(load_rig_params(PARAMS))
    assert rig.supply.regulation
    t = np.arange(121) * 0.5
    run = simulate_rig(rig, t, eq25(t))
    assert np.max(np.abs(run.truth['position_true'] - eq25(t))) < 1e-8


def test_eps_c_is_eq26_measured_from_an_offset():
    w_ud = np.array([10.0, 12.0, 10.0, 8.0])
    w_c = w_ud + np.array([1.0, -1.0, 1.0, -1.0])
    assert eps_c_percent(w_c, w_ud) == pytest.approx(100 * np.sqrt(4 / np.sum(w_ud ** 2)))
    assert eps_c_percent(w_c, w_ud, offset=10.0) == pytest.approx(100 * np.sqrt(4 / 8))
    # A gain cancels: the position-equivalent value only depends on the offset.
    assert eps_c_percent(-3 * w_c + 5, -3 * w_ud + 5, offset=-25.0) == pytest.approx(
        eps_c_percent(w_c, w_ud, offset=10.0))


@pytest.fixture(scope='module')
def quick():
    settings = replace(QUICK_SETTINGS, workers=2)
    return run_experiment(PARAMS, settings=settings, seeds=1, regulation=(False,),
                          adaptive=True, diagnose_settings=QUICK_DIAGNOSIS)


def test_quick_run_has_the_augmented_and_tracking_columns(quick):
    """Issue 17's (b) and (c) for every channel, with what the diagnosis became."""
    sc = quick.scenarios['off']
    for (mode, ch), r in sc.channels.items():
        a = r.adaptive
        assert a is not None and a.augmented_from in ('diagnosis', 'identification')
        assert np.isfinite(a.eps_c_augmented_percent) and np.isfinite(a.eps_c_tracking_percent)
        assert all(h.startswith(('in-line', 'no in-line', 'not applied'))
                   for _, h in a.applied)
        assert np.all((a.command_augmented_ma >= 4.0) & (a.command_augmented_ma <= 20.0))
        # nothing is worse than no compensation at all: (b) 0.31 / 2.12 / 4.53 against
        # uncompensated 4.64 / 8.56 / 5.48 (position / pressure / flow) in the default run
        # (`hyst-id experiment`, RESULTS.md)
        assert a.eps_c_augmented_percent < sc.eps_unc_percent[ch], (mode, ch)
    text = format_markdown(quick)
    assert '(b) augmented' in text and '(c) tracking' in text
    doc = json.loads(json.dumps(quick.to_dict()))
    assert doc['scenarios']['off']['results']['refined']['pressure']['adaptive'][
        'augmented_from'] in ('diagnosis', 'identification')


def test_quick_run_compensation_beats_no_compensation_on_every_channel(quick):
    """Each channel's own error falls; the position follows for position and pressure.

    Not for flow from one seed: its chain is the poorest identified (RESULTS.md), and the
    position its H⁻¹ places depends on which basin the one seed ends in (measured: rms
    0.28 mA-eq GAASS-only and 0.62 refined against 0.42 uncompensated, while %ε_c falls
    in both; another run of the same code ended below 0.42), so that assertion rested
    on the last bits of a sum.
    """
    sc = quick.scenarios['off']
    assert set(sc.channels) == {(m, c) for m in MODES for c in CHANNELS}
    for (mode, ch), r in sc.channels.items():
        assert r.eps_c_percent < sc.eps_unc_percent[ch], (mode, ch)
        assert r.eps_c_raw_percent < sc.eps_unc_raw_percent[ch], (mode, ch)
        if ch != 'flow':
            assert r.position_rms_error < sc.position_rms_error_unc, (mode, ch)
        assert np.all((r.command_ma >= 4.0) & (r.command_ma <= 20.0))
        assert not r.top_line_reached or ch != 'position'  # Eq. 24 never reaches c_t
    assert sc.channels[('refined', 'position')].eps_c_percent < 1.0
    # Calibrated pressure and flow: opening the valve lowers p1 and raises the flow.
    assert sc.calibrations['pressure'].k < 0 < sc.calibrations['flow'].k


def test_quick_run_desired_value_in_channel_units_is_consistent(quick):
    """H^-1 in pressure units with ``k u_d + b`` == H^-1 in position units with ``u_d``."""
    sc = quick.scenarios['off']
    r = sc.channels[('refined', 'pressure')]
    u_d = sc.uncompensated.command_ma
    cmd = Compensator(InverseModel.from_vector(r.x_position), CommandLimits(4.0, 20.0),
                      v0=4.0).run(u_d)
    np.testing.assert_allclose(cmd, r.command_ma, atol=1e-7)
    np.testing.assert_allclose(r.desired, sc.calibrations['pressure'].from_position(u_d))


def test_quick_run_writes_json_tables_and_figures(quick, tmp_path):
    paths = write_outputs(quick, tmp_path, command='hyst-id experiment --quick', fig2=False)
    for name in ('json', 'markdown', 'fig4', 'position', 'pressure', 'flow'):
        assert paths[name].is_file() and paths[name].stat().st_size > 0, name
    data = json.loads(paths['json'].read_text())
    assert data['paper']['eps_c_percent']['flow'] == 38.87
    assert set(data['scenarios']['off']['results']) == set(MODES)
    text = format_markdown(quick)
    assert 'Table 1' in text and '%ε_c' in text and 'n.i.' in text
    assert len(headline(quick)) == len(MODES) * len(CHANNELS)


def test_cli_gaass_only_quick(tmp_path, capsys):
    out = tmp_path / 'exp'
    figs = tmp_path / 'figs'
    code = main(['experiment', '--params', str(PARAMS), '--out', str(out), '--quick',
                 '--gaass-only', '--seeds', '1', '--no-fig2', '--quiet', '--no-adaptive',
                 '--copy-figures', str(figs)])
    assert code == 0
    assert (out / 'results.json').is_file() and (figs / 'fig6_pressure.png').is_file()
    out_text = capsys.readouterr().out
    assert 'GAASS only' in out_text and '(b) augmented' not in out_text


@pytest.mark.slow
@pytest.mark.thorough
def test_paper_settings_beat_all_six_paper_numbers():
    """Ten seeds, 500 generations, N_pop 10 (the paper's settings), regulation off.

    The paper's GAASS with the refinement, without identify's global phase and hopping
    (the package's additions for recordings it did not make): the paper's numbers are
    beaten without them.
    """
    res = run_experiment(PARAMS, settings=IdentifySettings(global_evals=0, hops=0), seeds=10,
                         regulation=(False,))
    sc = res.scenarios['off']
    for (mode, ch), r in sc.channels.items():
        assert r.er['cal_seeds_mean'] < PAPER['er_percent'][ch], (mode, ch)
        assert r.er['raw_seeds_mean'] < PAPER['er_percent'][ch], (mode, ch)
        assert r.eps_c_percent < PAPER['eps_c_percent'][ch], (mode, ch)
        assert r.eps_c_raw_percent < PAPER['eps_c_percent'][ch], (mode, ch)
        assert r.eps_c_percent < sc.eps_unc_percent[ch], (mode, ch)
