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

"""Which forked pools a module used: for the tests that compare one worker with two.

Those comparisons run in a fresh process (``subprocess``), which has one
thread, so that the pools really fork; a pytest worker may have threads left
by earlier tests, and the work then runs in the calling process, which would
compare one process with itself.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
import subprocess
import sys

__all__ = ['in_fresh_process', 'watch_pools']


def watch_pools(module) -> list:
    """Patch ``module.forked_pool``; the returned list gets every pool it yields from then on.

    None for each time the module's work ran in the calling process (one
    worker, threads running, no fork).
    """
    real, pools = module.forked_pool, []

    @contextmanager
    def seen(n_workers):
        with real(n_workers) as pool:
            pools.append(pool)
            yield pool

    module.forked_pool = seen
    return pools


def in_fresh_process(test_file: str, call: str) -> subprocess.CompletedProcess:
    """Import ``test_file``'s module in a new interpreter and evaluate ``call`` there."""
    here = Path(test_file).resolve().parent
    code = (f'import sys; sys.path[:0] = [{str(here)!r}, {str(Path(__file__).parent)!r}]; '
            f'import {Path(test_file).stem} as m; m.{call}')
    return subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=600)
