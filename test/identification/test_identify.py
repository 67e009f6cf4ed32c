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

"""Identification recovers known chains from simulated recordings (fixed seeds)."""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.errors import IdentificationError, NoExcitationError, RecordingError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.domains import preset_spec
from hyst_id.io.recording import Recording
from hyst_id.signals.noise import noise_floor_percent


@pytest.mark.parametrize('channel', ['position', 'pressure'])
def test_reaches_the_noise_floor_in_nine_of_ten_seeds(simulated, channel):
    """The core issue's accuracy target, with the paper's GAASS settings."""
    rec, _ = simulated(channel)
    ident = identify(rec, settings=IdentifySettings(seeds=tuple(range(10))))
    floor = noise_floor_percent(rec.measurement)
    ratios = np.array([r.er_percent for r in ident.runs]) / floor
    assert np.sum(ratios <= 1.1) >= 9, f'per-seed %e_r / noise floor: {np.round(ratios, 3)}'
    assert ident.noise_floor_percent == pytest.approx(floor)


@pytest.mark.parametrize('channel', ['position', 'pressure', 'flow'])
def test_identified_chain_reproduces_the_noise_free_output(simulated, channel):
    """Parameters are a gauge orbit apart at most: the output itself is recovered."""
    rec, y_true = simulated(channel)
    seeds = (0, 1, 2, 3) if channel == 'flow' else (0, 1)
    # Flow with data-derived domains settles at ~1.3 x the floor on this record
    # (docs/byo-actuator.md, known limitations); the paper's domains reach it.
    spec = preset_spec('paper', channel) if channel == 'flow' else None
    ident = identify(rec, spec=spec, settings=IdentifySettings(seeds=seeds))
    y_fit = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    noise_rms = np.sqrt(np.mean((rec.measurement - y_true) ** 2))
    assert np.sqrt(np.mean((y_fit - y_true) ** 2)) < 0.35 * noise_rms
    assert ident.params['m_bl'] == 1.0
    assert ident.params['c_bl'] == pytest.approx(-ident.params['c_br'])
    assert chain_spec(channel).feasible(ident.x[None, :])[0]


def test_sensor_time_constant_is_recovered(simulated):
    rec, _ = simulated('pressure')
    ident = identify(rec, settings=IdentifySettings(seeds=(0, 1), workers=1))
    assert ident.params['tau_s'] == pytest.approx(0.5, abs=0.05)


def test_gaass_only_is_reproducible_and_worse_than_refined(simulated):
    rec, _ = simulated('position')
    ga = IdentifySettings(seeds=(3,), workers=1, refine=False, maxiter=100)
    first, second = identify(rec, settings=ga), identify(rec, settings=ga)
    np.testing.assert_array_equal(first.runs[0].x_raw, second.runs[0].x_raw)
    refined = identify(rec, settings=IdentifySettings(seeds=(3,), workers=1, maxiter=100))
    assert refined.er_percent <= first.er_percent


def test_er_bound_stops_gaass_early(simulated):
    rec, _ = simulated('position')
    ident = identify(rec, settings=IdentifySettings(seeds=(0,), workers=1, refine=False,
                                                    er_bound_percent=5.0))
    assert ident.runs[0].nit < 500
    assert ident.er_percent <= 5.0


def test_channel_mismatch_and_empty_seeds_are_errors(simulated):
    rec, _ = simulated('position')
    with pytest.raises(IdentificationError, match='chain is for'):
        identify(rec, spec=chain_spec('flow'))
    with pytest.raises(IdentificationError, match='no seeds'):
        identify(rec, settings=IdentifySettings(seeds=()))


