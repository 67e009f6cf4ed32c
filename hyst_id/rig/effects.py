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

"""Optional effects that make the rig differ from the identification model.

Each effect is off by default and is a small parameter dataclass plus the
numba function(s) the simulator calls where the effect physically acts
(see ``docs/rig.md``):

=======================  =============================================  ===================
effect                   where it acts                                  function
=======================  =============================================  ===================
``dead_time``            command, before the actuator (D/A, bus)        :func:`delay_push`,
                                                                        :func:`delay_lookup`
``rate_hysteresis``      H: loop widens with the command rate           :func:`rate_filter_step`
``stick_slip``           actuator position (stiction in the drive)      :func:`stick_slip_step`
``end_stops``            actuator position (mechanical travel stops)    :func:`end_stop`
``valve_characteristic`` opening -> valve flow area                     :func:`valve_area_fraction`
``sensor_lag``           extra first-order lag on every sensor          (sensors'
                                                                        ``first_order_coefficient``)
``offset_drift``         slow additive offset on every sensor           (ramp + random walk)
=======================  =============================================  ===================

Supply pressure decay is not here: it is the rig's own physics with the
regulation switched off (``supply.regulation: false``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math

from numba import njit
import numpy as np

from hyst_id.errors import ConfigError

__all__ = [
    'DeadTime',
    'SensorLag',
    'StickSlip',
    'EndStops',
    'OffsetDrift',
    'RateHysteresis',
    'ValveCharacteristic',
    'Effects',
    'CHARACTERISTIC_KINDS',
    'DELAY_CAPACITY',
    'delay_push',
    'delay_lookup',
    'stick_slip_step',
    'end_stop',
    'rate_filter_step',
    'valve_area_fraction',
]

#: Valve characteristic kinds, in the code order the kernel uses.
CHARACTERISTIC_KINDS = ('linear', 'equal_percentage', 'power')

#: Most command samples the dead-time line can hold in flight.
DELAY_CAPACITY = 16384


def _check(effect: object, name: str, ok: bool, message: str) -> None:
    """Raise ConfigError for a non-finite parameter or when ``ok`` is False."""
    for key, value in vars(effect).items():
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f'effects.{name}.{key} must be finite, got {value}')
    if not ok:
        raise ConfigError(f'effects.{name}: {message}')


@dataclass(frozen=True)
class DeadTime:
    """Transport delay between the command and the actuator.

    Attributes
    ----------
    enabled : bool
        Switch.
    delay_s : float
        Delay in seconds (D/A, field bus, positioner scan).
    """

    enabled: bool = False
    delay_s: float = 0.2

    def __post_init__(self) -> None:
        _check(self, 'dead_time', self.delay_s >= 0, 'delay_s must be >= 0')


@dataclass(frozen=True)
class SensorLag:
    """Unmodelled first-order lag on each sensor output (0 s: none on that sensor).

    Attributes
    ----------
    position_tau_s, pressure_tau_s, flow_tau_s : float
        Extra time constants in seconds, in series with the modelled dynamics.
    """

    enabled: bool = False
    position_tau_s: float = 0.3
    pressure_tau_s: float = 0.5
    flow_tau_s: float = 0.5

    def __post_init__(self) -> None:
        _check(self, 'sensor_lag',
               min(self.position_tau_s, self.pressure_tau_s, self.flow_tau_s) >= 0,
               'time constants must be >= 0')


@dataclass(frozen=True)
class StickSlip:
    """Stiction in the actuator drive (two-parameter stick-slip model).

    The position stays put while the drive's demanded position is within
    ``static_band`` of it; once beyond, it slips to ``dynamic_band`` short of
    the demand. A ramp therefore becomes a staircase with steps of about
    ``static_band - dynamic_band``.

    Attributes
    ----------
    static_band : float
        Breakaway band, position units.
    dynamic_band : float
        Band left after a slip, position units (``0 <= dynamic < static``).
    """

    enabled: bool = False
    static_band: float = 0.15
    dynamic_band: float = 0.05

    def __post_init__(self) -> None:
        _check(self, 'stick_slip', 0 <= self.dynamic_band < self.static_band,
               'needs 0 <= dynamic_band < static_band')


@dataclass(frozen=True)
class EndStops:
    """Mechanical travel stops: the actuator position saturates.

    Attributes
    ----------
    min_position, max_position : float
        Stops, position units. The defaults sit inside the paper's Eq. 24
        travel so that the effect shows.
    """

    enabled: bool = False
    min_position: float = 8.5
    max_position: float = 10.5

    def __post_init__(self) -> None:
        _check(self, 'end_stops', self.min_position < self.max_position,
               'min_position must be below max_position')


@dataclass(frozen=True)
class OffsetDrift:
    """Slow additive sensor offsets: a linear ramp plus a random walk.

    Attributes
    ----------
    position_per_s, pressure_pa_per_s, flow_g_s_per_s : float
        Ramp rates.
    position_walk_per_sqrt_s, pressure_walk_pa_per_sqrt_s, flow_walk_g_s_per_sqrt_s : float
        Random-walk intensities (standard deviation after one second).
    """

    enabled: bool = False
    position_per_s: float = 0.002
    pressure_pa_per_s: float = 100.0
    flow_g_s_per_s: float = 0.01
    position_walk_per_sqrt_s: float = 0.0
    pressure_walk_pa_per_sqrt_s: float = 0.0
    flow_walk_g_s_per_sqrt_s: float = 0.0

    def __post_init__(self) -> None:
        _check(self, 'offset_drift', min(self.position_walk_per_sqrt_s,
                                         self.pressure_walk_pa_per_sqrt_s,
                                         self.flow_walk_g_s_per_sqrt_s) >= 0,
               'random-walk intensities must be >= 0')


@dataclass(frozen=True)
class RateHysteresis:
    """Rate-dependent hysteresis: the loop widens with the command rate.

    The left and right crossings move apart by ``width_per_rate_s * r``
    each, where ``r`` is the command rate magnitude (mA/s) low-passed with
    ``filter_tau_s`` (eddy currents and viscous drag grow with speed).

    Attributes
    ----------
    width_per_rate_s : float
        Extra half-width of the loop, in mA per mA/s (seconds).
    filter_tau_s : float
        Time constant of the rate estimate, seconds (> 0).
    """

    enabled: bool = False
    width_per_rate_s: float = 0.5
    filter_tau_s: float = 1.0

    def __post_init__(self) -> None:
        _check(self, 'rate_hysteresis', self.width_per_rate_s >= 0 and self.filter_tau_s > 0,
               'needs width_per_rate_s >= 0 and filter_tau_s > 0')


@dataclass(frozen=True)
class ValveCharacteristic:
    """Nonlinear flow characteristic of the ball valve (default map is linear).

    ``equal_percentage``: ``f(x) = (R^x - 1)/(R - 1)`` with rangeability
    ``R``; ``power``: ``f(x) = x^n``. ``x`` is the opening in [0, 1], ``f``
    the fraction of the full-open flow area.
    """

    enabled: bool = False
    kind: str = 'equal_percentage'
    rangeability: float = 20.0
    exponent: float = 2.0

    def __post_init__(self) -> None:
        _check(self, 'valve_characteristic', self.kind in CHARACTERISTIC_KINDS,
               f'kind must be one of {CHARACTERISTIC_KINDS}, got {self.kind!r}')
        _check(self, 'valve_characteristic', self.rangeability > 1 and self.exponent > 0,
               'needs rangeability > 1 and exponent > 0')


@dataclass(frozen=True)
class Effects:
    """All optional effects (every one off by default)."""

    dead_time: DeadTime = field(default_factory=DeadTime)
    sensor_lag: SensorLag = field(default_factory=SensorLag)
    stick_slip: StickSlip = field(default_factory=StickSlip)
    end_stops: EndStops = field(default_factory=EndStops)
    offset_drift: OffsetDrift = field(default_factory=OffsetDrift)
    rate_hysteresis: RateHysteresis = field(default_factory=RateHysteresis)
    valve_characteristic: ValveCharacteristic = field(default_factory=ValveCharacteristic)

    @property
    def enabled(self) -> tuple[str, ...]:
        """Names of the effects switched on."""
        return tuple(name for name in self.__dataclass_fields__
                     if getattr(self, name).enabled)


@njit(cache=True)
def delay_push(buf: np.ndarray, head: int, count: int, t_start_s: float,
               value: float) -> tuple[int, int]:
    """Append ``(t_start_s, value)`` to the ring buffer; return ``(head, count)``.

    ``count`` is returned as -1 when the buffer is full (the caller reports it).
    """
    cap = buf.shape[0]
    if count >= cap:
        return head, -1
    k = (head + count) % cap
    buf[k, 0] = t_start_s
    buf[k, 1] = value
    return head, count + 1


@njit(cache=True)
def delay_lookup(buf: np.ndarray, head: int, count: int,
                 t_query_s: float) -> tuple[float, int, int]:
    """Value active at ``t_query_s`` (latest entry starting before it).

    Queries must not go back in time: older entries are dropped.
    Returns ``(value, head, count)``.
    """
    cap = buf.shape[0]
    while count > 1 and buf[(head + 1) % cap, 0] < t_query_s:
        head = (head + 1) % cap
        count -= 1
    return buf[head, 1], head, count


@njit(cache=True, inline='always')
def stick_slip_step(demand: float, x_prev: float, static_band: float,
                    dynamic_band: float) -> float:
    """Position after stiction: stuck within ``static_band``, else slip."""
    d = demand - x_prev
    if abs(d) <= static_band:
        return x_prev
    return demand - math.copysign(dynamic_band, d)


@njit(cache=True, inline='always')
def end_stop(x: float, lo: float, hi: float) -> float:
    """Position limited by the travel stops."""
    return min(max(x, lo), hi)


@njit(cache=True, inline='always')
def rate_filter_step(r: float, dv_abs: float, h_s: float, tau_s: float) -> float:
    """Low-passed command rate after a substep of ``h_s`` in which it moved ``dv_abs``."""
    return r * math.exp(-h_s / tau_s) + dv_abs / tau_s


@njit(cache=True, inline='always')
def valve_area_fraction(x: float, kind: int, rangeability: float, exponent: float) -> float:
    """Fraction of the full-open flow area at opening ``x`` in [0, 1]."""
    if kind == 1:
        return (rangeability ** x - 1.0) / (rangeability - 1.0)
    if kind == 2:
        return x ** exponent
    return x
