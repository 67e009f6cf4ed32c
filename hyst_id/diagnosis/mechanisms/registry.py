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

"""The registry of mechanisms: one line per mechanism module.

Adding a mechanism is one module exposing ``MECHANISM`` (an instance of a
:class:`~hyst_id.diagnosis.mechanisms.base.Mechanism` subclass) and one entry
in the module tuple of :data:`MECHANISMS` below (see ``docs/diagnosis.md``, "Adding a mechanism").
"""

from __future__ import annotations

from hyst_id.diagnosis.mechanisms import (
    actuator_dynamics,
    bouc_wen,
    creep,
    dead_time,
    friction,
    gain_drift,
    gain_loss,
    loop_shape,
    offset_drift,
    rate_dependence,
    rate_limit,
    saturation,
    sensor_lag,
    static_nonlinearity,
    stiction,
    supply_decay,
)
from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, Quantity
from hyst_id.errors import ConfigError

__all__ = ['MECHANISMS', 'MECHANISM_IDS', 'Context', 'Mechanism', 'Quantity', 'get_mechanisms',
           'mechanism_ids']

#: Every mechanism by id, in the issue's order.
MECHANISMS: dict[str, Mechanism] = {m.MECHANISM.id: m.MECHANISM for m in (
    dead_time, sensor_lag, supply_decay, offset_drift, saturation, stiction,
    static_nonlinearity, rate_dependence, loop_shape, gain_drift, gain_loss, creep,
    actuator_dynamics, friction, bouc_wen, rate_limit)}

#: The ids alone.
MECHANISM_IDS = tuple(MECHANISMS)


def mechanism_ids(text: str) -> tuple[str, ...]:
    """Mechanism ids from comma-separated ``text`` (a node parameter); blanks are skipped."""
    return tuple(m.strip() for m in text.split(',') if m.strip())


def get_mechanisms(ids=None, channel: str | None = None) -> list[Mechanism]:
    """Mechanisms by id (all when ``ids`` is None), those that can act on ``channel`` if given.

    Raises
    ------
    ConfigError
        An id is unknown, or a mechanism asked for by id cannot be ``channel``'s
        physics (:attr:`Mechanism.channels`).
    """
    if ids is None:
        mechs = list(MECHANISMS.values())
    else:
        unknown = [i for i in ids if i not in MECHANISMS]
        if unknown:
            raise ConfigError(f'unknown mechanism(s) {unknown}; known: {list(MECHANISM_IDS)}')
        mechs = [MECHANISMS[i] for i in ids]
    off = [m for m in mechs if channel is not None and m.channels is not None
           and channel not in m.channels]
    if ids is not None and off:
        raise ConfigError('; '.join(f'{m.id} cannot act on the {channel} channel (only on '
                                    f'{", ".join(m.channels)})' for m in off))
    return [m for m in mechs if m not in off]
