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

"""Compensation: the identified model's exact inverse, in-line, sample by sample.

:mod:`.inverse` holds :class:`InverseModel` (a validated parameter set),
:class:`CommandLimits` and :class:`Compensator` (B⁻¹ then H⁻¹ with its own
model state, atomic swaps). :mod:`.tracking` wraps it in an
:class:`~hyst_id.compensation.tracking.AdaptiveCompensator` that tracks the
plant's slow gain and offset from its measurement; :mod:`.augment` wraps it
in an :class:`~hyst_id.compensation.augment.AugmentedCompensator` that runs
a diagnosis's in-line corrections (dead time ahead, gain and offset
schedules, travel stops, a static curve's inverse).

May import: :mod:`hyst_id.models`, :mod:`hyst_id.errors`.
"""

from hyst_id.compensation.augment import Augmentation, AugmentedCompensator
from hyst_id.compensation.inverse import CommandLimits, Compensator, InverseModel

__all__ = ['Augmentation', 'AugmentedCompensator', 'CommandLimits', 'Compensator',
           'InverseModel']
