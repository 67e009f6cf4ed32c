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

"""Pipeline simulator node: command (mA) in, pressure and flow (and position) out.

The plant sits behind :class:`PlantModel` (``step(command_ma, dt_s) ->
PlantReading``). ``plant: simple`` is :class:`SimplePlant`: the simulated
actuator (H then B, :mod:`hyst_id.nodes.actuator_driver`), then a
first-order pressure transducer (Eq. 8) and a second-order thermal flow
sensor (Eq. 9), each followed by an affine calibration into Pa and g/s,
discretised exactly (zero-order hold) as in :mod:`hyst_id.models.sensors`.
``plant: rig`` is the physics simulator of the paper's pneumatic rig,
``hyst_id.rig.RigSimulator``, configured by ``rig_params_file`` (for
example ``params/pipeline.yaml`` or ``params/paper_rig.yaml``); its own
actuator then drives the sensors, and ``publish_position`` makes the node
the whole plant (run it without an actuator_driver).

Samples are stamped with the time the command reached the node (the
middleware's receive timestamp), like the actuator driver's, and sensor
dynamics advance by the time between those stamps (times ``time_scale``),
or by a fixed ``step_s`` of simulated time per command when it is set:
then the simulated run does not depend on when messages arrive, and is
the same on a slow or busy machine (the bringup sets it to each run's
sample period).
With ``topics.flow_type`` ``std_msgs/msg/Float64`` the flow reading has no
header: its time is when it was published, so keep the sample period above
the node's processing delay; ``hyst_id_interfaces/msg/StampedValue`` carries
the reading's stamp (the same as the pressure's). A stamped command
(``topics.command_type``) acts at its own stamp, not when it arrived.

Calibration gains are positive: the identifier's canonical gauge needs a
sensor that rises with the actuator output. Sensor time constants are in
simulated seconds; with ``time_scale`` > 1 the wall-clock stamps of the
messages run that much faster than the simulated plant.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
import math
from typing import Any

from builtin_interfaces.msg import Time
import numpy as np
from sensor_msgs.msg import FluidPressure, JointState

from hyst_id.errors import ConfigError
from hyst_id.models.sensors import first_order_coefficient, second_order_coefficients
from hyst_id.nodes.actuator_driver import (actuator_problem, PAPER_BACKLASH, PAPER_HYSTERESIS,
                                           SimulatedActuator)
from hyst_id.nodes.support import (
    COMMAND_QOS,
    CommandClock,
    HystNode,
    OVERRIDABLE,
    Param,
    resolved,
    scalar_type_param,
    ScalarStream,
    SENSOR_QOS,
    spin_node,
    topic_params,
)

__all__ = ['PARAMS', 'PipelineSim', 'PlantModel', 'PlantReading', 'RigPlant', 'SimplePlant',
           'main', 'make_plant']

_H_NAMES = tuple(PAPER_HYSTERESIS)
_B_NAMES = tuple(PAPER_BACKLASH)


@dataclass(frozen=True)
class PlantReading:
    """One sample of the plant: actuator position, pressure (Pa), mass flow (g/s)."""

    position: float
    pressure_pa: float
    flow_g_s: float


class PlantModel(abc.ABC):
    """What the node needs from a plant: one step per command."""

    @abc.abstractmethod
    def step(self, command_ma: float, dt_s: float) -> PlantReading:
        """Hold ``command_ma`` for ``dt_s`` simulated seconds and return the sensors."""


class SimplePlant(PlantModel):
    """Simulated actuator, first-order pressure and second-order flow sensors.

    Parameters
    ----------
    actuator : SimulatedActuator
        Position source (H then B).
    tau_s : float
        Pressure transducer time constant.
    zeta, omega_n : float
        Flow sensor damping ratio and natural frequency (rad/s).
    pressure_offset_pa, pressure_gain_pa : float
        ``pressure = offset + gain * lagged position``.
    flow_offset_g_s, flow_gain_g_s : float
        ``flow = offset + gain * filtered position``.
    pressure_noise_pa, flow_noise_g_s : float
        Standard deviations of the measurement noise.
    seed : int
        Noise seed.
    """

    def __init__(self, actuator: SimulatedActuator, tau_s: float = 1.79, zeta: float = 0.51,
                 omega_n: float = 0.22, pressure_offset_pa: float = 180000.0,
                 pressure_gain_pa: float = 2000.0, flow_offset_g_s: float = 0.0,
                 flow_gain_g_s: float = 0.5, pressure_noise_pa: float = 0.0,
                 flow_noise_g_s: float = 0.0, seed: int = 0) -> None:
        if not (tau_s >= 0 and zeta >= 0 and omega_n > 0):
            raise ConfigError('need tau_s >= 0, zeta >= 0 and omega_n > 0')
        if not (pressure_gain_pa > 0 and flow_gain_g_s > 0):
            raise ConfigError('calibration gains must be > 0')
        self.actuator = actuator
        self.tau_s, self.zeta, self.omega_n = float(tau_s), float(zeta), float(omega_n)
        self.p_cal = (float(pressure_offset_pa), float(pressure_gain_pa))
        self.f_cal = (float(flow_offset_g_s), float(flow_gain_g_s))
        self.noise = (float(pressure_noise_pa), float(flow_noise_g_s))
        self._rng = np.random.default_rng(seed)
        self._x_p: float | None = None
        self._x_f = 0.0
        self._xd_f = 0.0

    def step(self, command_ma: float, dt_s: float) -> PlantReading:
        noise_std = self.actuator.noise_std
        self.actuator.noise_std = 0.0
        y = self.actuator.apply(command_ma, dt_s)
        self.actuator.noise_std = noise_std
        if self._x_p is None:
            self._x_p, self._x_f, self._xd_f = y, y, 0.0
        elif dt_s > 0:
            a = first_order_coefficient(dt_s, self.tau_s)
            self._x_p = a * self._x_p + (1.0 - a) * y
            p11, p12, p21, p22 = second_order_coefficients(dt_s, self.zeta, self.omega_n)
            e = self._x_f - y
            self._x_f, self._xd_f = y + p11 * e + p12 * self._xd_f, p21 * e + p22 * self._xd_f
        pos = y + (self._rng.normal(0.0, noise_std) if noise_std > 0 else 0.0)
        pres = self.p_cal[0] + self.p_cal[1] * self._x_p
        flow = self.f_cal[0] + self.f_cal[1] * self._x_f
        if self.noise[0] > 0:
            pres += float(self._rng.normal(0.0, self.noise[0]))
        if self.noise[1] > 0:
            flow += float(self._rng.normal(0.0, self.noise[1]))
        return PlantReading(float(pos), float(pres), float(flow))


class RigPlant(PlantModel):
    """The pneumatic rig of :mod:`hyst_id.rig` (``RigSimulator``), one sample per command.

    Parameters
    ----------
    params_file : str
        Rig parameters (``params/pipeline.yaml`` layout); '' for the defaults.
    seed : int
        Noise seed.
    """

    def __init__(self, params_file: str = '', seed: int = 0) -> None:
        from hyst_id.rig import RigSimulator
        self._sim = RigSimulator(params_file or None, seed)

    def step(self, command_ma: float, dt_s: float) -> PlantReading:
        r = self._sim.step(command_ma, max(dt_s, 1e-6))
        return PlantReading(r.position, r.pressure_pa, r.flow_g_s)


def make_plant(values: dict[str, Any]) -> PlantModel:
    """Build the plant named by ``values['plant']`` from node parameter values."""
    if values['plant'] == 'rig':
        return RigPlant(values['rig_params_file'], values['seed'])
    act = SimulatedActuator({n: values[n] for n in _H_NAMES}, {n: values[n] for n in _B_NAMES},
                            values['position_noise_std'], values['seed'])
    return SimplePlant(act, values['tau_s'], values['zeta'], values['omega_n'],
                       values['pressure_offset_pa'], values['pressure_gain_pa'],
                       values['flow_offset_g_s'], values['flow_gain_g_s'],
                       values['pressure_noise_pa'], values['flow_noise_g_s'],
                       values['seed'] + 1)


PARAMS = [
    Param('plant', 'simple', 'plant model', choices=('simple', 'rig'), read_only=True),
    Param('rig_params_file', '', 'rig parameters (YAML, params/pipeline.yaml layout) for '
          "plant 'rig'; '' = the rig's defaults", read_only=True),
    *[Param(n, v, f'simulated hysteresis {n} (paper section 4)', low=-100.0, high=100.0,
            read_only=True) for n, v in PAPER_HYSTERESIS.items()],
    *[Param(n, v, f'simulated backlash {n} (paper Table 1, position)', low=-100.0,
            high=100.0, read_only=True) for n, v in PAPER_BACKLASH.items()],
    Param('tau_s', 1.79, 'pressure transducer time constant (Table 1)', low=0.0, high=1e3,
          unit='s', read_only=True),
    Param('zeta', 0.51, 'flow sensor damping ratio (Table 1)', low=0.0, high=10.0,
          read_only=True),
    Param('omega_n', 0.22, 'flow sensor natural frequency (Table 1)', low=1e-6, high=1e4,
          unit='rad/s', read_only=True),
    Param('pressure_offset_pa', 180000.0, 'pressure calibration offset', low=-1e9, high=1e9,
          unit='Pa', read_only=True),
    Param('pressure_gain_pa', 2000.0, 'pressure calibration gain (> 0)', low=1e-9, high=1e9,
          unit='Pa per position unit', read_only=True),
    Param('flow_offset_g_s', 0.0, 'flow calibration offset', low=-1e9, high=1e9, unit='g/s',
          read_only=True),
    Param('flow_gain_g_s', 0.5, 'flow calibration gain (> 0)', low=1e-9, high=1e9,
          unit='g/s per position unit', read_only=True),
    Param('position_noise_std', 0.01, 'position noise standard deviation', low=0.0,
          high=1e3, read_only=True),
    Param('pressure_noise_pa', 20.0, 'pressure noise standard deviation', low=0.0, high=1e9,
          unit='Pa', read_only=True),
    Param('flow_noise_g_s', 0.005, 'flow noise standard deviation', low=0.0, high=1e9,
          unit='g/s', read_only=True),
    Param('seed', 0, 'noise seed', low=0, high=2**31 - 2, read_only=True),
    Param('publish_position', False, 'also publish the position (off when an actuator_driver '
          'publishes it)', read_only=True),
    Param('time_scale', 1.0, 'simulated seconds per wall-clock second', low=1e-3, high=1e4),
    Param('step_s', 0.0, 'simulated time per command (0 = the time between command stamps '
          'x time_scale)', low=0.0, high=1e4, unit='s'),
    Param('joint_name', 'valve', 'JointState name of the actuator joint', read_only=True),
    *topic_params(),
    scalar_type_param('topics.command_type', 'command stream'),
    scalar_type_param('topics.flow_type', 'flow stream'),
]


class PipelineSim(HystNode):
    """Simulate the plant on every command and publish its sensors."""

    def __init__(self, plant: PlantModel | None = None, **kwargs: Any) -> None:
        super().__init__('pipeline_sim', PARAMS, **kwargs)
        values = self.param_values()
        self.plant = plant if plant is not None else make_plant(values)
        self._command_clock = CommandClock()
        self._pres_pub = self.create_publisher(FluidPressure, values['topics.pressure_topic'],
                                               SENSOR_QOS, qos_overriding_options=OVERRIDABLE)
        self._command = ScalarStream(values['topics.command_type'])
        self._flow = ScalarStream(values['topics.flow_type'])
        self._flow_pub = self.create_publisher(self._flow.cls, values['topics.flow_topic'],
                                               SENSOR_QOS, qos_overriding_options=OVERRIDABLE)
        self._pos_pub = None
        if values['publish_position']:
            self._pos_pub = self.create_publisher(JointState, values['topics.position_topic'],
                                                  SENSOR_QOS,
                                                  qos_overriding_options=OVERRIDABLE)
        self.create_subscription(self._command.cls, values['topics.command_topic'],
                                 self._on_command,
                                 COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        self.watch_input_types([(values['topics.command_topic'], self._command.type_name)])
        outs = [values['topics.pressure_topic'], values['topics.flow_topic']]
        if self._pos_pub is not None:
            outs.append(values['topics.position_topic'])
        self.get_logger().info(f'{type(self.plant).__name__}: '
                               f'{resolved(self, values["topics.command_topic"])} -> '
                               + ', '.join(resolved(self, o) for o in outs))

    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        return actuator_problem(values)

    def _on_command(self, msg: Any, info: dict) -> None:
        command = self._command.value(msg)
        if not math.isfinite(command):
            self.note_non_finite('command')
            return
        # a stamped command acts at its stamp; an unstamped one when it arrived
        ns, dt_s = self._command_clock.advance(self._command.acts_at_ns(msg, info, self),
                                               self.get_logger())
        step_s = self.p('step_s')
        reading = self.plant.step(command, step_s if step_s > 0 else dt_s * self.p('time_scale'))
        stamp = Time()
        stamp.sec, stamp.nanosec = divmod(ns, 1_000_000_000)
        if self._pos_pub is not None:
            js = JointState()
            js.header.stamp = stamp
            js.name = [self.p('joint_name')]
            js.position = [reading.position]
            self._pos_pub.publish(js)
        fp = FluidPressure()
        fp.header.stamp = stamp
        fp.header.frame_id = 'pressure_transducer'
        fp.fluid_pressure = reading.pressure_pa
        self._pres_pub.publish(fp)
        self._flow_pub.publish(self._flow.make(reading.flow_g_s, stamp))


def main(args: list[str] | None = None) -> int:
    """Run the pipeline simulator until Ctrl-C / SIGTERM."""
    return spin_node(PipelineSim, 'pipeline_sim', args)


if __name__ == '__main__':
    raise SystemExit(main())
