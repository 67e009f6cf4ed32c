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

"""Find a fleet's recordings, run one task per recording on an engine, resume.

Engines: a local process pool (default: identify's
:func:`~hyst_id.identification.workers.map_in_processes`, whose workers leave
Ctrl-C to the parent, die with it and are ended at once on an interrupt),
or a Dask distributed cluster (``address``: a scheduler address such as
``tcp://10.0.0.5:8786``, or ``local`` for a cluster started on this
machine), used through its :class:`concurrent.futures.Executor` interface
(``Client.get_executor``), so no scheduling is written here. Dask rather
than Ray: it installs from PyPI as pure Python (Ray's wheels are large and
platform-bound), joins an existing cluster from an address alone, and its
executor is the standard one.
"""

from __future__ import annotations

from concurrent.futures import as_completed, Executor
from dataclasses import asdict, dataclass
import glob
import hashlib
import itertools
import json
import os
from pathlib import Path
import re
import time
from typing import Any, Callable, Iterable

from hyst_id.errors import ConfigError, HystIdError, TruncatedBagError
from hyst_id.identification.workers import map_in_processes, n_processes
from hyst_id.io.csv_reader import CSV_SUFFIXES

__all__ = ['file_stamp', 'FleetOptions', 'find_recordings', 'fleet_task', 'result_path',
           'run_fleet']

_RECORDING_SUFFIXES = ('.mcap', '.csv', '.tsv')
#: Suffixes of a file named on the command line: every one ``identify`` reads.
_NAMED_SUFFIXES = ('.mcap', *CSV_SUFFIXES)


@dataclass(frozen=True)
class FleetOptions:
    """What to do with each recording (picklable: it travels to the workers)."""

    channel: str = 'position'
    seeds: int = 4
    generations: int = 500
    model: str = 'tk'
    diagnose: bool = False
    #: A :class:`~hyst_id.io.topics.TopicConfig` or mapping of topic keys (bags), or None.
    topics: Any = None
    #: CSV columns (time, command, measurement; names or 0-based indices), None: the
    #: default; bags in the same fleet are read by their topics.
    columns: tuple | None = None
    #: Factor from the CSV time column to seconds (CSV files only), None: 1.
    time_scale: float | None = None


def find_recordings(inputs: Iterable[str]) -> list[Path]:
    """Recordings under directories and globs: bag directories, ``.mcap`` and CSV files.

    A directory holding ``metadata.yaml`` is one bag; other directories are
    searched recursively. The list is sorted and free of repeats.

    Raises
    ------
    ConfigError
        An input matches nothing.
    """
    found: dict[str, Path] = {}
    for item in inputs:
        matches = [Path(p) for p in sorted(glob.glob(str(item)))]
        if not matches and Path(item).exists():
            matches = [Path(item)]
        if not matches:
            raise ConfigError(f'{item}: no such file, directory or glob match')
        for path in matches:
            for rec in _walk(path, named=True):
                found[str(rec.resolve())] = rec
    return [found[k] for k in sorted(found)]


def _walk(path: Path, named: bool = False) -> Iterable[Path]:
    """Recordings at ``path``; a file named by the user (or its glob) may also be ``.txt``.

    A ``.txt`` file met while searching a directory is left out (notes and readmes sit
    beside recordings); named, it is read as ``identify`` reads it.
    """
    if path.is_file():
        if path.suffix.lower() in (_NAMED_SUFFIXES if named else _RECORDING_SUFFIXES):
            yield path
        return
    if (path / 'metadata.yaml').exists() or _bag_without_metadata(path):
        yield path
        return
    if path.is_dir():
        for child in sorted(path.iterdir()):
            yield from _walk(child)


def _bag_without_metadata(path: Path) -> bool:
    """A directory whose MCAP files are named after it: one bag whose recorder was killed.

    rosbag2 names them ``<dir>_0.mcap``, ``<dir>_1.mcap`` …, rosbags ``<dir>.mcap``,
    and writes ``metadata.yaml`` last. Such a directory is its bag (its valve is its
    parent folder's, as a complete bag's), not a folder of recordings: an independent
    reviewer's killed recording had become a valve of its own.
    """
    if not path.is_dir():
        return False
    mcaps = list(path.glob('*.mcap'))
    pattern = re.compile(re.escape(path.name) + r'(_[0-9]+)?')
    return bool(mcaps) and all(pattern.fullmatch(m.stem) for m in mcaps)


def result_path(out_dir: Path, recording: Path) -> Path:
    """Where a recording's JSON goes: its name plus a short hash of its full path."""
    digest = hashlib.sha1(str(Path(recording).resolve()).encode()).hexdigest()[:8]
    return Path(out_dir) / 'recordings' / f'{Path(recording).name}-{digest}.json'


def _options_doc(options: FleetOptions) -> dict:
    """The options as a result's JSON holds them (lists for tuples)."""
    return json.loads(json.dumps({**asdict(options), 'topics': str(options.topics or '')}))


