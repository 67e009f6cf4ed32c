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

"""``hyst-id identify``'s progress bar: seeds, then hopping and the global phase."""

from __future__ import annotations

import argparse
import io

import numpy as np

from hyst_id.commands.identify import _progress_bar
from hyst_id.identification import IdentifySettings
from hyst_id.identification.result import SeedRun

__all__: list[str] = []


def _run(seed: int, er: float) -> SeedRun:
    return SeedRun(seed=seed, x_raw=np.zeros(1), x=np.zeros(1), sign=1.0, fun=er,
                   er_percent=er, er_gaass_percent=er, nfev=1, nit=1,
                   best_history=np.zeros(0), message='', initial='rising', hold='none')


def test_the_bar_stays_open_after_the_seeds_and_shows_hopping(monkeypatch):
    err = io.StringIO()
    monkeypatch.setattr('sys.stderr', err)
    settings = IdentifySettings(seeds=(0, 1))
    bar = _progress_bar(argparse.Namespace(quiet=False), settings)
    bar(1, 2, _run(0, 1.5))
    bar(2, 2, _run(1, 1.4))
    bar.hopping(0, 100, 1.4)                     # between the seeds and the global phase
    bar(3, 16, _run(-1, 1.2))                    # a global run: the total grows
    bar.close()
    text = err.getvalue()
    assert 'hopping 1/100: %e_r 1.400' in text, text
    assert 'global phase' in text and 'run -1: %e_r 1.200' in text, text


def test_model_auto_counts_on_past_its_first_total(monkeypatch):
    """--model auto: three identifications on one bar; global runs never overrun the total."""
    err = io.StringIO()
    monkeypatch.setattr('sys.stderr', err)
    bar = _progress_bar(argparse.Namespace(quiet=False), IdentifySettings(seeds=(0,)), total=3)
    for k in range(3):                               # one seed and two global runs each
        bar(1, 1, _run(0, 2.0))
        bar(2, 3, _run(-1, 1.9))
        bar(3, 3, _run(-2, 1.8))
        assert bar.bar.n <= bar.bar.total, (bar.bar.n, bar.bar.total)
    bar.close()
    assert 'global phase' in err.getvalue()


def test_quiet_has_no_bar():
    assert _progress_bar(argparse.Namespace(quiet=True), IdentifySettings()) is None


def _no_monitor_yet(monkeypatch):
    """The defaults of tqdm, with no monitor thread left by an earlier bar of this process."""
    import tqdm
    if tqdm.tqdm.monitor is not None:
        tqdm.tqdm.monitor.exit()
    monkeypatch.setattr(tqdm.tqdm, 'monitor', None)
    monkeypatch.setattr(tqdm.tqdm, 'monitor_interval', 10)


def _monitors() -> list:
    import threading
    return [t for t in threading.enumerate() if t.name == 'tqdm_monitor' and t.is_alive()]


def test_the_bar_starts_no_thread_so_the_worker_pools_can_fork(monkeypatch):
    import argparse
    import threading

    from hyst_id.commands.identify import _progress_bar
    from hyst_id.identification.result import IdentifySettings
    from hyst_id.identification.workers import mp_context
    _no_monitor_yet(monkeypatch)
    before = threading.active_count()
    progress = _progress_bar(argparse.Namespace(quiet=False), IdentifySettings())
    try:
        progress.bar.update(1)
        progress.bar.refresh()
        assert threading.active_count() == before and _monitors() == []
        if before == 1 and 'fork' in __import__('multiprocessing').get_all_start_methods():
            assert mp_context().get_start_method() == 'fork'
    finally:
        progress.bar.close()


def test_every_command_bar_comes_from_the_one_that_starts_no_thread(monkeypatch):
    """The experiment and fleet commands made bars whose monitor threads ran under the pools."""
    import threading
    from pathlib import Path

    import hyst_id
    from hyst_id.commands.common import progress_bar
    _no_monitor_yet(monkeypatch)
    before = threading.active_count()
    bar = progress_bar(total=3, desc='x')
    try:
        bar.update(1)
        bar.refresh()
        assert threading.active_count() == before and _monitors() == []
    finally:
        bar.close()
    root = Path(hyst_id.__file__).parent
    own = [str(p.relative_to(root)) for p in sorted(root.rglob('*.py'))
           if p.name != 'common.py' and 'tqdm' in p.read_text(encoding='utf-8')]
    assert own == [], f'these modules make their own tqdm bar: {own}'
