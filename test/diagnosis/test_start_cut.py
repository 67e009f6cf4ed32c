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

"""Diagnose a clean record whose actuator starts inside its play (the reviewer's case).

The data come from the play operator written apart from the package
(``test/play_reference.py``: ``y = 2 play(u, 0.8) + 1``, noise 0.01). The
chain starts on an edge of its loop, so the whole record's baseline stays
above its floor; before :mod:`hyst_id.diagnosis.start_cut` a 20 s rest inside
the play was diagnosed ``rate_dependence`` + ``creep`` and a start inside it
with no rest ``unknown``. Measured on noise seeds 0 and 1 (40 s of sine): the
whole record's baseline 31.7 x (20 s rest) and 8.2 x (no rest) the floor, the
probe from the first reversal 0.97-0.99 x (the bound :data:`PROBE_NEAR` is 1.3).
"""

from __future__ import annotations

import numpy as np
from play_reference import rest_then_sine
import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.start_cut import PROBE_NEAR, start_cut
from hyst_id.identification.domains import domains_from_data
from hyst_id.io.recording import Recording
from hyst_id.signals.excitation import multisine
from hyst_id.signals.reversals import reversal_indices
from hyst_id.signals.split import split_index

SETTINGS = DiagnoseSettings(workers=1, hops=20)


def test_a_start_inside_the_play_is_cut_and_no_physics_is_claimed():
    rest_s = 20.0       # (no rest is cut the same way: 8.2 x -> 0.99 x; left out for time)
    rec = rest_then_sine(0, rest_s, True, sine_s=40.0)
    d = diagnose(rec, settings=SETTINGS)
    assert d.verdict == 'none' and not d.findings, (d.verdict, d.notes[:1])
    note = d.notes[0]
    assert 'left out of the diagnosis' in note and 'inside its play' in note, note
    assert d.t_s[0] > rest_s                       # the report is of the record after the cut
    after = float(note.split('without them ')[1].split(' x')[0])
    assert after <= PROBE_NEAR
    cut = d.to_dict()['start_cut']                  # and in --json
    assert cut['first_t_s'] == d.t_s[0] and cut['probe_over_floor'] <= PROBE_NEAR
    assert cut['baseline_over_floor'] > 1.5 * cut['probe_over_floor']


def test_an_edge_start_is_diagnosed_whole():
    rec = rest_then_sine(0, 0.0, False, sine_s=40.0)
    d = diagnose(rec, settings=SETTINGS)
    assert d.verdict == 'none' and d.t_s[0] == rec.t_s[0]
    assert not any('left out' in n for n in d.notes) and 'start_cut' not in d.to_dict()


def test_start_state_off_never_tries_the_cut(monkeypatch):
    """``DiagnoseSettings.start_state`` (``--whole-record``) decides whether the cut is tried.

    Checked where it is cheap: the edge start's baseline is at its floor, so
    :func:`start_cut` answers None at once when asked; here it only records the asking.
    """
    import hyst_id.diagnosis.driver as driver
    asked = []
    monkeypatch.setattr(driver, 'start_cut', lambda *a, **k: asked.append(a) or None)
    rec = rest_then_sine(0, 0.0, False, sine_s=40.0)
    diagnose(rec, settings=DiagnoseSettings(workers=1, hops=20, start_state=False))
    assert asked == []
    diagnose(rec, settings=SETTINGS)
    assert len(asked) == 1


def test_the_cut_is_tried_only_above_one_and_a_half_times_the_floor(monkeypatch):
    """Identify retries from 1.1 x its floor; a diagnosis's baseline keeps the 1.5 x it had.

    So the blind family's verdicts and times (measured with 1.5 x) stand: a baseline
    at 1.4 x is no reason to cut, and the probe is never run for it.
    """
    import hyst_id.diagnosis.start_cut as start_cut_module
    from hyst_id.identification.chains import chain_spec
    rec = rest_then_sine(0, 20.0, True, sine_s=40.0)

    def no_probe(*args, **kwargs):
        raise AssertionError('the probe ran')
    monkeypatch.setattr(start_cut_module, 'identify', no_probe)
    v = np.asarray(rec.command)
    assert start_cut_module.start_cut(rec, v, chain_spec('position'), SETTINGS, 1.4, 1.0) is None
    with pytest.raises(AssertionError, match='the probe ran'):
        start_cut_module.start_cut(rec, v, chain_spec('position'), SETTINGS, 1.6, 1.0)


def test_no_cut_leaves_a_record_too_short_to_diagnose(monkeypatch):
    """A cut whose rest would fail the split's minimum is not tried.

    The record is then diagnosed whole, instead of the diagnosis after the cut refusing
    it (100 training and 40 held-out samples, ``split_notes.require_split``).
    """
    import hyst_id.diagnosis.start_cut as start_cut_module
    from hyst_id.identification.chains import chain_spec

    def no_probe(*args, **kwargs):
        raise AssertionError('the probe ran')
    monkeypatch.setattr(start_cut_module, 'identify', no_probe)
    for n, probed in ((150, False), (400, True)):       # first reversal at sample 15
        t = np.arange(n) * 0.05
        v = np.sin(2 * np.pi * t / 3.0)
        rec = Recording(t, v, v, 'position')
        if probed:
            with pytest.raises(AssertionError, match='the probe ran'):
                start_cut_module.start_cut(rec, v, chain_spec('position'), SETTINGS, 3.0, 1.0)
        else:
            assert start_cut_module.start_cut(rec, v, chain_spec('position'), SETTINGS,
                                              3.0, 1.0) is None


def test_a_part_that_no_longer_reverses_twice_gives_no_cut():
    """The probe's training part from the first reversal may not excite the loop.

    A 10 s multisine reverses three times, but the training part of the record
    from its first reversal on reverses once; ``diagnose`` raised ``NoExcitationError`` from
    the probe (saying the command reverses once) for a record it could
    diagnose.
    """
    t = np.arange(0.0, 10.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    rec = Recording(t, v, 0.5 * v + np.random.default_rng(0).normal(0.0, 0.005, t.size),
                    'position')
    spec = domains_from_data(rec)
    index, _ = reversal_indices(v)
    k = int(index[0])
    n_train = split_index(t[k:], SETTINGS.train_fraction)
    assert index.size >= 3 and reversal_indices(v[k:k + n_train])[0].size < 2
    assert start_cut(rec, v, spec, SETTINGS, er_train_percent=5.0,
                     floor_train_percent=0.1) is None
