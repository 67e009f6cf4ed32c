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

"""What an ``unknown`` verdict rests on, in words (issue 14 item 2).

The figures are those of blind #3 and #13 of ``bench/blind_family.py`` (their JSON
diagnoses, 2026-11-28) and of the hum recording of ``test_empirical.py``.
"""

from __future__ import annotations

from hyst_id.diagnosis.report import unknown_reading


def test_a_miss_only_after_the_split_is_said_to_be_undecided_by_the_split():
    """Blind #3: training 1.22 x, held out 17.7 x, the whole record 1.45 x."""
    lines = unknown_reading(17.72, 1.22, 1.45, [('supply_decay', 1.07),
                                                ('static_nonlinearity', 1.19)])
    text = ' '.join(lines)
    assert 'makes the whole record at 1.45 x' in text and 'the miss sits after the split' in text
    assert 'this split cannot say which mechanism it is' in text
    assert 'supply_decay (1.07 x), static_nonlinearity (1.19 x)' in text


def test_a_miss_the_whole_record_shares_is_in_the_data():
    """Blind #13: training 2.8 x, held out 15.4 x, the whole record 5.0 x; a lag is true."""
    lines = unknown_reading(15.4, 2.8, 4.97, [('creep', 0.98), ('sensor_lag', 0.98),
                                              ('gain_drift', 2.7)])
    text = ' '.join(lines)
    assert 'leaves 4.97 x the floor over the whole record' in text
    assert 'cannot say which mechanism' not in text
    assert 'creep (0.98 x), sensor_lag (0.98 x)' in text and 'gain_drift' not in text


def test_a_whole_record_fit_as_far_off_as_the_held_out_part_is_in_the_data():
    """Near the floor over the whole record, but no nearer than held out: not the split's doing."""
    text = ' '.join(unknown_reading(2.0, 1.1, 1.8, []))
    assert 'leaves 1.80 x the floor over the whole record' in text
    assert 'the miss sits after the split' not in text


def test_without_a_whole_record_fit_or_candidates_only_the_split_is_read():
    """A held-out miss near the floor in training: the split sentence alone."""
    assert len(unknown_reading(4.0, 1.1, None, [])) == 1
    assert unknown_reading(4.0, 3.0, None, [('creep', 2.0)]) == []
