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

"""Numbers printed with the digits their span needs (``hyst_id.io.numbers``)."""

from __future__ import annotations

import math

from hyst_id.io.numbers import level


def test_an_offset_keeps_the_digits_that_tell_levels_apart():
    # a command 2-18 offset by a million printed '1e+06' for every level
    assert level(1000002.015, 16.0) == '1000002.02'
    assert level(1000002.015, 16.0) != level(1000017.99, 16.0)
    assert level(12.3456, 16.0) == '12.35'            # no offset: four digits as before
    assert level(0.0, 1.0) == '0' and level(3.0, 0.0) == '3'
    assert level(math.inf, 1.0) == 'inf'
