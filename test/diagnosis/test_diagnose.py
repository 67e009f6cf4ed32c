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

"""Diagnosis: each mechanism's own block switched on is named; clean data gets ``none``.

Recordings are made with the diagnosis's own composed model
(:class:`hyst_id.diagnosis.model.ComposedModel`): the paper's chain with one
block at known values, white noise on top. The blind test on recordings of
the rig simulator is ``test_concealed_bags.py``.
"""

from __future__ import annotations

from dataclasses import replace
import json
from pathlib import Path

import numpy as np
import pytest
from smooth_reference import smooth_recording

from hyst_id.cli import main
from hyst_id.compensation.augment import Augmentation
from hyst_id.compensation.params_file import read_compensator_params
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.blocked_cv import BlockedCV
from hyst_id.diagnosis.locate import locate, noise_std
from hyst_id.diagnosis.mechanisms import Context, get_mechanisms, MECHANISM_IDS, MECHANISMS
from hyst_id.diagnosis.mechanisms.base import COMPENSATION_KINDS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.report import plot_diagnosis
from hyst_id.errors import ConfigError, NoExcitationError, RecordingError
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.loop import loop_width
from hyst_id.io.recording import Recording
from hyst_id.signals.excitation import multisine

__all__: list[str] = []

#: The paper's induced hysteresis with a small backlash; 0.5 s pressure lag.
CHAIN = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15, 0.5])
FAST = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1,
                        hops=20)

#: mechanism -> (channel, theta, linear coefficients of the model's columns)
CASES = {
    'dead_time': ('position', [0.2], None),
    'sensor_lag': ('position', [0.3], None),
    'supply_decay': ('pressure', [1.0 / 600.0], [1.0, 0.0, 0.0]),
    'gain_drift': ('position', [0.001], None),
    'offset_drift': ('position', [], [1.0, 0.004, 0.0]),
    'saturation': ('position', [0.15, 0.15], None),
    'stiction': ('position', [0.04, 0.01], None),
    'static_nonlinearity': ('position', [], [1.0, 0.25, 0.1, 9.0]),
    'rate_dependence': ('position', [0.3, 1.0], None),
}


