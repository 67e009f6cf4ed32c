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

"""Reading a number from each message of an input stream, and saying when it cannot be read.

A message whose field cannot be read (``position[0]`` of a JointState with an empty
``position``, a missing attribute) is not collected; a node that only logged it stayed OK on
``/diagnostics`` while it collected nothing (a review's JointState stream with empty
``position`` for 12 s). :class:`FieldReads` counts such messages per stream and words them
for the node's next ``/diagnostics`` status, an ERROR.
"""

from __future__ import annotations

from typing import Any

from hyst_id.io.topics import get_field

__all__ = ['FieldReads']


class FieldReads:
    """Numbers from messages, with a count and the reason for those that cannot be read."""

    def __init__(self, logger: Any) -> None:
        self._logger = logger
        self.count: dict[str, int] = {}
        self._seen: dict[str, int] = {}
        self._why: dict[str, str] = {}

    def read(self, stream: str, topic: str, msg: Any, field: Any) -> float | None:
        """``field`` of ``msg`` as a float; None (counted, logged) when it cannot be read."""
        try:
            return float(get_field(msg, field))
        except (AttributeError, IndexError, KeyError, TypeError, ValueError) as exc:
            self.count[stream] = self.count.get(stream, 0) + 1
            self._why[stream] = f'{topic}: cannot read the {stream} field ({exc})'
            self._logger.warning(self._why[stream], throttle_duration_sec=5.0)
            return None

    def problems(self) -> list[str]:
        """Words for the messages not read since the last call, one per stream."""
        out = [f'{n - self._seen.get(k, 0)} message(s) not collected: {self._why[k]}'
               for k, n in self.count.items() if n > self._seen.get(k, 0)]
        self._seen = dict(self.count)
        return out
