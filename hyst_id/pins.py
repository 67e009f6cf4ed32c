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

"""Pin the numeric kernels to one instruction set, so CPU makes agree more often.

NumPy, OpenBLAS and numba pick their code paths by the CPU they run on: an
Intel machine with AVX-512 sums in another order than an AMD one with AVX2,
and every result differs in its last bits. The package's answers are made
robust to that (docs/reproducibility.md); these pins remove the difference
where it can be removed, as defence in depth:

=============================  =============================================
variable                       effect
=============================  =============================================
``OPENBLAS_CORETYPE``          ``Haswell``: the AVX2 BLAS kernels everywhere
``NPY_DISABLE_CPU_FEATURES``   NumPy's AVX-512 dispatch off (AVX2 kept)
``NUMBA_CPU_NAME``             ``haswell``: numba generates AVX2 code
=============================  =============================================

They only apply on x86-64 CPUs with AVX2 and FMA (every x86 server since
2013), only before NumPy is imported, and never override a value the user
set. ``./run`` sets them for the tests and the demo; ``hyst-id`` and
``import hyst_id`` set them (:func:`pin_numerics`), so the nodes and the
CLI compute with the same kernels. A library user who imports NumPy first
keeps the unpinned kernels, and the answers are still expected to hold
(that is what ``bench/roundoff_verdicts.py`` measures).
"""

from __future__ import annotations

from importlib import metadata
import os
import platform
import sys
from typing import MutableMapping

__all__ = ['pin_numerics', 'pins_for_this_machine']


def _cpu_flags() -> set[str]:
    try:
        with open('/proc/cpuinfo', encoding='ascii', errors='replace') as f:
            for line in f:
                if line.startswith('flags'):
                    return set(line.split(':', 1)[1].split())
    except OSError:
        pass
    return set()


def _numpy_avx512_names() -> str:
    try:
        major, minor = (int(x) for x in metadata.version('numpy').split('.')[:2])
    except (metadata.PackageNotFoundError, ValueError):
        return ''
    if (major, minor) >= (2, 3):
        return 'X86_V4 AVX512_ICL AVX512_SPR'
    return ('AVX512F AVX512CD AVX512_KNL AVX512_KNM AVX512_SKX AVX512_CLX AVX512_CNL '
            'AVX512_ICL AVX512_SPR')


def pins_for_this_machine() -> dict[str, str]:
    """The environment pins that apply to this machine (empty when none do)."""
    if platform.machine().lower() not in ('x86_64', 'amd64'):
        return {}
    if not {'avx2', 'fma'} <= _cpu_flags():
        return {}
    pins = {'OPENBLAS_CORETYPE': 'Haswell', 'NUMBA_CPU_NAME': 'haswell'}
    names = _numpy_avx512_names()
    if names:
        pins['NPY_DISABLE_CPU_FEATURES'] = names
    return pins


def pin_numerics(environ: MutableMapping[str, str] | None = None) -> dict[str, str]:
    """Set the pins in the environment unless NumPy is already imported.

    Parameters
    ----------
    environ : mutable mapping, optional
        Environment to update; default ``os.environ``.

    Returns
    -------
    dict
        The variables this call set (user-set values are kept and not listed).
    """
    env = os.environ if environ is None else environ
    if 'numpy' in sys.modules and environ is None:
        return {}
    if env.get('HYST_ID_NO_PINS'):
        return {}
    done = {}
    for key, value in pins_for_this_machine().items():
        if key not in env:
            env[key] = value
            done[key] = value
    return done
