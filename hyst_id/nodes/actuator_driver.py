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

"""Actuator driver node: command (mA) in, actuator position out.

The hardware sits behind :class:`ActuatorInterface` (``apply(command, dt)
-> position``); the default :class:`SimulatedActuator` is the paper's
induced hysteresis H (section 4) followed by backlash B (Table 1, position
row) plus optional Gaussian measurement noise. A real driver implements
the interface and is selected with the ``backend`` parameter.

Every command received is applied and answered with one position sample
(``sensor_msgs/JointState``), so a recording holds one measurement per
command, as the chains expect. The sample is stamped with the time the
command reached the node (the middleware's receive timestamp): the
simulated actuator responds at once and holds that position until the
next command, and the stamp does not depend on how late the executor
handled the message, so pairing by stamp stays exact under load.
"""

from __future__ import annotations

import abc
import math
from typing import Any

import numpy as np
from sensor_msgs.msg import JointState

from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.models.backlash import backlash_step, check_backlash
from hyst_id.models.tk import check_hysteresis, hysteresis_step, initial_output
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

__all__ = ['ActuatorDriver', 'ActuatorInterface', 'actuator_problem', 'PAPER_BACKLASH',
           'PAPER_HYSTERESIS', 'PARAMS', 'SimulatedActuator', 'main']

#: The paper's induced hysteresis (section 4).
PAPER_HYSTERESIS = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15,
                    'c_l': -0.25, 'c_r': 0.50, 'c_t': 14.00, 'c_b': 7.00}
#: Backlash of the paper's Table 1, position row.
PAPER_BACKLASH = {'m_bl': 1.09, 'c_bl': 0.48, 'c_br': 1.02}
_H_NAMES = tuple(PAPER_HYSTERESIS)
_B_NAMES = tuple(PAPER_BACKLASH)


def actuator_problem(values: dict[str, Any]) -> str | None:
    """Why the simulated actuator's H and B parameters in ``values`` are invalid, or None."""
    try:
        check_hysteresis([values[n] for n in _H_NAMES])
        check_backlash([values[n] for n in _B_NAMES])
    except InvalidParametersError as exc:
        return str(exc)
    return None


class ActuatorInterface(abc.ABC):
    """What the driver node needs from an actuator (simulated or real)."""

    @abc.abstractmethod
    def apply(self, command_ma: float, dt_s: float) -> float:
        """Send ``command_ma``, wait/simulate ``dt_s`` and return the position."""

    def close(self) -> None:
        """Release the hardware (nothing for a simulation)."""