@pytest.mark.parametrize('mutate, error, text', [
    (lambda t, v, y: (t, np.full_like(v, 9.0), y), NoExcitationError, 'constant'),
    (lambda t, v, y: (t, np.linspace(7, 11, v.size), y), NoExcitationError, 'reverses'),
    (lambda t, v, y: (t, v, np.where(np.arange(y.size) == 7, np.nan, y)), RecordingError,
     'NaN'),
    (lambda t, v, y: (t[::-1].copy(), v, y), RecordingError, 'backwards'),
    (lambda t, v, y: (np.where(np.arange(t.size) == 5, t[4], t), v, y), RecordingError,
     'duplicate'),
    (lambda t, v, y: (t[:5], v[:5], y[:5]), RecordingError, 'too few'),
])
def test_bad_recordings_are_refused_in_one_line(simulated, mutate, error, text):
    rec, _ = simulated('position')
    t, v, y = mutate(rec.t_s.copy(), rec.command.copy(), rec.measurement.copy())
    with pytest.raises(error, match=text) as info:
        identify(Recording(t, v, y, 'position'))
    assert '\n' not in str(info.value)


def test_negative_gain_sensor_is_identified_with_output_sign():
    """Upstream pressure falls as the valve opens: k < 0 must still work."""
    from conftest import simulate_channel

    rec, y_true = simulate_channel('pressure')
    flipped = Recording(rec.t_s, rec.command, 3000.0 - rec.measurement, 'pressure')
    ident = identify(flipped, settings=IdentifySettings(seeds=(0, 1)))
    assert ident.output_sign == -1.0
    y_fit = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    noise_rms = np.sqrt(np.mean((rec.measurement - y_true) ** 2))
    assert np.sqrt(np.mean((y_fit - (3000.0 - y_true)) ** 2)) < 0.35 * noise_rms


def test_restarts_stop_when_they_stop_gaining(simulated):
    """Unmodelled physics (here a slow drift) keeps %e_r off the floor: restarts stop early."""
    rec, _ = simulated('position')
    drift = 0.05 * np.sin(2 * np.pi * rec.t_s / 37.0) * np.ptp(rec.measurement)
    off = Recording(rec.t_s, rec.command, rec.measurement + drift, 'position', 'mA', '',
                    'position with an unmodelled drift')
    # the seed's restarts are what is measured: no global phase, no hopping after them
    base = {'seeds': (0,), 'workers': 1, 'maxiter': 60, 'restarts': 4, 'global_evals': 0,
            'hops': 0}
    full = identify(off, settings=IdentifySettings(**base, restart_patience=100)).runs[0]
    capped = identify(off, settings=IdentifySettings(**base, restart_patience=1)).runs[0]
    assert full.er_percent > 1.5 * noise_floor_percent(off.measurement)   # restarts wanted
    assert full.nit == 5 * 60          # every restart ran
    assert capped.nit < full.nit       # stopped at the first restart that did not gain
    assert capped.nit % 60 == 0


def test_the_fit_does_not_depend_on_the_measurements_units():
    """The piezo example in um and in units 1e-7 and 1e-12 as large: the same %e_r.

    A review found the polish stopping early in tiny units (least_squares' absolute gtol):
    5.760 at x 1e-7 and 5.753 at x 1e-12 against 5.652; with the residual scaled by a power of
    two (``refine.residual_scale``) all three end at 5.6515-5.6516 (differences of 2e-5).
    """
    from dataclasses import replace
    from pathlib import Path

    from hyst_id.identification.refine import residual_scale
    from hyst_id.io.readers import read_recording
    path = Path(__file__).resolve().parents[2] / 'docs' / 'examples' / 'piezo_stage.csv'
    rec = read_recording(path, 'position', columns=['t_s', 'command_V', 'position_um'])
    assert residual_scale(rec.measurement) == 1.0             # its own units: untouched
    assert residual_scale(rec.measurement * 1e-7) == 2.0 ** -20   # RMS 1.2e-6 into [1, 2)
    er = {k: identify(replace(rec, measurement=rec.measurement * 10.0 ** k),
                      settings=IdentifySettings(workers=1)).er_percent for k in (0, -7, -12)}
    assert all(abs(e / er[0] - 1.0) < 2e-3 for e in er.values()), er
