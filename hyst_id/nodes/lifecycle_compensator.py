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

"""Lifecycle compensator: the compensator as a managed node (``lifecycle_compensator``).

The same node as :mod:`hyst_id.nodes.compensator` (parameters, topics,
swaps, tracking, bypass/reset, ``~/active_set``; default name
``compensator``, so the same params file and the identifier's push work),
driven by the standard lifecycle state machine (``~/change_state``,
``~/get_state``, as a lifecycle manager expects):

* **unconfigured** and **inactive**: no command is published; desired
  samples are counted and dropped (a managed controller that is not active
  does not move the actuator), and ``/diagnostics`` says so (WARN);
* **configure**: the parameter set is checked and the inverse's kernels are
  compiled (no first-sample delay after activation); with
  ``require_model`` and no valid set the transition fails, with the reason
  in the log;
* **activate**: the model state restarts at the command the actuator holds
  (the last command sent; ``initial_command`` before any, or after a
  cleanup) and commands flow;
* **deactivate**: commands stop; the actuator holds its last command;
* **cleanup**: the model state is reset to ``initial_command`` (the loop's
  memory is forgotten: after a cleanup the actuator may have been moved by
  hand) and the in-line schedules (``augment.*``) start again at the next
  sample (a new run).

Parameters, sets and services behave as in the compensator in every state.
"""

from __future__ import annotations

from typing import Any

from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from hyst_id.compensation.inverse import warm_up
from hyst_id.nodes.compensator import Compensator, PARAMS
from hyst_id.nodes.support import spin_node

__all__ = ['LifecycleCompensator', 'PARAMS', 'main']


class LifecycleCompensator(Compensator, LifecycleNode):
    """The compensator under the lifecycle state machine: commands only while active."""

    def __init__(self, **kwargs: Any) -> None:
        self._dropped = 0
        super().__init__(**kwargs)
        self.get_logger().info('lifecycle compensator unconfigured: no commands until '
                               'configured and activated (~/change_state)')

    @property
    def lifecycle_state(self) -> str:
        """``unconfigured``, ``inactive``, ``active``, ``finalized`` or a transition."""
        return self._state_machine.current_state[1]

    # ------------------------------------------------------------ transitions
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Check the set and compile the kernels; fail without a set under require_model."""
        model = self._comp.model
        if model is None and self.p('require_model'):
            self.get_logger().error('configure failed: require_model is set and there is no '
                                    'valid parameter set (give one by params file, '
                                    'set_parameters or the identified-params topic)')
            return TransitionCallbackReturn.FAILURE
        if model is not None:
            warm_up(model)
        self.get_logger().info('configured: ' + ('model ready' if model is not None else
                                                 'no parameter set yet: pass-through once '
                                                 'active'))
        return super().on_configure(state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Restart the model state at the command held and let commands flow."""
        v = self._comp.state[0]
        self._comp.reset(v)
        self.get_logger().warning(f'activated: compensating from command {v:g}')
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop commanding; the actuator holds the last command."""
        self.get_logger().warning(f'deactivated: no commands; the actuator holds '
                                  f'{self._comp.state[0]:g}')
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Forget the loop's memory (restart at ``initial_command``)."""
        self._comp.reset(self.p('initial_command'))
        self._comp.restart_schedules()   # a new run: augment.* schedules start again
        self.get_logger().info('cleaned up: model state back at initial_command, in-line '
                               'schedules restart at the next sample')
        return super().on_cleanup(state)

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Log and finish."""
        self.get_logger().info('shut down')
        return super().on_shutdown(state)

    # -------------------------------------------------------------- traffic
    def _on_desired(self, msg: Any) -> None:
        if self.lifecycle_state != 'active':
            self._dropped += 1
            self.get_logger().info(f'{self.lifecycle_state}: desired samples dropped, no '
                                   f'command sent ({self._dropped} so far)',
                                   throttle_duration_sec=5.0)
            return
        super()._on_desired(msg)

    def _publish_status(self) -> None:
        if self.lifecycle_state == 'active':
            super()._publish_status()
            return
        self.publish_diagnostics(1, f'{self.lifecycle_state}: not commanding (lifecycle)',
                                 {'lifecycle_state': self.lifecycle_state,
                                  'dropped_while_not_active': self._dropped,
                                  'command': self._comp.state[0],
                                  'model': 'set' if self._comp.model is not None else 'none'})


def main(args: list[str] | None = None) -> int:
    """Run the lifecycle compensator until Ctrl-C / SIGTERM."""
    return spin_node(LifecycleCompensator, 'compensator', args)


if __name__ == '__main__':
    raise SystemExit(main())
