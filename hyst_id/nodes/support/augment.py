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

"""The compensator's ``augment.*`` parameters: in-line corrections from a diagnosis.

Each is a field of :class:`hyst_id.compensation.augment.Augmentation`;
``hyst-id diagnose --params-out`` writes them with the diagnosed set. The
stops' ``.nan`` means no stop (a ROS double cannot hold an infinity from
every params file writer).
"""

from __future__ import annotations

import math
from typing import Any

from hyst_id.compensation.augment import Augmentation, GAIN_LAWS
from hyst_id.nodes.support.params import Param

__all__ = ['AUGMENT_PARAMS', 'augmentation_from_values']

_NAN = math.nan

AUGMENT_PARAMS = [
    Param('augment.dead_time_s', 0.0, 'command -> actuator delay (diagnosis dead_time): each '
          'command is computed for the desired value this far ahead, from its slope; 0 = off',
          low=0.0, high=3600.0, unit='s'),
    Param('augment.predict_window_s', 0.0, 'window of the desired value slope used to predict '
          'ahead; 0 = the last two samples', low=0.0, high=60.0, unit='s'),
    Param('augment.gain_law', 'none', 'scheduled plant gain over the time t since the first '
          "compensated sample: 'exponential' exp(-rate t) (supply_decay), 'linear' 1 + rate t "
          '(gain_drift)',
          choices=GAIN_LAWS),
    Param('augment.gain_rate_per_s', 0.0, 'rate of the scheduled gain', low=-10.0, high=10.0,
          unit='1/s'),
    Param('augment.gain_centre', 0.0, 'reading the scheduled gain leaves unchanged',
          unit='out'),
    Param('augment.gain_reference', 1.0, 'scheduled gain at which the set holds (1: the '
          'run start)', low=1e-6, high=1e6),
    Param('augment.offset_rate_per_s', 0.0, 'scheduled offset drift (offset_drift)',
          unit='out/s'),
    Param('augment.offset_reference_s', 0.0, 'time since the start at which the set holds '
          'the offset', low=0.0, high=1e9, unit='s'),
    Param('augment.schedule_horizon_s', 0.0, 'schedules are held at their value this long '
          'after the start (the diagnosed record length); 0 = never held', low=0.0,
          high=1e9, unit='s'),
    Param('augment.min_command', _NAN, 'low travel stop (diagnosis saturation): commands '
          'stay above it; .nan = none', unit='mA'),
    Param('augment.max_command', _NAN, 'high travel stop (diagnosis saturation): commands '
          'stay below it; .nan = none', unit='mA'),
    *[Param(f'augment.poly_c{i}', 1.0 if i == 1 else 0.0,
            f'output map (diagnosis static_nonlinearity): coefficient of z^{i} of the reading '
            "as a cubic of the set's output z; identity 0, 1, 0, 0", unit='out')
      for i in range(4)],
]


def augmentation_from_values(values: dict[str, Any]) -> Augmentation:
    """The :class:`Augmentation` of a node's parameter values.

    Raises
    ------
    InvalidParametersError
        Values that do not make a valid augmentation.
    """
    return Augmentation.from_mapping(values)     # .nan stops: none