def file_stamp(path: Path) -> list:
    """Size and modification time of a recording (a bag folder: of all its files).

    A resumed fleet keeps an earlier result only for the same stamp and options; a
    review's recording replaced by a shorter one had kept its old row.
    """
    files = sorted(p for p in path.rglob('*') if p.is_file()) if path.is_dir() else [path]
    stats = [f.stat() for f in files if f.exists()]
    return [sum(st.st_size for st in stats), max((st.st_mtime_ns for st in stats), default=0)]


def fleet_task(path: str, options: FleetOptions) -> dict:
    """Identify (and diagnose) one recording; a document, never an exception.

    ``status`` is ``ok`` or ``error`` (with ``error``: the one-line reason a
    bad recording gives).
    """
    t0 = time.monotonic()
    doc: dict[str, Any] = {'recording': path, 'options': _options_doc(options),
                           'file': file_stamp(Path(path))}
    try:
        from hyst_id.identification import identify
        from hyst_id.identification.config import make_settings, make_spec
        from hyst_id.io.readers import CSV_SUFFIXES, read_recording

        csv = Path(path).suffix.lower() in CSV_SUFFIXES     # columns are a CSV's only
        how = {'topics': options.topics or None, 'columns': options.columns if csv else None,
               'time_scale': options.time_scale if csv else None}
        try:
            rec = read_recording(path, options.channel, **how)
        except TruncatedBagError:   # a killed recorder's bag: its complete chunks (noted)
            rec = read_recording(path, options.channel, recover_truncated=True, **how)
        spec = make_spec(rec, 'auto', family=options.model)
        settings = make_settings(seeds=options.seeds, generations=options.generations,
                                 workers=1)
        ident = identify(rec, spec=spec, settings=settings)
        from hyst_id.fleet.width import loop_width_command
        doc.update(status='ok', identification=ident.to_dict(), n_samples=rec.n_samples,
                   duration_s=rec.duration_s, source=rec.source, notes=list(rec.notes),
                   loop_width_command=loop_width_command(
                       ident, (float(rec.command.min()), float(rec.command.max()))))
        if options.diagnose:
            from hyst_id.diagnosis import diagnose
            doc['diagnosis'] = diagnose(rec).to_dict()
    except HystIdError as exc:
        doc.update(status='error', error=(str(exc).splitlines() or [type(exc).__name__])[0])
    except Exception as exc:  # noqa: BLE001 - one bad recording never stops the fleet
        doc.update(status='error', error=f'{type(exc).__name__}: {exc}'.splitlines()[0])
    doc['elapsed_s'] = time.monotonic() - t0
    return doc


def _dask_executor(address: str, workers: int) -> tuple[Executor, Callable[[], None]]:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError('--address needs the dask distributed package '
                          '(pip install distributed)') from None
    if address == 'local':
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                               threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)

        def close() -> None:
            client.close()
            cluster.close()
    else:
        try:
            client = Client(address, timeout='10s')
        except (OSError, TimeoutError) as exc:
            raise ConfigError(f'cannot reach the Dask scheduler at {address}: {exc}') from None
        close = client.close
    return client.get_executor(pure=False), close


def run_fleet(recordings: list[Path], out_dir: str | Path, options: FleetOptions, *,
              workers: int = 0, address: str | None = None,
              progress: Callable[[int, int, dict], None] | None = None) -> list[dict]:
    """Run :func:`fleet_task` over ``recordings``; return every document (old and new).

    A recording whose JSON in ``out_dir/recordings`` already says ``ok``, for
    the same options and the same file (:func:`file_stamp`), is not run again
    (resume; its document gets ``resumed: true``); failed or changed ones are run
    again. Each document is written as soon as it arrives, so an interrupted fleet
    loses only the running tasks.
    """
    out_dir = Path(out_dir)
    (out_dir / 'recordings').mkdir(parents=True, exist_ok=True)
    docs: dict[str, dict] = {}
    todo = []
    current = _options_doc(options)
    for rec in recordings:
        old = _read(result_path(out_dir, rec))
        if old is not None and old.get('status') == 'ok' and old.get('options') == current \
                and old.get('file') == file_stamp(rec):
            docs[str(rec)] = {**old, 'resumed': True}
        else:
            todo.append(rec)
    arrived = itertools.count(1)

    def keep(doc: dict) -> None:
        """Write a row as it arrives (an interrupted fleet keeps it), then report it."""
        _write(result_path(out_dir, Path(doc['recording'])), doc)
        docs[doc['recording']] = doc
        if progress:
            progress(next(arrived), len(todo), doc)

    if todo and not address:
        map_in_processes(fleet_task, [(str(rec), options) for rec in todo],
                         n_processes(workers, len(todo)), on_result=keep)
    elif todo:
        executor, close = _dask_executor(address, workers)
        try:
            for fut in as_completed([executor.submit(fleet_task, str(rec), options)
                                     for rec in todo]):
                keep(fut.result())
        finally:
            close()
    return [docs[str(rec)] for rec in recordings]


def _read(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _write(path: Path, doc: dict) -> None:
    tmp = path.with_name(path.name + '.tmp')
    tmp.write_text(json.dumps(doc, default=float))
    os.replace(tmp, path)
