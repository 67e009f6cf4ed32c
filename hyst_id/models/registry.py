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

"""The registry of hysteresis families: one line per family module.

Adding a family is one module defining a
:class:`~hyst_id.models.family.HysteresisFamily` subclass and a module-level
``FAMILY`` instance, plus one entry in :data:`MODULES` below
(``docs/model.md``, "Adding a hysteresis family").
"""

from __future__ import annotations

from hyst_id.errors import ConfigError
from hyst_id.models import smooth, tk
from hyst_id.models.family import HysteresisFamily

__all__ = ['DEFAULT_FAMILY', 'FAMILIES', 'MODULES', 'get_family']

#: The family modules, in the order they are listed.
MODULES = (
    tk,
    smooth,
)

#: Every family by id.
FAMILIES: dict[str, HysteresisFamily] = {m.FAMILY.id: m.FAMILY for m in MODULES}

#: The family used when none is named: the paper's.
DEFAULT_FAMILY = 'tk'


def get_family(family: str | HysteresisFamily | None = None) -> HysteresisFamily:
    """A family by id (the default when None); a family object is returned as it is.

    Raises
    ------
    ConfigError
        Unknown id.
    """
    if isinstance(family, HysteresisFamily):
        return family
    key = DEFAULT_FAMILY if family is None else str(family)
    if key not in FAMILIES:
        raise ConfigError(f'unknown hysteresis family {key!r}; known: {sorted(FAMILIES)}')
    return FAMILIES[key]