def synthetic(mech: str | None, *, seed: int = 0, duration_s: float = 120.0,
              noise: float = 0.005) -> Recording:
    """A multisine run of the chain with one block (or none) and white noise."""
    channel, theta, coef = CASES[mech] if mech else ('position', [], None)
    t = np.arange(0.0, duration_s, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    ctx = Context(channel, t, t.size)
    mechs = [MECHANISMS[mech]] if mech else []
    n_chain = 12 if channel == 'pressure' else 11
    model = ComposedModel(channel, mechs, ctx, chain_spec(channel).bounds)
    p = np.concatenate([CHAIN[:n_chain], np.asarray(theta, dtype=float)])
    a = model.evaluate(p, t, v, t.size).matrix()
    coef = np.asarray(coef if coef is not None else [1.0] + [0.0] * (a.shape[1] - 1))
    y = a @ coef
    y = y + np.random.default_rng(seed).normal(0.0, noise, t.size)
    return Recording(t, v, y, channel, 'mA', 'mA-eq', f'synthetic {mech or "clean"}')


@pytest.fixture(scope='module')
def clean_diagnosis():
    return diagnose(synthetic(None, seed=3), settings=FAST)


@pytest.fixture(scope='module')
def delay_diagnosis():
    return diagnose(synthetic('dead_time', seed=4), settings=FAST)


def test_clean_recording_gets_none(clean_diagnosis):
    d = clean_diagnosis
    assert d.verdict == 'none'
    assert d.findings == []
    assert d.final.er_holdout_percent < 1.3 * d.noise_floor_percent


def test_dead_time_is_named_with_its_value(delay_diagnosis):
    d = delay_diagnosis
    assert d.verdict == 'dead_time'
    f = d.findings[0]
    assert f.params['delay_s'].value == pytest.approx(0.2, abs=0.02)
    assert f.params['delay_s'].unit == 's'
    assert f.er_holdout_after_percent < 0.7 * f.er_holdout_before_percent
    assert f.er_holdout_after_percent < 1.5 * d.noise_floor_percent


#: Mechanisms that a concealed bag of the default run names too (``test_concealed_bags``,
#: which checks the same words); here they are in the thorough tier.
NAMED_BY_A_BAG = ('rate_dependence', 'saturation', 'sensor_lag', 'offset_drift', 'stiction',
                  'static_nonlinearity')


def check_finding_words(d, mech: str) -> None:
    """The finding of ``mech`` explains itself and says how it is compensated, in its kind."""
    f = next((f for f in d.findings if f.mechanism == mech), None)
    assert f is not None and f.explanation and f.params, d.report()
    assert f.compensation['kind'] == MECHANISMS[mech].compensation
    assert f.compensation['kind'] in COMPENSATION_KINDS and len(f.compensation['how']) > 40
    assert f'compensation: {f.compensation["how"]}' in d.report()


@pytest.mark.slow
@pytest.mark.parametrize('mech', [
    pytest.param(m, marks=pytest.mark.thorough) if m in NAMED_BY_A_BAG else m
    for m in MECHANISM_IDS    # these have their own test modules:
    if m not in ('dead_time', 'loop_shape', 'creep', 'actuator_dynamics', 'friction',
                 'gain_loss', 'bouc_wen', 'rate_limit')])
def test_each_mechanism_is_named(mech):
    d = diagnose(synthetic(mech, seed=5), settings=FAST)
    assert d.verdict == mech, d.report()
    f = d.findings[0]
    # every finding says whether and how it is compensated, with the mechanism's own kind
    check_finding_words(d, mech)
    if mech == 'stiction':
        check_stick_slip(d, band=0.04 * loop_travel(synthetic(None, seed=5)))
        return
    if mech == 'saturation':
        check_end_stop(d)
        return
    assert f.er_holdout_after_percent < 0.7 * f.er_holdout_before_percent


@pytest.mark.slow
@pytest.mark.thorough
@pytest.mark.parametrize('seed', [0, 1])
def test_curved_branches_are_named_loop_shape(seed):
    """A smooth (Prandtl-Ishlinskii) loop is a loop shape, not a block after the paper's loop.

    Thorough tier: the default run names ``loop_shape`` on the real steel B(H) loops
    (``test_real_diagnoses.py::test_steel_loops_are_named_curved_branches_not_creep``)
    and chooses the smooth family on seed 0's recording
    (``test_model_choice.py::test_a_curved_loop_goes_to_the_smooth_family``); the
    diagnosis of this reference loop runs in ``./run test-all`` only.
    """
    rec, _ = smooth_recording(seed)
    d = diagnose(rec, settings=FAST)
    assert d.verdict == 'loop_shape', d.report()
    f = d.findings[0]
    assert f.params['er_holdout_smooth'].value == pytest.approx(f.er_holdout_after_percent)
    # The smooth chain reaches the held-out floor, and removes most of the paper chain's
    # excess over it. How far the paper chain misses varies (its best fit of seed 1 is
    # 1.4 x the floor, of seed 0 5.8 x), so the gain is a share of the excess, not a ratio.
    # Measured over seeds 0-11, unperturbed and one round-off probe
    # (``bench/claim_spreads.py --only loop_shape --seeds 12 --probes 1``): named 20/24
    # (seeds 8 and 10 get none: the paper chain is already within 1.04 x held out), final
    # held-out 0.98-1.04 x the floor, share of the excess removed 0.80-1.16.
    floor = d.noise_floor_percent
    assert f.er_holdout_after_percent < 1.1 * floor, d.report()
    excess = f.er_holdout_before_percent - floor
    assert f.er_holdout_before_percent - f.er_holdout_after_percent > 0.6 * excess, d.report()
    assert 'curved' in f.explanation and '--model smooth' in f.explanation


def check_end_stop(d) -> None:
    """An end stop's own criteria: what its training part can say about the held-out part.

    The stop levels are only seen where the training part reaches them; a
    fitted stop trains at the floor as well as the true one does, and how
    much held-out error it removes depends on where the held-out command
    goes beyond them. Measured over 12 noise seeds x {unperturbed, round-off
    probe} (``bench/claim_spreads.py --only saturation --seeds 12``): named
    24/24, held-out gain 10.6 % to 35.2 %, final held-out 0.97 to 1.32 x the
    noise floor. The bounds sit outside that: a gain of at least 5 % (the
    acceptance criterion itself) and within 1.6 x the floor.
    """
    f = d.findings[0]
    assert f.er_train_after_percent < 1.5 * d.noise_floor_train_percent, d.report()
    assert f.er_holdout_after_percent < 0.95 * f.er_holdout_before_percent, d.report()
    assert f.er_holdout_after_percent < 1.6 * d.noise_floor_percent, d.report()


def loop_travel(rec: Recording) -> float:
    """Travel of the chain's demand ``B(H(v))`` over a whole synthetic record."""
    return float(np.ptp(chain_spec('position').signal(CHAIN[:11], rec.t_s, rec.command)))


def check_stick_slip(d, band: float) -> None:
    """Stiction's own criteria (docs/diagnosis.md, stick-slip).

    The staircase is lined up on the training part (every slip on its
    measured sample: training %e_r at the noise floor) and the slip band is
    recovered. On held-out data a slip that falls while the demand barely
    moves can land a sample off and cost a whole jump there, so one record
    is only required to improve clearly; how often held-out data end at the
    floor is :func:`test_stick_slip_is_lined_up_on_held_out_data_often`.
    """
    f = d.findings[0]
    assert f.er_train_after_percent < 1.5 * d.noise_floor_train_percent, d.report()
    assert f.params['slip_band'].value == pytest.approx(band, rel=0.03)
    # measured held-out gain over 24 runs: 23.6 % or more (see the rate test below)
    assert f.er_holdout_after_percent < 0.85 * f.er_holdout_before_percent, d.report()


@pytest.mark.slow
@pytest.mark.thorough
def test_stick_slip_is_lined_up_on_held_out_data_often(record_property):
    """Six noise seeds: every one named and improved, a share at the floor.

    Whether a record ends at the floor on held-out data depends on single
    samples (a slip landing one sample off costs a whole jump), so the last
    bits of a sum can move a record across 1.5 x the floor. Measured over
    seeds 5..16 x {unperturbed, round-off probe} (``bench/claim_spreads.py
    --only stiction --seeds 12``): named 24/24, held-out gain 23.6 % to
    80.5 %, final/floor 0.93 to 3.66 with 14 of 24 under 1.5 (5 to 9 of 12
    per run, CI on another CPU make: 5). Seeds 5..10 alone (this test, in
    the thorough tier; the twelve stay in the benchmark): final/floor 3.15,
    0.96, 1.48, 0.94, 0.97, 1.80, gain 23.4 % to 79.8 %, 3 to 4 under 1.5
    (seed 7 sits on the line). Bounds outside that spread: 2 of 6 at the
    floor, every one improved by at least 15 % and within 4.5 x the floor.
    Remeasured with ``FAST``'s 20 jumps of hopping (docs/reproducibility.md):
    named 24/24, gain 23.5 % to 80.8 %, final/floor 0.93 to 3.15, 16 of 24
    under 1.5.
    """
    ratios, gains = [], []
    for seed in range(5, 11):
        d = diagnose(synthetic('stiction', seed=seed), settings=FAST)
        assert d.verdict == 'stiction', d.report()
        ratios.append(d.final.er_holdout_percent / d.noise_floor_percent)
        gains.append(1.0 - d.final.er_holdout_percent / d.baseline.er_holdout_percent)
    record_property('final_over_floor', [round(r, 3) for r in ratios])
    record_property('holdout_gain', [round(g, 3) for g in gains])
    assert sum(r < 1.5 for r in ratios) >= 2, np.round(ratios, 2)
    assert max(ratios) < 4.5, np.round(ratios, 2)
    assert min(gains) > 0.15, np.round(gains, 2)


def test_json_document_has_the_issue_schema(delay_diagnosis, tmp_path):
    doc = json.loads(json.dumps(delay_diagnosis.to_dict()))
    for key in ('channel', 'verdict', 'baseline', 'noise_floor_percent', 'findings', 'final'):
        assert key in doc
    assert set(doc['baseline']) >= {'er_train_percent', 'er_holdout_percent'}
    f = doc['findings'][0]
    assert set(f) >= {'mechanism', 'explanation', 'where', 'params',
                      'er_holdout_before_percent', 'er_holdout_after_percent'}
    assert set(doc['final']) >= {'mechanisms', 'er_train_percent', 'er_holdout_percent'}
    assert doc['final']['mechanisms'] == ['dead_time']
    # the paper's loop lags the command: counter-clockwise, said from the data alone
    assert doc['measured_loop']['direction'] == 'counter-clockwise'
    assert 'the measured loop runs counter-clockwise' in delay_diagnosis.report()
    assert f['params']['delay_s']['unit'] == 's'
    assert f['compensation']['kind'] == 'in-line' and 'ahead' in f['compensation']['how']
    assert f['compensation']['correction'] == {
        'augment.dead_time_s': pytest.approx(f['params']['delay_s']['value'])}
    # blocked cross-validation of the block, and of the final model against the baseline:
    # better in every judged time block on seeds 4-6 (z 144-185 against 4; the first
    # quarter is not judged: the multisine sweeps the command range only later)
    for cv in (f['blocked_cv'], doc['blocked_cv']):
        assert cv['blocks'] >= 3 and cv['better'] == cv['blocks'] and cv['worse'] == 0, cv


def test_status_for_diagnostics(delay_diagnosis, clean_diagnosis):
    level, message, values = delay_diagnosis.status()
    assert level == 'warn' and message.startswith('dead_time')
    assert values['verdict'] == 'dead_time' and values['dead_time.delay_s'].endswith(' s')
    assert all(isinstance(v, str) for v in values.values())
    assert clean_diagnosis.status()[0] == 'ok'


def test_report_and_figure(delay_diagnosis, clean_diagnosis, tmp_path):
    text = delay_diagnosis.report()
    assert 'verdict: dead_time' in text and 'held-out %e_r' in text
    assert 'final model against the baseline: blocked cross-validation' in text
    assert 'blocked_cv' not in clean_diagnosis.to_dict()     # nothing to confirm
    assert 'verdict: none' in clean_diagnosis.report()
    path = plot_diagnosis(delay_diagnosis, tmp_path / 'fig.png')
    assert path.stat().st_size > 10_000
    small = plot_diagnosis(delay_diagnosis, tmp_path / 'small.png', dpi=72)   # the docs'
    assert 5_000 < small.stat().st_size < path.stat().st_size


def test_a_none_without_rounds_says_the_residual_is_white_only_when_it_is(clean_diagnosis):
    """``max_mechanisms=0`` within the floor: the words follow the residual's checks."""
    loc = clean_diagnosis.localization
    for white, independent, said in [(True, True, 'the baseline residual is white'),
                                     (False, True, 'its residual is not white, independent'),
                                     (True, False, 'its residual is white, related to the')]:
        d = replace(clean_diagnosis, rounds=[], findings=[], verdict='none',
                    localization=replace(loc, white=white, independent=independent))
        verdict = next(x for x in d.report().splitlines() if x.startswith('verdict:'))
        assert said in verdict
        assert ('residual is white, independent of the command and at the noise floor'
                in verdict) is (white and independent)


def test_words_and_axes_name_what_the_file_measured(delay_diagnosis, tmp_path, monkeypatch):
    """A force recorded on the position chain is called a force, not a position."""
    import matplotlib.axes
    from dataclasses import replace
    from hyst_id.diagnosis.mechanisms.base import Quantity
    d = replace(delay_diagnosis, measurement_name='force_N', command_name='stroke_mm')
    assert d.report().splitlines()[0].endswith(
        f'channel position (measurement force_N), {d.t_s.size} samples over '
        f'{d.t_s[-1] - d.t_s[0]:.1f} s')
    assert d.to_dict()['measurement_name'] == 'force_N'
    labels = []
    for name in ('set_xlabel', 'set_ylabel'):
        plain = getattr(matplotlib.axes.Axes, name)

        def kept(ax, text, *args, _plain=plain, **kwargs):
            labels.append(text)
            return _plain(ax, text, *args, **kwargs)
        monkeypatch.setattr(matplotlib.axes.Axes, name, kept)
    plot_diagnosis(d, tmp_path / 'fig.png', dpi=50)
    assert 'force_N [mA-eq]' in labels and 'stroke_mm [mA]' in labels, labels
    ctx = Context('position', d.t_s, d.n_train, measurement_name='force_N')
    words = MECHANISMS['sensor_lag'].explain({'tau_lag_s': Quantity(0.1, 's')}, None, ctx)
    assert words.startswith('The measured force_N lags'), words
    assert Context('position', d.t_s, d.n_train).quantity == 'position'


def test_locate_white_noise_is_white_and_a_delay_is_not():
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 100.0, 0.05)
    v = multisine(t)
    y = rng.normal(0.0, 1.0, t.size)
    loc = locate(t, v, y, np.zeros_like(y), 1.0)
    assert loc.white and loc.independent and not loc.structured
    rate = np.gradient(v, t)
    loc = locate(t, v, y + 3.0 * rate, np.zeros_like(y), 1.0)
    assert loc.ccf_rate['significant'] and loc.structured


