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

"""Range checks of settings objects at construction, so the API refuses what it cannot run.

An independent fuzz review found ``IdentifySettings(seeds=(-1,))`` failing inside
numpy with a bare ``ValueError``, and negative workers, restarts or hops, an
unknown ``conventions`` or a negative %e_r bound accepted silently; the CLI
refused their equivalents only because it checks its own options
(:mod:`hyst_id.identification.config`).
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any, Iterable, Mapping

from hyst_id.errors import ConfigError

__all__ = ['check_fields']


def check_fields(obj: Any, *, at_least: Mapping[str, int] = {},
                 positive: Iterable[str] = (), choices: Mapping[str, tuple] = {},
                 seeds: str = '') -> None:
    """Raise :class:`~hyst_id.errors.ConfigError` for the first field out of its range.

    Parameters
    ----------
    obj : object
        A settings dataclass.
    at_least : mapping
        Integer fields and their least value.
    positive : iterable of str
        Real fields that must be finite and > 0 (None allowed: "not set").
    choices : mapping
        Fields and the values they may take.
    seeds : str
        A field holding a sequence of seeds (integers >= 0), or ''.
    """
    kind = type(obj).__name__
    for name, least in at_least.items():
        value = getattr(obj, name)
        if isinstance(value, bool) or not isinstance(value, Integral) or value < least:
            raise ConfigError(f'{kind}.{name} must be an integer >= {least}, got {value!r}')
    for name in positive:
        value = getattr(obj, name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, Real)
                                  or not 0.0 < float(value) < math.inf):
            raise ConfigError(f'{kind}.{name} must be a finite number > 0, got {value!r}')
    for name, allowed in choices.items():
        if getattr(obj, name) not in allowed:
            raise ConfigError(f'{kind}.{name} must be one of {allowed}, '
                              f'got {getattr(obj, name)!r}')
    if seeds:
        for s in getattr(obj, seeds):
            if isinstance(s, bool) or not isinstance(s, Integral) or s < 0:
                raise ConfigError(f'{kind}.{seeds} must be integers >= 0, got {s!r}')
