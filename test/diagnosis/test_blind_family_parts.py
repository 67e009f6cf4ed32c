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

"""The blind family's bookkeeping: scoring with judgement calls, and running in parts."""

from __future__ import annotations

import json
from pathlib import Path
import sys

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))

import blind_family  # noqa: E402, I100


def fake_row(index: int) -> dict:
    """A row without a diagnosis (module level: the pool pickles it by name)."""
    return {'index': index, 'channel': 'position', 'excitation': 'chirp', 'dt_s': 0.05,
            'effects': [], 'verdict': 'none', 'found': [], 'calls': [], 'cost': 1.0,
            'final': 1.0, 'seconds': 0.0}


def _row(effects, found, calls):
    return {'effects': effects, 'found': found, 'calls': calls, 'verdict': 'x'}


@pytest.mark.parametrize('effects, found, calls, right', [
    (['gain_drift'], ['offset_drift'], [['gain_drift']], True),
    (['gain_drift'], ['offset_drift'], [[]], False),
    (['a', 'b'], ['a'], [['b']], False),            # one finding cannot stand for two
    (['a', 'b'], ['a', 'c'], [[], ['b']], True),
    (['a'], ['a', 'c'], [[], ['d']], False),        # a second claim with no effect in it
    (['a'], ['a'], [[]], True),
])
def test_a_stated_judgement_call_counts_only_where_it_names_the_effect(
        effects, found, calls, right):
    """Each finding must be an effect or state one as its alternative, and cover them all."""
    assert blind_family._right_or_called(_row(effects, found, calls)) is right


def test_a_row_from_before_calls_were_recorded_counts_as_named_right():
    """Old rows have no ``calls``: they are scored by the names alone."""
    row = {'effects': ['a'], 'found': ['b'], 'verdict': 'b'}
    assert blind_family._right_or_called(row) is False
    assert blind_family._right_or_called(dict(row, found=['a'], verdict='a')) is True


def test_a_run_in_parts_goes_on_from_rows_of_the_same_code_only(tmp_path):
    """Rows of the same code are kept and skipped, rows of other code are run again."""
    partial = tmp_path / 'partial.jsonl'
    none = blind_family.run_parts([0, 1, 2, 3], 1, 0.0, True, partial=partial,
                                  one=fake_row, code='A')
    assert none == [] and not partial.exists()         # no recording started after the time
    part = blind_family.run_parts([0, 1], 2, float('inf'), True, partial=partial,
                                  one=fake_row, code='A')
    assert [r['index'] for r in part] == [0, 1]
    whole = blind_family.run_parts([0, 1, 2, 3], 2, float('inf'), True, partial=partial,
                                   one=fake_row, code='A')
    assert [r['index'] for r in whole] == [0, 1, 2, 3]
    lines = [json.loads(x) for x in partial.read_text().splitlines()]
    assert sorted(r['index'] for r in lines) == [0, 1, 2, 3]      # 0 and 1 not run twice
    assert {r['code'] for r in lines} == {'A'}
    other = blind_family.run_parts([0, 1], 2, float('inf'), True, partial=partial,
                                   one=fake_row, code='B')
    assert [r['index'] for r in other] == [0, 1]
    assert len(partial.read_text().splitlines()) == 6      # B's rows run again and appended
    assert sorted(r['index'] for r in blind_family.finished_rows('B', partial)) == [0, 1]
    assert blind_family.run_parts([5], 1, float('inf'), False, partial=tmp_path / 'no.jsonl',
                                  one=fake_row, code='B')[0]['index'] == 5
    assert not (tmp_path / 'no.jsonl').exists()           # keep=False writes nothing
    inline = tmp_path / 'inline.jsonl'          # --diagnose-workers: in this process
    assert blind_family.run_parts([3, 4], 1, 0.0, True, partial=inline, one=fake_row,
                                  code='C', inline=True) == []
    assert [r['index'] for r in blind_family.run_parts(
        [4, 3], 1, float('inf'), True, partial=inline, one=fake_row, code='C',
        inline=True)] == [3, 4]
    assert len(inline.read_text().splitlines()) == 2


def test_the_time_line_compares_the_same_recordings_only():
    """Median, sum and max over the recordings both runs hold (or the indices asked for)."""
    old = [{'index': i, 'seconds': s} for i, s in enumerate([10.0, 20.0, 30.0])]
    new = [{'index': i, 'seconds': s} for i, s in [(1, 40.0), (2, 60.0), (3, 999.0)]]
    assert blind_family.time_ratio(old, new) == (
        'seconds per recording on the same 2 recordings, median: 25 -> 50 (2.0 x); '
        'sum 50 -> 100; max 30 -> 60')
    assert '1 recordings, median: 30 -> 60' in blind_family.time_ratio(old, new, [2])
    assert blind_family.time_ratio(old, new, [7]) == 'no recording in both runs'


