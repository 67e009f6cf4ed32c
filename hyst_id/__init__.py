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

"""hyst_id: identify actuator hysteresis, cancel it in-line, find what the model left out.

The public API, as rosbags and pysindy expose theirs (details in ``docs/api.md``)::

    from hyst_id import read_recording, identify, diagnose, Compensator, InverseModel

    rec = read_recording('run.mcap', 'position')        # or a CSV
    ident = identify(rec)                                # -> Identification
    # ident.proper False: a loop whose output jumps, which no inverse cancels
    diag = diagnose(rec)                                 # -> Diagnosis
    comp = Compensator(InverseModel.from_mapping(dict(ident.params,
                                                      output_sign=ident.output_sign)))

The stages live in subpackages (``docs/architecture.md``): :mod:`hyst_id.signals`,
:mod:`hyst_id.io`, :mod:`hyst_id.models`, :mod:`hyst_id.solvers`,
:mod:`hyst_id.identification`, :mod:`hyst_id.compensation`, :mod:`hyst_id.rig`,
:mod:`hyst_id.diagnosis`, :mod:`hyst_id.experiment`, :mod:`hyst_id.live`, and
the ROS 2 nodes in :mod:`hyst_id.nodes`. Names below are imported on first use,
so ``import hyst_id`` stays light (a node does not pay for the optimisers).
"""

from hyst_id import _deprecated
from hyst_id.pins import pin_numerics

# Same numerics for every entry point (hyst-id, the nodes, scripts) when hyst_id comes
# before NumPy: pins OpenBLAS, NumPy dispatch and the numba target where that is
# possible (docs/reproducibility.md). A program that imported NumPy first keeps its own.
pin_numerics()

__version__ = '0.2.0'

#: Public name -> module that defines it.
_API = {
    'read_recording': 'hyst_id.io.readers',
    'Recording': 'hyst_id.io.recording',
    'validate_recording': 'hyst_id.io.recording',
    'identify': 'hyst_id.identification',
    'Identification': 'hyst_id.identification',
    'IdentifySettings': 'hyst_id.identification',
    'diagnose': 'hyst_id.diagnosis',
    'Diagnosis': 'hyst_id.diagnosis',
    'DiagnoseSettings': 'hyst_id.diagnosis',
    'Compensator': 'hyst_id.compensation',
    'CommandLimits': 'hyst_id.compensation',
    'InverseModel': 'hyst_id.compensation',
    'HystIdError': 'hyst_id.errors',
}

__all__ = sorted(_API) + ['__version__']

_deprecated.install()


def __getattr__(name: str):
    """Import a public name on first use (PEP 562)."""
    module = _API.get(name)
    if module is None:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    import importlib
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