@pytest.mark.parametrize('kind', ['multisine', 'triangle'])
def test_the_cross_correlation_bound_is_never_below_a_white_residuals(kind):
    """``3.29 sqrt(P/N)`` with ``P`` at least 1: a new user's clean record printed 'bound 0.01'.

    ``P`` estimated from the sample ACFs of a smooth command came out near 0 (the
    multisine's bound fell to 0.051 over these 40 seeds, against 0.074 for white
    noise); a white residual's ``P`` is 1.
    """
    t = np.arange(0.0, 100.0, 0.05)
    v = multisine(t) if kind == 'multisine' else np.abs(((t / 4.0) % 2.0) - 1.0)
    for seed in range(40):
        y = np.random.default_rng(seed).normal(0.0, 1.0, t.size)
        loc = locate(t, v, y, np.zeros_like(y), 1.0)
        for c in (loc.ccf_command, loc.ccf_rate):
            assert c['bound'] >= 3.29 / np.sqrt(t.size) * (1 - 1e-12), (seed, c['bound'])


def test_ranges_in_the_words_tell_their_ends_apart():
    """A new user's report read 'time windows 20-20 s' and 'level -0.9998--0.5968'."""
    from hyst_id.diagnosis.locate import span_label
    assert span_label(19.6, 20.0, 0) == '19.6-20.0'
    assert span_label(0.0, 4.0, 0) == '0-4'
    assert span_label(-0.99981, -0.59678) == '-0.9998 to -0.5968'
    assert span_label(7.25, 9.5) == '7.25-9.5'


