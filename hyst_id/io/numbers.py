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
"""Numbers in words: enough digits to tell apart what differs within a span.

``f'{x:.4g}'`` prints a command of 1000002.015 as ``1e+06``: on a record
offset by a million every level reads the same (found by an independent
review). :func:`level` keeps the digits that resolve a ten-thousandth of the
span the number lives in.
"""

from __future__ import annotations

import math

__all__ = ['level']


def level(x: float, span: float, digits: int = 4) -> str:
    """``x`` with ``digits`` significant digits, more when its offset hides the ``span``.

    Parameters
    ----------
    x : float
        The value (a command level, a bound).
    span : float
        The range it is read against (the command's span, a domain's width);
        the digits kept resolve ``span / 10**digits``.
    digits : int
        Significant digits of a value whose magnitude is near its span.
    """
    x, span = float(x), abs(float(span))
    if not (math.isfinite(x) and math.isfinite(span)) or x == 0.0 or span == 0.0:
        return f'{x:.{digits}g}'
    extra = max(0, math.ceil(math.log10(abs(x) / span)))
    return f'{x:.{min(digits + extra, 17)}g}'
