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

"""ParameterPusher: hand a parameter set to another node's ``set_parameters_atomically``."""

from __future__ import annotations

import time
from typing import Any

from rcl_interfaces.srv import SetParametersAtomically
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.validate_topic_name import InvalidServiceNameException

__all__ = ['ParameterPusher']


class ParameterPusher:
    """Send a parameter list to another node's ``set_parameters_atomically``.

    :meth:`push` queues one request (replacing a pending one); :meth:`poll`,
    called from a timer of ``node``, sends it once the service is up, or
    drops it with a warning after ``timeout_s``. The answer is logged
    (rejections with the target's reason); nothing ever blocks the executor.
    """

    def __init__(self, node: Node) -> None:
        self.node = node
        self._client = None
        self._pending: tuple[str, list[Parameter], float] | None = None

    def push(self, target_node: str, params: list[Parameter], timeout_s: float) -> None:
        """Queue ``params`` for ``<target_node>/set_parameters_atomically``."""
        name = target_node.rstrip('/') + '/set_parameters_atomically'
        self._pending = (name, params, time.monotonic() + timeout_s)

    def poll(self) -> None:
        """Send the pending request if its service is ready (call from a timer)."""
        if self._pending is None:
            return
        name, params, deadline = self._pending
        if self._client is None or self._client.srv_name != name:
            if self._client is not None:
                self.node.destroy_client(self._client)
            try:
                self._client = self.node.create_client(SetParametersAtomically, name)
            except (InvalidServiceNameException, ValueError) as exc:
                self.node.get_logger().error(
                    f'cannot push the parameters to {name}: {str(exc).splitlines()[0]} (they '
                    'are on the latched topic and in the params file)')
                self._client = self._pending = None
                return
        if not self._client.service_is_ready():
            if time.monotonic() > deadline:
                self.node.get_logger().warning(
                    f'{name} not available: parameters not pushed (they are on the latched '
                    'topic and in the params file)')
                self._pending = None
            return
        self._pending = None
        future = self._client.call_async(SetParametersAtomically.Request(
            parameters=[p.to_parameter_msg() for p in params]))
        future.add_done_callback(lambda f, n=name: self._done(f, n))

    def _done(self, future: Any, name: str) -> None:
        log = self.node.get_logger()
        try:
            result = future.result().result
        except Exception as exc:  # noqa: BLE001 - a failed call is logged, not raised
            log.warning(f'{name} failed: {exc}')
            return
        if result.successful:
            log.info(f'pushed the parameters to {name}')
        else:
            log.warning(f'{name} rejected the parameters: {result.reason}')
