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

"""Which forked pools a module used, and which workers outlived a pool: for the pool tests.

Those comparisons run in a fresh process (``subprocess``), which has one
thread, so that the pools really fork; a pytest worker may have threads left
by earlier tests, and the work then runs in the calling process, which would
compare one process with itself.
"""

from __future__ import annotations

from contextlib import contextmanager
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

__all__ = ['in_fresh_process', 'watch_pools', 'workers_left']


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


def workers_left(pids: list[int], timeout_s: float = 10.0) -> list[int]:
    """Which of the processes ``pids`` still live after ``timeout_s``; those are killed (Linux).

    For the tests that end a pool and check that no worker outlives it.
    """
    deadline = time.monotonic() + timeout_s
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = [p for p in pids if _alive(p)]
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    return left


def _alive(pid: int) -> bool:
    """Running and not a zombie (``/proc``)."""
    try:
        with open(f'/proc/{pid}/stat') as f:
            return f.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except OSError:
        return False
