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

"""Odd and bad input an independent fuzz review found mishandled (stop 64).

Each case was reproduced before its fix: settings the API accepted silently or
that failed inside numpy, a diagnosis that said ``none`` of a measurement
that does not follow the command or of a baseline far off its floor when no
block was tried, frozen samples called on a measurement riding on a large
offset, and two misleading messages. The data come from a play operator
written here (not the package's chain).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from hyst_id.cli import main
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.split_notes import require_split
from hyst_id.errors import ConfigError, RecordingError
from hyst_id.identification import IdentifySettings
from hyst_id.identification.domains import domains_from_data
from hyst_id.io.recording import Recording
from hyst_id.signals.noise import held_share

SMALL = {'seeds': (0,), 'generations': 60, 'hops': 10, 'workers': 1}


def _play(u: np.ndarray, width: float = 0.5) -> np.ndarray:
    y, s = np.empty_like(u), float(u[0])
    for i, v in enumerate(u):
        s = min(max(s, v - width), v + width)
        y[i] = s
    return y


def _sine(n: int = 400, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(n) * 0.01
    u = 9.0 + 2.0 * np.sin(2 * np.pi * 0.5 * t * (1.0 + t / t[-1]))
    return t, u, 2.0 * _play(u) + 0.01 * np.random.default_rng(seed).standard_normal(n)


@pytest.mark.parametrize('cls, kwargs, field', [
    (IdentifySettings, {'seeds': (-1,)}, 'seeds'),
    (IdentifySettings, {'seeds': (0.5,)}, 'seeds'),
    (IdentifySettings, {'conventions': 'bogus'}, 'conventions'),
    (IdentifySettings, {'workers': -2}, 'workers'),
    (IdentifySettings, {'er_bound_percent': -1.0}, 'er_bound_percent'),
    (IdentifySettings, {'restarts': -1}, 'restarts'),
    (IdentifySettings, {'search_samples': -1}, 'search_samples'),
    (IdentifySettings, {'restart_factor': float('nan')}, 'restart_factor'),
    (IdentifySettings, {'global_factor': -1.0}, 'global_factor'),
    (DiagnoseSettings, {'hops': -1}, 'hops'),
    (DiagnoseSettings, {'workers': -1}, 'workers'),
    (DiagnoseSettings, {'joint_generations': -5}, 'joint_generations'),
    (DiagnoseSettings, {'fit_budget': 0}, 'fit_budget'),
    (DiagnoseSettings, {'max_mechanisms': -1}, 'max_mechanisms'),
    (DiagnoseSettings, {'train_fraction': 1.0}, 'train_fraction'),
])
def test_settings_out_of_range_are_refused_by_the_api(cls, kwargs, field):
    with pytest.raises(ConfigError, match=f'{cls.__name__}.{field}'):
        cls(**kwargs)


def test_the_default_settings_pass_their_checks():
    assert IdentifySettings().seeds and DiagnoseSettings().max_mechanisms >= 1


def test_no_block_tried_is_not_a_clean_verdict():
    """``max_mechanisms=0`` (the baseline only) on a record with a sensor lag: not ``none``."""
    t, u, _ = _sine()
    x = 2.0 * _play(u)
    y = np.empty_like(x)
    s = x[0]
    for i, xi in enumerate(x):          # a first-order lag of 0.08 s
        s += 0.01 / 0.09 * (xi - s)
        y[i] = s
    y += 0.01 * np.random.default_rng(3).standard_normal(y.size)
    d = diagnose(Recording(t, u, y, 'position'),
                 settings=DiagnoseSettings(**SMALL, max_mechanisms=0))
    assert d.final.er_holdout_percent > 10 * d.noise_floor_percent
    assert d.verdict == 'unknown' and not d.rounds
    assert 'no block of the library was tried' in d.report()


def test_a_measurement_that_does_not_follow_the_command_is_not_clean(tmp_path, capsys):
    """Noise alone: ``unknown`` with the reason in ``--json``, not ``none``."""
    t, u, _ = _sine()
    y = 0.01 * np.random.default_rng(1).standard_normal(t.size)
    csv = tmp_path / 'noise.csv'
    np.savetxt(csv, np.c_[t, u, y], delimiter=',', header='t,command,measurement',
               comments='')
    out = tmp_path / 'd.json'
    assert main(['diagnose', str(csv), '--quiet', '--seeds', '1', '--generations', '60',
                 '--workers', '1', '--hops', '10', '--max-mechanisms', '1',
                 '--json', str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc['verdict'] == 'unknown'
    assert 'does not follow the command' in doc['no_response']
    assert 'verdict: unknown - the measurement does not follow the command' in \
        capsys.readouterr().out


def test_a_large_offset_is_not_called_frozen():
    """Repeats judged against the spread: at 1e8 about half the samples were 'held' before.

    At 1e8 the tolerance's floor (``REPEAT_FLOOR`` of the largest value, above the
    round-off probe's perturbation) is 1e-3 against noise steps of 0.014.
    """
    t, u, y = _sine()
    assert held_share(y) < 0.005
    for offset in (1e4, 1e8):
        assert held_share(y + offset) < 0.05, offset


def test_a_train_fraction_that_starves_the_split_says_so():
    with pytest.raises(RecordingError, match='training fraction leaves 20 training'):
        require_split(20, 400)
    with pytest.raises(RecordingError, match='record too short'):
        require_split(90, 120)


def test_a_measurement_of_one_outlier_says_what_it_is():
    t, u, _ = _sine()
    y = np.zeros_like(t)
    y[200] = 1.0
    with pytest.raises(ConfigError, match='hold one value'):
        domains_from_data(Recording(t, u, y, 'position'))


def test_complex_arrays_are_refused_in_words():
    from hyst_id.io.recording import validate_recording
    t, u, y = _sine()
    with pytest.raises(RecordingError, match='measurement is complex'):
        validate_recording(Recording(t, u, y + 1e-3j, 'position'))


@pytest.mark.parametrize('encoding, said', [
    ('utf-8', None), ('latin-1', 'Latin-1'), ('utf-16', 'UTF-16')])
def test_a_csv_in_latin_1_or_utf_16_is_read_as_in_utf_8(tmp_path, encoding, said):
    from hyst_id.io.csv_reader import read_csv
    t, u, y = _sine()
    rows = [f'{float(a)!r},{float(b)!r},{float(c)!r}' for a, b, c in zip(t, u, y)]
    path = tmp_path / f'{encoding}.csv'
    path.write_bytes('\n'.join(['t [s],valve [mA],position [\u00b5m]'] + rows).encode(encoding))
    rec = read_csv(path, 'position', columns=(0, 1, 2))
    np.testing.assert_array_equal(rec.measurement, y)
    assert rec.measurement_unit == '\u00b5m'
    assert (said in rec.notes[0]) if said else 'read as' not in rec.notes[0]
