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

"""Signal primitives shared by every stage.

Reversals and periods, the train/held-out split, the measurement-noise
estimate and its floor, excitation profiles.

May import: numpy, scipy, :mod:`hyst_id.errors`. Nothing else of the package.
"""

__all__: list[str] = []
