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

"""ROS 2 nodes of hyst_id: one thin Node subclass per module, ``main()`` = init/spin/shutdown.

=====================  =====================================================
:mod:`.actuator_driver`  command -> actuator (simulated H + B, or a real one)
:mod:`.pipeline_sim`     simulated pipeline: position, pressure, flow
:mod:`.excitation`       command profiles (Eq. 24, Eq. 25, multisine, ...)
:mod:`.identifier`       GAASS identification of recorded or live data
:mod:`.compensator`      H⁻¹ in-line between desired and command
:mod:`.recorder`         topics -> rosbag2 MCAP
:mod:`.replay`           rosbag2 MCAP -> topics
:mod:`.bringup`          the whole graph in one process (``./run demo``)
=====================  =====================================================

Shared helpers are in :mod:`hyst_id.nodes.support`. Only this package imports
rclpy; it calls the core and never the CLI (:mod:`hyst_id.commands`).
"""


def __getattr__(name: str):
    """Names of hyst_id 0.1's ``hyst_id.nodes`` now in :mod:`hyst_id.nodes.support`."""
    import importlib
    import warnings
    support = importlib.import_module('hyst_id.nodes.support')
    if name not in support.__all__:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    warnings.warn(f'hyst_id.nodes.{name} moved to hyst_id.nodes.support.{name}; the old path '
                  'goes in hyst_id 0.3', DeprecationWarning, stacklevel=2)
    return getattr(support, name)