class SimulatedActuator(ActuatorInterface):
    """H then B, sample by sample, with the chains' initial state and optional noise.

    The first command puts H on the rising boundary of its major loop and B
    on its rising edge (as :mod:`hyst_id.identification.chains` assumes).
    """

    def __init__(self, hysteresis: dict[str, float] | None = None,
                 backlash: dict[str, float] | None = None, noise_std: float = 0.0,
                 seed: int | None = 0) -> None:
        self.set_parameters(hysteresis or PAPER_HYSTERESIS, backlash or PAPER_BACKLASH)
        if not (math.isfinite(noise_std) and noise_std >= 0):
            raise ConfigError(f'noise_std must be >= 0, got {noise_std}')
        self.noise_std = float(noise_std)
        self._rng = np.random.default_rng(seed)
        self._state: tuple[float, float, float] | None = None

    def set_parameters(self, hysteresis: dict[str, float], backlash: dict[str, float]) -> None:
        """Replace H and B (validated; raises InvalidParametersError), keeping the state."""
        self._h = tuple(float(x) for x in check_hysteresis([hysteresis[n] for n in _H_NAMES]))
        self._b = tuple(float(x) for x in check_backlash([backlash[n] for n in _B_NAMES]))

    @property
    def state(self) -> tuple[float, float, float] | None:
        """``(v, u, y)``: last command, H output, B output (None before the first)."""
        return self._state

    def apply(self, command_ma: float, dt_s: float = 0.0) -> float:
        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = self._h
        m_bl, c_bl, c_br = self._b
        v = float(command_ma)
        if self._state is None:
            u = initial_output(v, m_r, m_t, m_b, c_r, c_t, c_b)
            y = m_bl * (u - c_br)
        else:
            v_prev, u_prev, y_prev = self._state
            u = hysteresis_step(v, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
            y = backlash_step(u, y_prev, m_bl, c_bl, c_br)
        self._state = (v, u, y)
        if self.noise_std > 0:
            return y + float(self._rng.normal(0.0, self.noise_std))
        return y


PARAMS = [
    Param('backend', 'simulated', 'actuator implementation', choices=('simulated',),
          read_only=True),
    *[Param(n, v, f'simulated hysteresis {n} (paper section 4)', low=-100.0, high=100.0)
      for n, v in PAPER_HYSTERESIS.items()],
    *[Param(n, v, f'simulated backlash {n} (paper Table 1, position)', low=-100.0, high=100.0)
      for n, v in PAPER_BACKLASH.items()],
    Param('noise_std', 0.01, 'standard deviation of the simulated position noise', low=0.0,
          high=100.0, unit='position units'),
    Param('seed', 0, 'seed of the simulated noise', low=0, high=2**31 - 1, read_only=True),
    Param('joint_name', 'valve', 'JointState name of the actuator joint', read_only=True),
    Param('time_scale', 1.0, 'simulated seconds per wall-clock second (dt given to the '
          'actuator)', low=1e-3, high=1e4),
    *topic_params(('command_topic', 'position_topic')),
    scalar_type_param('topics.command_type', 'command stream'),
]


class ActuatorDriver(HystNode):
    """Apply each command to the actuator and publish the position it reaches."""

    def __init__(self, actuator: ActuatorInterface | None = None, **kwargs: Any) -> None:
        super().__init__('actuator_driver', PARAMS, **kwargs)
        values = self.param_values()
        if actuator is None:
            actuator = SimulatedActuator({n: values[n] for n in _H_NAMES},
                                         {n: values[n] for n in _B_NAMES},
                                         values['noise_std'], values['seed'])
        self.actuator = actuator
        self._command_clock = CommandClock()
        self._n = 0
        self._pub = self.create_publisher(JointState, self.p('topics.position_topic'),
                                          SENSOR_QOS, qos_overriding_options=OVERRIDABLE)
        self._command = ScalarStream(self.p('topics.command_type'))
        self.create_subscription(self._command.cls, self.p('topics.command_topic'),
                                 self._on_command,
                                 COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        self.watch_input_types([(self.p('topics.command_topic'), self._command.type_name)])
        self.get_logger().info(
            f'{type(actuator).__name__}: {resolved(self, self.p("topics.command_topic"))} -> '
            f'{resolved(self, self.p("topics.position_topic"))} '
            f'(joint {self.p("joint_name")!r})')

    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        if changed & set(_H_NAMES + _B_NAMES):
            return actuator_problem(values)
        return None

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        act = getattr(self, 'actuator', None)
        if isinstance(act, SimulatedActuator):
            if changed & set(_H_NAMES + _B_NAMES):
                act.set_parameters({n: values[n] for n in _H_NAMES},
                                   {n: values[n] for n in _B_NAMES})
                self.get_logger().info('simulated actuator parameters updated')
            act.noise_std = float(values['noise_std'])

    def _on_command(self, msg: Any, info: dict) -> None:
        # The simulated actuator responds at once: its position holds from the moment the
        # command acts (a stamped command's stamp; else when it arrived: the middleware's
        # receive stamp, free of executor delays) until the next command, so that is the
        # sample's stamp.
        command = self._command.value(msg)
        if not math.isfinite(command):
            self.note_non_finite('command')
            return
        ns, dt_s = self._command_clock.advance(self._command.acts_at_ns(msg, info, self),
                                               self.get_logger())
        position = self.actuator.apply(command, dt_s * self.p('time_scale'))
        out = JointState()
        out.header.stamp.sec, out.header.stamp.nanosec = divmod(ns, 1_000_000_000)
        out.name = [self.p('joint_name')]
        out.position = [float(position)]
        self._pub.publish(out)
        self._n += 1

    def destroy_node(self) -> None:
        """Close the actuator, then the node."""
        try:
            if hasattr(self, 'actuator'):
                self.actuator.close()
        finally:
            super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the actuator driver until Ctrl-C / SIGTERM."""
    return spin_node(ActuatorDriver, 'actuator_driver', args)


if __name__ == '__main__':
    raise SystemExit(main())