def test_noise_estimate_ignores_quantisation_and_jumps():
    rng = np.random.default_rng(2)
    y = np.round((rng.normal(0.0, 1.0, 4000) + np.linspace(0, 50, 4000)) / 0.8) * 0.8
    assert noise_std(y) == pytest.approx(1.03, rel=0.08)
    stairs = np.floor(np.linspace(0.0, 400.0, 4000) / 10.0) * 10.0   # jumps every 100 samples
    assert noise_std(stairs + rng.normal(0.0, 1.0, 4000)) == pytest.approx(1.0, rel=0.08)


def test_loop_width_of_the_paper_loop():
    rec = synthetic(None)
    w = loop_width(rec.t_s, rec.command, rec.measurement)
    assert 0.3 < w < 2.0


def test_bad_inputs_are_one_line_errors():
    rec = synthetic(None)
    short = Recording(rec.t_s[:30], rec.command[:30], rec.measurement[:30], 'position')
    with pytest.raises(RecordingError) as info:
        diagnose(short, settings=FAST)
    assert '\n' not in str(info.value)
    t = np.arange(50) * 0.02        # a new-user trial's 50 samples: a dead time was claimed
    v = 9.0 + np.sin(2 * np.pi * 3.0 * t)
    fifty = Recording(t, v, v + np.random.default_rng(0).normal(0, 0.01, t.size), 'pressure')
    with pytest.raises(RecordingError, match='too short to diagnose: 35 training and 15'):
        diagnose(fifty, settings=FAST)
    flat = Recording(rec.t_s, np.full_like(rec.t_s, 9.0), rec.measurement, 'position')
    with pytest.raises(NoExcitationError):
        diagnose(flat, settings=FAST)
    with pytest.raises(ConfigError, match='unknown mechanism'):
        diagnose(rec, settings=DiagnoseSettings(mechanisms=('not_a_mechanism',)))
    with pytest.raises(ConfigError, match='train fraction'):
        diagnose(rec, settings=DiagnoseSettings(train_fraction=1.5))
    with pytest.raises(ConfigError, match='supply_decay cannot act on the position channel'):
        diagnose(rec, settings=DiagnoseSettings(mechanisms=('dead_time', 'supply_decay')))


