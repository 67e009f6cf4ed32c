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

"""Every physical constant of the rig simulator, with units, and its YAML file.

The defaults are the plain pipeline configuration (``params/pipeline.yaml``):
the paper's rig (section 4) with supply regulation on and every optional
effect off. ``docs/rig.md`` gives the source or assumption behind each value.

File layout: a ROS 2 params file, nested groups under the node's
``ros__parameters`` (ROS flattens them to dotted names)::

    pipeline_sim:
      ros__parameters:
        supply:
          regulation: true
        effects:
          dead_time:
            enabled: false

:func:`load_rig_params` also accepts the same groups without the
``<node>: ros__parameters:`` wrapper, and dotted keys (``supply.regulation``)
at any level. In a ROS-wrapped file, top-level keys that are not rig groups
belong to the node and are ignored; anywhere else an unknown key is an error.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, is_dataclass
import math
from typing import Any, Mapping

import numpy as np

from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.models.backlash import check_backlash
from hyst_id.models.tk import check_hysteresis
from hyst_id.rig.effects import Effects
from hyst_id.rig.physics import FLOW_MODELS, STANDARD_ATMOSPHERE_PA

__all__ = [
    'GasParams', 'SupplyParams', 'PipeParams', 'ManualValveParams', 'ControlValveParams',
    'ActuatorParams', 'PositionSensorParams', 'PressureSensorParams', 'FlowSensorParams',
    'IntegrationParams', 'RIG_GROUPS', 'RigParams', 'rig_params_from_dict',
    'rig_params_to_dict',
]


def _positive(obj: Any, *names: str, allow_zero: bool = False) -> None:
    for name in names:
        v = getattr(obj, name)
        if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
            rel = '>= 0' if allow_zero else '> 0'
            raise ConfigError(f'{_GROUP_OF[type(obj)]}.{name} must be finite and {rel}, '
                              f'got {v}')


def _adc(obj: Any, lo: str, hi: str) -> None:
    group = _GROUP_OF[type(obj)]
    if not 0 <= obj.adc_bits <= 32:
        raise ConfigError(f'{group}.adc_bits must be 0 (no quantisation) to 32, '
                          f'got {obj.adc_bits}')
    if not (math.isfinite(getattr(obj, lo)) and math.isfinite(getattr(obj, hi))
            and getattr(obj, lo) < getattr(obj, hi)):
        raise ConfigError(f'{group}.{lo} must be below {group}.{hi}')


@dataclass(frozen=True)
class GasParams:
    """Air and surroundings: gas constant J/(kg K), gamma, room temperature K, ambient Pa."""

    r_j_kg_k: float = 287.05
    gamma: float = 1.4
    temperature_k: float = 293.15
    ambient_pressure_pa: float = STANDARD_ATMOSPHERE_PA

    def __post_init__(self) -> None:
        _positive(self, 'r_j_kg_k', 'temperature_k', 'ambient_pressure_pa')
        if not 1.0 < self.gamma <= 5.0 / 3.0:
            raise ConfigError(f'gas.gamma must be in (1, 5/3], got {self.gamma}')


@dataclass(frozen=True)
class SupplyParams:
    """Two 180-gal vessels fed by a compressor; optional pressure regulation.

    ``regulation: true`` holds the vessels at ``regulator_setpoint_pa`` with a
    proportional compressor/regulator inflow (gain kg/(s Pa), capped at
    ``regulator_max_flow_g_s``); ``false`` lets them blow down, fed only by
    ``compressor_flow_g_s`` (the paper's rig, with the compressor idle).
    """

    vessel_volume_m3: float = 0.681374  # 180 US gal
    vessel_count: int = 2
    initial_pressure_pa: float = 790800.7  # 100 psig
    polytropic_n: float = 1.0
    regulation: bool = True
    regulator_setpoint_pa: float = 790800.7
    regulator_gain_kg_s_pa: float = 2.0e-5
    regulator_max_flow_g_s: float = 200.0
    compressor_flow_g_s: float = 0.0

    def __post_init__(self) -> None:
        _positive(self, 'vessel_volume_m3', 'initial_pressure_pa', 'regulator_setpoint_pa',
                  'regulator_gain_kg_s_pa', 'regulator_max_flow_g_s')
        _positive(self, 'compressor_flow_g_s', allow_zero=True)
        if self.vessel_count < 1:
            raise ConfigError(f'supply.vessel_count must be >= 1, got {self.vessel_count}')

    @property
    def volume_m3(self) -> float:
        """Total vessel volume."""
        return self.vessel_volume_m3 * self.vessel_count


@dataclass(frozen=True)
class PipeParams:
    """Line between the manual and the control valve: 3/4" airline plus 2" PVC."""

    airline_diameter_m: float = 0.01905  # 3/4"
    airline_length_m: float = 3.0
    pvc_diameter_m: float = 0.0508  # 2"
    pvc_length_m: float = 4.0

    def __post_init__(self) -> None:
        _positive(self, 'airline_diameter_m', 'pvc_diameter_m')
        _positive(self, 'airline_length_m', 'pvc_length_m', allow_zero=True)
        if self.volume_m3 <= 0:
            raise ConfigError('pipe volume is zero: give a section a length')

    @property
    def volume_m3(self) -> float:
        """Volume ``V_1`` whose pressure ``p_1`` the transducer reads."""
        return math.pi / 4.0 * (self.airline_diameter_m ** 2 * self.airline_length_m
                                + self.pvc_diameter_m ** 2 * self.pvc_length_m)


@dataclass(frozen=True)
class ManualValveParams:
    """Upstream 1" manual ball valve, throttled to hold about 30 psig at the nominal flow."""

    bore_diameter_m: float = 0.0254
    area_m2: float = 1.0905e-5
    critical_ratio: float = 0.25

    def __post_init__(self) -> None:
        _positive(self, 'bore_diameter_m', 'area_m2')
        _check_area(self, 'area_m2')
        _check_ratio(self)


@dataclass(frozen=True)
class ControlValveParams:
    """3/4" ball valve on the actuator: position -> opening -> effective area.

    ``opening = clip((position - position_closed)/(position_open -
    position_closed), 0, 1)`` (4-20 mA-equivalent travel), area
    ``leak + (max - leak) f(opening)`` with ``f`` linear unless the
    ``valve_characteristic`` effect is on.
    """

    bore_diameter_m: float = 0.01905
    max_area_m2: float = 8.8e-5
    leak_area_m2: float = 0.0
    critical_ratio: float = 0.30
    position_closed: float = 4.0
    position_open: float = 20.0

    def __post_init__(self) -> None:
        _positive(self, 'bore_diameter_m', 'max_area_m2')
        _positive(self, 'leak_area_m2', allow_zero=True)
        _check_area(self, 'max_area_m2')
        if self.leak_area_m2 >= self.max_area_m2:
            raise ConfigError('control_valve.leak_area_m2 must be below max_area_m2')
        if not self.position_closed < self.position_open:
            raise ConfigError('control_valve.position_closed must be below position_open')
        _check_ratio(self)


def _check_area(obj: Any, name: str) -> None:
    bore = math.pi / 4.0 * obj.bore_diameter_m ** 2
    if getattr(obj, name) > bore:
        raise ConfigError(f'{_GROUP_OF[type(obj)]}.{name} = {getattr(obj, name):.4g} m^2 '
                          f'exceeds the bore area {bore:.4g} m^2')


def _check_ratio(obj: Any) -> None:
    if not 0.0 < obj.critical_ratio < 0.99:
        raise ConfigError(f'{_GROUP_OF[type(obj)]}.critical_ratio must be in (0, 0.99), '
                          f'got {obj.critical_ratio}')


@dataclass(frozen=True)
class ActuatorParams:
    """Induced hysteresis H (paper section 4) and the drive's backlash B.

    H maps the command (mA) to the positioner set point, B the set point to
    the valve position (position units, "mA-equivalent" on a 4-20 mA scale).
    """

    m_l: float = 1.01
    m_r: float = 1.05
    m_t: float = 0.10
    m_b: float = 0.15
    c_l: float = -0.25
    c_r: float = 0.50
    c_t: float = 14.00
    c_b: float = 7.00
    m_bl: float = 1.10
    c_bl: float = 0.54
    c_br: float = 1.09

    def __post_init__(self) -> None:
        try:
            check_hysteresis(self.hysteresis)
            check_backlash(self.backlash)
        except InvalidParametersError as exc:
            raise ConfigError(f'actuator: {exc}') from None

    @property
    def hysteresis(self) -> np.ndarray:
        """``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``."""
        return np.array([self.m_l, self.m_r, self.m_t, self.m_b,
                         self.c_l, self.c_r, self.c_t, self.c_b])

    @property
    def backlash(self) -> np.ndarray:
        """``(m_bl, c_bl, c_br)``."""
        return np.array([self.m_bl, self.c_bl, self.c_br])


@dataclass(frozen=True)
class PositionSensorParams:
    """Position sensor (no dynamics): white noise and A/D (``adc_bits`` 0: none)."""

    noise_std: float = 0.005
    adc_bits: int = 12
    range_min: float = 0.0
    range_max: float = 25.0

    def __post_init__(self) -> None:
        _positive(self, 'noise_std', allow_zero=True)
        _adc(self, 'range_min', 'range_max')


@dataclass(frozen=True)
class PressureSensorParams:
    """Static pressure transducer on ``p_1``: first-order lag, noise, A/D.

    ``reference``: ``absolute`` (``sensor_msgs/FluidPressure``) or ``gauge``.
    """

    tau_s: float = 0.02
    noise_std_pa: float = 300.0
    adc_bits: int = 12
    range_min_pa: float = 0.0
    range_max_pa: float = 1.0e6
    reference: str = 'absolute'

    def __post_init__(self) -> None:
        _positive(self, 'tau_s', 'noise_std_pa', allow_zero=True)
        _adc(self, 'range_min_pa', 'range_max_pa')
        if self.reference not in ('absolute', 'gauge'):
            raise ConfigError("pressure_sensor.reference must be 'absolute' or 'gauge', "
                              f'got {self.reference!r}')


@dataclass(frozen=True)
class FlowSensorParams:
    """Thermal mass-flow sensor downstream: second order (underdamped), noise, A/D."""

    zeta: float = 0.5
    omega_n_rad_s: float = 1.5
    noise_std_g_s: float = 0.05
    adc_bits: int = 12
    range_min_g_s: float = 0.0
    range_max_g_s: float = 100.0

    def __post_init__(self) -> None:
        _positive(self, 'zeta', 'omega_n_rad_s')
        _positive(self, 'noise_std_g_s', allow_zero=True)
        _adc(self, 'range_min_g_s', 'range_max_g_s')


@dataclass(frozen=True)
class IntegrationParams:
    """Longest substep of the integrator (s) and the orifice flow law."""

    max_substep_s: float = 0.005
    flow_model: str = 'iso6358'

    def __post_init__(self) -> None:
        _positive(self, 'max_substep_s')
        if self.flow_model not in FLOW_MODELS:
            raise ConfigError(f'integration.flow_model must be one of {FLOW_MODELS}, '
                              f'got {self.flow_model!r}')


@dataclass(frozen=True)
class RigParams:
    """The whole rig; every field a group of the YAML file."""

    gas: GasParams = field(default_factory=GasParams)
    supply: SupplyParams = field(default_factory=SupplyParams)
    pipe: PipeParams = field(default_factory=PipeParams)
    manual_valve: ManualValveParams = field(default_factory=ManualValveParams)
    control_valve: ControlValveParams = field(default_factory=ControlValveParams)
    actuator: ActuatorParams = field(default_factory=ActuatorParams)
    position_sensor: PositionSensorParams = field(default_factory=PositionSensorParams)
    pressure_sensor: PressureSensorParams = field(default_factory=PressureSensorParams)
    flow_sensor: FlowSensorParams = field(default_factory=FlowSensorParams)
    integration: IntegrationParams = field(default_factory=IntegrationParams)
    effects: Effects = field(default_factory=Effects)

    def __post_init__(self) -> None:
        p_amb = self.gas.ambient_pressure_pa
        for name in ('initial_pressure_pa', 'regulator_setpoint_pa'):
            if getattr(self.supply, name) <= p_amb:
                raise ConfigError(f'supply.{name} must exceed gas.ambient_pressure_pa')
        if self.supply.polytropic_n > self.gas.gamma or self.supply.polytropic_n < 1.0:
            raise ConfigError('supply.polytropic_n must be in [1, gas.gamma] '
                              '(1 isothermal, gamma adiabatic)')

    def with_values(self, values: Mapping[str, Any]) -> 'RigParams':
        """Copy with some values replaced, by dotted name (``'supply.regulation'``)."""
        data = rig_params_to_dict(self)
        _merge(data, _unflatten(dict(values)))
        return rig_params_from_dict(data)


_GROUPS = {f.name: f.default_factory for f in fields(RigParams)}
#: The rig's parameter groups, in declaration order.
RIG_GROUPS = tuple(_GROUPS)
_GROUP_OF = {cls: name for name, cls in _GROUPS.items()}


def _unflatten(data: Mapping[str, Any]) -> dict:
    """Nested dict from a mapping whose keys may be dotted paths."""
    out: dict = {}
    for key, value in data.items():
        if not isinstance(key, str):
            raise ConfigError(f'parameter names must be strings, got {key!r}')
        if isinstance(value, Mapping):
            value = _unflatten(value)
        parts = key.split('.')
        node = out
        for part in parts[:-1]:
            nxt = node.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise ConfigError(f'{key}: {part} is both a value and a group')
            node = nxt
        if parts[-1] in node and isinstance(node[parts[-1]], dict) and isinstance(value, dict):
            _merge(node[parts[-1]], value)
        else:
            node[parts[-1]] = value
    return out


def _merge(base: dict, new: Mapping) -> None:
    for key, value in new.items():
        if isinstance(value, Mapping) and isinstance(base.get(key), dict):
            _merge(base[key], value)
        else:
            base[key] = value


def _coerce(where: str, value: Any, default: Any) -> Any:
    if isinstance(default, float) and isinstance(value, str):
        try:  # PyYAML reads 1e6 (no exponent sign) as a string
            value = float(value)
        except ValueError:
            pass
    kind, ok = {
        bool: ('true or false', isinstance(value, bool)),
        int: ('an integer', not isinstance(value, bool) and (
            isinstance(value, int) or (isinstance(value, float) and value.is_integer()))),
        float: ('a number', not isinstance(value, bool) and isinstance(value, (int, float))),
        str: ('a string', isinstance(value, str)),
    }[type(default)]
    if not ok:
        raise ConfigError(f'{where} must be {kind}, got {value!r}')
    return type(default)(value)


def _build(cls: type, data: Any, where: str) -> Any:
    if not isinstance(data, Mapping):
        raise ConfigError(f'{where} must be a mapping of parameters, got {data!r}')
    proto = cls()
    known = {f.name: f for f in fields(cls)}
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ConfigError(f'unknown parameter(s) in {where}: {unknown}; known: {sorted(known)}')
    kwargs = {}
    for name, value in data.items():
        default = getattr(proto, name)
        if is_dataclass(default):
            kwargs[name] = _build(type(default), value, f'{where}.{name}')
        else:
            kwargs[name] = _coerce(f'{where}.{name}', value, default)
    return cls(**kwargs)


def rig_params_from_dict(data: Mapping[str, Any], *, allow_unknown: bool = False) -> RigParams:
    """Build and validate :class:`RigParams` from nested and/or dotted groups.

    Parameters
    ----------
    data : mapping
        Groups as in the YAML file; missing values take the defaults.
    allow_unknown : bool
        Ignore top-level keys that are not rig groups (node parameters).

    Raises
    ------
    ConfigError
        Unknown group or parameter, wrong type, or a value out of range.
    """
    nested = _unflatten(data)
    unknown = sorted(set(nested) - set(_GROUPS))
    if unknown and not allow_unknown:
        raise ConfigError(f'unknown parameter group(s) {unknown}; known: {sorted(_GROUPS)}')
    groups = {name: _build(_GROUPS[name], nested[name], name)
              for name in _GROUPS if name in nested}
    return RigParams(**groups)


def rig_params_to_dict(params: RigParams) -> dict:
    """Nested plain dict of every value (the inner part of the YAML file)."""
    return asdict(params)