def test_the_blocked_tally_splits_findings_by_whether_they_are_effects():
    rows = [{'effects': ['dead_time'], 'found': ['dead_time'], 'blocked': [[3, 0]],
             'unconfirmed': []},
            {'effects': ['creep', 'gain_drift'], 'found': ['gain_drift', 'sensor_lag'],
             'blocked': [[2, 1], [3, 1]], 'unconfirmed': ['creep']},
            {'effects': [], 'found': [], 'blocked': [], 'unconfirmed': ['offset_drift']},
            {'effects': ['saturation'], 'found': ['saturation'], 'blocked': [[1, 0]]}]
    text = blind_family.blocked_tally(rows)       # the last row: a run before the rule
    assert text.startswith('Blocked cross-validation (3 recordings)')
    assert 'effect of their recording confirmed 2/3' in text
    assert 'findings: 0: 1, 1: 1)' in text
    assert 'not an effect not confirmed 1/2' in text
    assert 'not in these rows' in blind_family.blocked_tally(rows[3:])


def test_the_clean_draw_figures_set_apart_what_the_split_costs_the_chain(tmp_path,
                                                                         monkeypatch):
    """Recordings whose clean draw the chain misses are set apart; the rest scored per effect."""
    import blind_effect_costs as costs
    rows = [{**fake_row(i), 'effects': e, 'found': f, 'cost': c}
            for i, e, f, c in ((0, ['a'], ['a'], 9.0),           # judgeable, right
                               (1, ['a', 'b'], ['a'], 9.0),      # b costs little alone
                               (2, ['a'], [], 9.0),              # the clean draw is missed
                               (3, ['b'], [], 2.0),              # costs <= 3 x: not counted
                               (4, [], [], 1.0))]                # clean: not drawn again
    clean = {'0': 1.0, '1': 1.2, '2': 8.0, '3': 1.0}
    train = {'0': 1.0, '1': 1.0, '2': 2.5, '3': 1.0}       # #2's training fit stopped above
    (tmp_path / 'clean.json').write_text(json.dumps({'cost': clean, 'train': train}))
    (tmp_path / 'alone.json').write_text(json.dumps({'1': {'a': 9.0, 'b': 1.1}}))
    monkeypatch.setattr(costs, 'CLEAN_OUT', tmp_path / 'clean.json')
    monkeypatch.setattr(costs, 'OUT', tmp_path / 'alone.json')
    monkeypatch.setattr(costs, '_beyond_training_levels', lambda index: (0.0, 0.0))
    text = costs.clean_figures(rows, blind_family._right)
    assert '1 of the 4 clean draws are missed by more than 3 x' in text
    assert '0 of the 1 fit their training part within 1.5 x' in text and '#2 (2.50 x)' in text
    assert 'clean draw within 1.5 x: every effect named, nothing else | 1/2 |' in text
    assert '| 1: #2 (9.0 x, clean 8.0 x) |' in text
    assert 'within 1.5 x: named | 2/2 |' in text        # a in #0 and a in #1; b alone 1.1 x
    assert 'no finding that is not an effect | 2/2 |' in text
    (tmp_path / 'clean.json').write_text(json.dumps({'cost': {'0': 1.0}, 'train': {'0': 1.0}}))
    assert costs.clean_figures(rows, blind_family._right) == ''       # #1, #2 not costed
    (tmp_path / 'clean.json').write_text(json.dumps(clean))          # the format before 'train'
    assert costs.clean_figures(rows, blind_family._right) == ''


def test_a_draw_without_its_effects_keeps_everything_else():
    """``draw(i, only=frozenset())``: the same command and chain, no effect applied."""
    with_effects = blind_family.draw(138)
    clean = blind_family.draw(138, only=frozenset())
    assert with_effects['effects'] and not clean['effects']
    assert (clean['command'] == with_effects['command']).all()
    assert clean['chain_params'] == with_effects['chain_params']
    assert not (clean['measurement'] == with_effects['measurement']).all()
    assert (blind_family.draw(2, only=frozenset())['measurement']
            == blind_family.draw(2)['measurement']).all()       # #2 is clean: the same bits


def test_the_gaass_comparison_counts_both_ways(tmp_path, monkeypatch):
    """Clean draws that came within 1.5 x with other GAASS settings, and those that left."""
    import blind_effect_costs as costs
    old = {'cost': {'1': 4.0, '2': 1.0, '3': 2.0}, 'train': {'1': 2.0, '2': 1.0, '3': 1.0}}
    new = {'cost': {'1': 1.2, '2': 1.6, '3': 2.0}, 'train': {'1': 1.0, '2': 1.0, '3': 1.0}}
    (tmp_path / 'clean.json').write_text(json.dumps(old))
    (tmp_path / 'clean_s10g500.json').write_text(json.dumps(new))
    monkeypatch.setattr(costs, 'CLEAN_OUT', tmp_path / 'clean.json')
    text = costs.gaass_comparison(costs._gaass_out([10, 500]))
    assert 'held-out cost > 1.5 x: 2 -> 2' in text and 'held-out cost > 3.0 x: 1 -> 0' in text
    assert 'training fit > 1.5 x: 1 -> 0' in text
    assert 'within 1.5 x now, not before: #1 (4.0 -> 1.20)' in text
    assert 'within 1.5 x before, not now: #2 (1.00 -> 1.6)' in text