def test_a_supply_is_not_physics_of_the_position_reading():
    """The blind family's position recordings named a supply decay for gain and offset drifts."""
    by_channel = {ch: [m.id for m in get_mechanisms(channel=ch)]
                  for ch in ('position', 'pressure', 'flow')}
    assert 'supply_decay' not in by_channel['position']
    assert 'supply_decay' in by_channel['pressure'] and 'supply_decay' in by_channel['flow']
    assert set(by_channel['position']) == set(MECHANISM_IDS) - {'supply_decay'}
    # a gain drift keeps a growth above zero on every channel: near zero with a distant
    # zero b0 it would be an offset drift (a synthetic offset drift on position was named
    # gain_drift with 0.03 % of growth when the bound was dropped)
    t = np.arange(100.0)
    for ch in ('position', 'pressure', 'flow'):
        assert MECHANISMS['gain_drift'].bounds(Context(ch, t, 70))[0, 0] > 0


def test_cli_errors_are_one_line(tmp_path, capsys):
    assert main(['diagnose', str(tmp_path / 'missing.csv')]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('hyst-id: error:') and '\n' not in err
    csv = tmp_path / 'r.csv'
    rec = synthetic(None)
    np.savetxt(csv, np.c_[rec.t_s, rec.command, rec.measurement], delimiter=',',
               header='t,command,measurement', comments='')
    assert main(['diagnose', str(csv), '--mechanisms', 'not_a_mechanism']) == 2
    assert 'unknown mechanism' in capsys.readouterr().err
    assert main(['diagnose', str(csv), '--mechanisms', 'supply_decay', '--quiet']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert 'supply_decay cannot act on the position channel' in err[-1], err
    assert main(['diagnose', str(csv), '--hops', '-1', '--quiet']) == 2
    assert '--hops must be at least 0' in capsys.readouterr().err
    for bad in ('-1', '10001'):
        assert main(['diagnose', str(csv), '--joint-generations', bad, '--quiet']) == 2
        assert '--joint-generations must be 0 to 10000, got ' + bad in capsys.readouterr().err
    # an empty name is not "all of them", an output without its input is not ignored
    for bad in ('', 'dead_time,,'):
        assert main(['diagnose', str(csv), '--mechanisms', bad, '--quiet']) == 2
        assert 'an empty name' in capsys.readouterr().err
    assert main(['diagnose', str(csv), '--sim-out', str(tmp_path / 's.yaml'), '--quiet']) == 2
    assert 'it needs --sim' in capsys.readouterr().err
    assert main(['diagnose', str(csv), '--workers', '-2', '--quiet']) == 2
    assert '--workers must be >= 0' in capsys.readouterr().err
    # an output that cannot be written is refused before the diagnosis runs
    (tmp_path / 'afile').write_text('')
    assert main(['diagnose', str(csv), '--json', str(tmp_path / 'afile' / 'd.json'),
                 '--quiet']) == 2
    assert 'is a file, not a folder' in capsys.readouterr().err
    assert not list(tmp_path.glob('*.json')) and not list(tmp_path.glob('*.png'))


@pytest.mark.parametrize('flag', ['--global-runs', '--restarts', '--search-samples',
                                  '--er-bound', '--global-evals', '--xi'])
def test_cli_identify_only_flags_are_refused(flag, tmp_path, capsys):
    """Flags only ``identify`` uses are a usage error for ``diagnose``, not ignored."""
    with pytest.raises(SystemExit) as stop:
        main(['diagnose', str(tmp_path / 'r.csv'), flag, '3'])
    assert stop.value.code == 2
    assert f'unrecognized arguments: {flag} 3' in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:
        main(['diagnose', str(tmp_path / 'r.csv'), '--gaass-only'])
    assert stop.value.code == 2


def test_cli_hops_reach_the_baseline():
    """``diagnose --hops N`` is the baseline's hopping (identify's default, 100)."""
    import argparse

    from hyst_id.commands import diagnose as command
    from hyst_id.diagnosis.baseline import identify_base
    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    for argv, hops in (([], 100), (['--hops', '0'], 0), (['--hops', '7'], 7)):
        settings = command._settings(parser.parse_args(['r.csv'] + argv))
        assert settings.hops == hops and identify_base(settings)['hops'] == hops
    assert DiagnoseSettings().hops == 100


def test_cli_writes_json_and_figure(tmp_path, capsys):
    rec = synthetic('offset_drift', seed=7)
    csv = tmp_path / 'drift.csv'
    np.savetxt(csv, np.c_[rec.t_s, rec.command, rec.measurement], delimiter=',',
               header='t,command,measurement', comments='')
    out = tmp_path / 'd.json'
    fig = tmp_path / 'd.png'
    params = tmp_path / 'compensator.yaml'
    code = main(['diagnose', str(csv), '--seeds', '1', '--generations', '100', '--workers', '1',
                 '--max-mechanisms', '1', '--json', str(out), '--plot', str(fig), '--quiet',
                 '--params-out', str(params)])
    assert code == 0
    doc = json.loads(out.read_text())
    assert doc['verdict'] == 'offset_drift'
    rate = doc['findings'][0]['params']['rate_per_s']['value']
    assert rate == pytest.approx(0.004, rel=0.1)
    assert doc['findings'][0]['compensation']['correction'] == {
        'augment.offset_rate_per_s': pytest.approx(rate), 'augment.offset_reference_s':
        pytest.approx(0.5 * (rec.t_s[-1] - rec.t_s[0]))}
    assert Path(fig).exists()
    captured = capsys.readouterr()
    assert 'verdict: offset_drift' in captured.out
    assert 'compensator: offset_drift: in-line: offset_rate_per_s' in captured.err
    back = read_compensator_params(params)
    assert Augmentation.from_mapping(back).offset_rate_per_s == pytest.approx(rate)
    assert doc['compensator']['applied'][0]['mechanism'] == 'offset_drift'


def test_a_finding_the_time_blocks_do_not_hold_up_is_stated_not_claimed(monkeypatch):
    """The verdict rule end to end: the only finding not confirmed -> ``unknown``.

    No simulated record makes the split accept a block that blocked
    cross-validation then refuses with a margin that survives round-off (the
    blind family's cases move with it, docs/diagnosis.md), so the time blocks'
    verdict is set here: the block worse in 3 of 4 quarters, better in none.
    The rest is the diagnosis's own (the delayed record of ``delay_diagnosis``).
    """
    def against(self, before, after):
        return {'blocks': 4, 'better': 0, 'worse': 3, 'er_a_percent': [1.0] * 4,
                'er_b_percent': [2.0] * 4, 'n_extrapolated': [0] * 4, 'n_unswept': [0] * 4,
                'z_min': 4.0}

    monkeypatch.setattr(BlockedCV, 'confirm', against)
    d = diagnose(synthetic('dead_time', seed=4), settings=FAST)
    assert d.verdict == 'unknown' and [f.mechanism for f in d.findings] == ['dead_time']
    assert d.final is not d.baseline                 # the block stays in the fitted model
    level, message, values = d.status()
    assert level == 'warn' and values['not_confirmed'] == 'dead_time'
    text = d.report()
    assert 'verdict: unknown - the blocks below predict the held-out part' in text
    assert 'not confirmed (1): dead_time' in text
    doc = d.to_dict()
    assert doc['verdict'] == 'unknown' and doc['findings'][0]['blocked_cv']['worse'] == 3
