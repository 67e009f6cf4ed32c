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

"""Narrow exception types raised by the hyst_id core.

Every error a user can cause (bad recordings, bad configuration, bounds
that admit no feasible parameter set) derives from :class:`HystIdError`,
so the CLI and the nodes can turn it into a one-line message and a
non-zero exit without a traceback.
"""

from __future__ import annotations

__all__ = [
    'HystIdError',
    'RecordingError',
    'MissingTopicError',
    'TruncatedBagError',
    'NoExcitationError',
    'ConfigError',
    'InfeasibleBoundsError',
    'InvalidParametersError',
    'IdentificationError',
]


class HystIdError(Exception):
    """Base class of every error hyst_id reports to a user."""

    exit_code = 2


class RecordingError(HystIdError):
    """A recording cannot be read or fails validation (NaN, time order...)."""


class TruncatedBagError(RecordingError):
    """An MCAP bag has no footer (its recorder was killed): its complete chunks can be read."""


class MissingTopicError(RecordingError):
    """A configured topic or column is absent from the recording."""


class NoExcitationError(RecordingError):
    """The command never reverses, so the hysteresis loop is not excited."""


class ConfigError(HystIdError):
    """A parameter file, CLI option or ROS parameter is invalid."""


class InfeasibleBoundsError(ConfigError):
    """Search domains admit no parameter vector satisfying the constraints."""


class InvalidParametersError(HystIdError):
    """A parameter set violates the model constraints (e.g. ``c_l >= c_r``)."""


class IdentificationError(HystIdError):
    """Identification failed or was cancelled."""
