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

"""Old module paths of hyst_id 0.1 (before the stage packages), kept for one release.

``import hyst_id.chains`` and the like still work: a finder on
``sys.meta_path`` maps each old name to its new module and warns with a
:class:`DeprecationWarning` that names the new path. Remove in 0.3.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from types import ModuleType
import warnings

__all__ = ['MOVED', 'MOVED_PACKAGES', 'install', 'new_name']

#: Old module -> new module.
MOVED = {
    'hyst_id.chains': 'hyst_id.identify.chains',
    'hyst_id.domains': 'hyst_id.identify.domains',
    'hyst_id.refine': 'hyst_id.identify.refine',
    'hyst_id.gauge': 'hyst_id.identify.gauge',
    'hyst_id.diagnostics_checks': 'hyst_id.identify.quality',
    'hyst_id.report': 'hyst_id.identify.report',
    'hyst_id.gaass': 'hyst_id.solvers.gaass',
    'hyst_id.gaass_ops': 'hyst_id.solvers.gaass_ops',
    'hyst_id.benchmarks': 'hyst_id.solvers.simple_ga',
    'hyst_id.noise': 'hyst_id.signals.noise',
    'hyst_id.excitation': 'hyst_id.signals.excitation',
    'hyst_id.experiment_report': 'hyst_id.experiment.report',
    'hyst_id.identify': 'hyst_id.identification',
    'hyst_id.compensate': 'hyst_id.compensation',
    'hyst_id.models.hysteresis': 'hyst_id.models.tk',
}

#: Old package -> new package: every submodule moved with it.
MOVED_PACKAGES = {
    'hyst_id.diagnose': 'hyst_id.diagnosis',
}


def new_name(name: str) -> str | None:
    """The module an old name moved to, or None if it did not move."""
    if name in MOVED:
        return MOVED[name]
    for old, new in MOVED_PACKAGES.items():
        if name == old or name.startswith(old + '.'):
            return new + name[len(old):]
    return None


class _Alias(importlib.abc.Loader):
    def __init__(self, new: str) -> None:
        self.new = new

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        warnings.warn(f'{spec.name} moved to {self.new}; the old path goes in hyst_id 0.3',
                      DeprecationWarning, stacklevel=3)
        return importlib.import_module(self.new)

    def exec_module(self, module: ModuleType) -> None:
        return None


class _MovedFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, name: str, path: object = None,
                  target: object = None) -> importlib.machinery.ModuleSpec | None:
        new = new_name(name)
        if new is None:
            return None
        return importlib.machinery.ModuleSpec(name, _Alias(new))


def install() -> None:
    """Put the finder on ``sys.meta_path`` once (after the normal finders)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.append(_MovedFinder())
