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

"""What the subcommands share: arguments (recording, GAASS settings, domains), the progress bar."""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
from typing import Any

from hyst_id.errors import ConfigError, TruncatedBagError
from hyst_id.identification import config, IdentifySettings
from hyst_id.identification.chains import CHAIN_NAMES, ChainSpec
from hyst_id.io.outputs import make_output_folder, names_folder, same_file
from hyst_id.io.recording import gap_note, Recording

__all__ = ['add_output_arguments', 'add_recording_arguments', 'add_settings_arguments',
           'load_recording', 'make_spec', 'make_settings', 'parse_columns', 'prepare_outputs',
           'progress_bar', 'reading_notes']


def add_recording_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments naming a recording and how to read it."""
    parser.add_argument('recording', help='rosbag2 MCAP (directory or .mcap file) or CSV')
    parser.add_argument('--channel', choices=tuple(CHAIN_NAMES), default='position',
                        help='measured channel (default: position)')
    parser.add_argument('--params', metavar='YAML',
                        help='params file: the topics and message fields of a bag (a node '
                        "params file works; its node parameters are the node's, GAASS "
                        'settings and domains here come from the flags)')
    parser.add_argument('--columns', metavar='T,CMD,MEAS', default=None,
                        help='CSV columns by name or 0-based index (default t,command,'
                        'measurement)')
    parser.add_argument('--time-scale', type=float, default=None,
                        help='multiply the CSV time column by this to get seconds')
    parser.add_argument('--quiet', action='store_true', help='no progress bar')


def add_output_arguments(parser: argparse.ArgumentParser, what: str, plot: str) -> None:
    """``--json FILE`` (``what`` as JSON) and ``--plot`` (``plot`` says where figures go)."""
    parser.add_argument('--json', metavar='FILE', help=f'write {what} as JSON')
    parser.add_argument('--plot', metavar=plot.split(':')[0], help=plot.split(':', 1)[-1])


def add_settings_arguments(parser: argparse.ArgumentParser, identify: bool = True) -> None:
    """GAASS and refinement settings (paper's defaults).

    With ``identify=False`` only what ``diagnose`` passes on to its fits
    (seeds, population, generations, workers, hops, more starts, domains): the
    identification-only flags are not registered, so giving one is a usage
    error rather than a flag silently ignored.
    """
    g = parser.add_argument_group('GAASS (defaults: the paper)')
    g.add_argument('--seeds', type=int, default=10, help='number of seeds (0..N-1)')
    g.add_argument('--seed-offset', type=int, default=0, help='first seed')
    g.add_argument('--pop-size', type=int, default=10)
    g.add_argument('--generations', type=int, default=500)
    g.add_argument('--workers', type=int, default=0, help='processes (0: one per core)')
    g.add_argument('--hops', type=int, default=100, metavar='N',
                   help='when the best seed ends between 1.1 and 4 x the noise floor, the '
                   'most jumps of basin hopping from it, each polished (default 100; 0 = none)')
    g.add_argument('--more-starts', action='store_true',
                   help='when the chains built from the data stop above the noise floor, '
                   'build five more ways of sharing the loop between H and the backlash '
                   '(slower; finds narrow basins, see docs/model.md)')
    g.add_argument('--domains', default='auto', metavar='auto|paper|YAML',
                   help="search domains: derived from the data (auto), the paper's "
                   'preset (paper), or a YAML mapping name: [low, high] that overrides '
                   'the derived ones')
    g.add_argument('--whole-record', action='store_true',
                   help='fit (diagnose) the whole record even when it seems to start inside '
                   "the play; by default a poor fit is tried again from the command's first "
                   'reversal and the part before it is left out when that fits clearly better')
    g.add_argument('--proper-loops', action='store_true',
                   help='search proper loops only (those the compensator can invert); by '
                   "default a fit (a diagnosis's baseline) left above the floor is tried again "
                   "over the paper's wider set, loops whose output jumps at some reversals "
                   '(docs/model.md)')
    if not identify:
        return
    g.add_argument('--c', type=float, default=0.007, help='search-space contraction rate')
    g.add_argument('--xi', type=float, default=0.02, help='mutation subspace coefficient')
    g.add_argument('--er-bound', type=float, default=None,
                   help='stop a run once %%e_r falls below this')
    g.add_argument('--gaass-only', action='store_true',
                   help='no refinement after GAASS (fidelity to the paper)')
    g.add_argument('--restarts', type=int, default=4,
                   help='extra GAASS runs per seed while %%e_r stays above 1.05 x the '
                   'noise floor (default 4; 0 = one run per seed)')
    g.add_argument('--global-evals', type=int, default=200000, metavar='N',
                   help='evaluations of each global-phase run (one per initial state and '
                   'sensor hold, then longer ones) while the best fit stays above 1.1 x the '
                   'noise floor (default 200000; 0 = no global phase: faster, but a trapped '
                   'fit stays trapped)')
    g.add_argument('--global-runs', type=int, default=14, metavar='N',
                   help='most runs of the global phase (default 14; 0 = none)')
    g.add_argument('--search-samples', type=int, default=20000, metavar='N',
                   help='on a longer record GAASS searches on every k-th sample plus every '
                   'command reversal; refinement and results use all samples '
                   '(default 20000; 0 = search on every sample)')


def load_recording(args: argparse.Namespace) -> Recording:
    """Read and validate the recording named on the command line."""
    from hyst_id.io.csv_reader import time_unit_notes
    from hyst_id.io.readers import read_recording
    from hyst_id.io.topics import load_topic_file

    topics, unused = load_topic_file(args.params, args.channel) if args.params else (None, [])
    if unused:
        print(f'note: {args.params}: only topics and fields are read here; node parameters '
              f'{", ".join(unused[:8])}{" ..." if len(unused) > 8 else ""} are not used (give '
              'GAASS settings and domains as flags)', file=sys.stderr)
    how = {'topics': topics, 'columns': parse_columns(args.columns), 'time_scale': args.time_scale}
    try:
        rec = read_recording(args.recording, args.channel, **how)
    except TruncatedBagError:           # a killed recorder's bag: its complete chunks
        print(f'note: {args.recording} has no MCAP footer (its recorder was killed or the '
              'file was cut): reading its complete chunks; what the recorder held in memory '
              'when it stopped (up to about a second) is not in the file', file=sys.stderr)
        rec = read_recording(args.recording, args.channel, recover_truncated=True, **how)
    for note in time_unit_notes(rec.notes) + [gap_note(rec.t_s)]:
        if note:
            print(f'note: {note}', file=sys.stderr)
    return rec


def reading_notes(notes) -> list[str]:
    """A recording's notes that :func:`load_recording` did not print already.

    The time-unit hints are printed as the recording is read; the rest (stamps
    sorted, messages with a repeated stamp dropped, gaps, the time origin, the
    columns read) say what reading did to the data.
    """
    from hyst_id.io.csv_reader import TIME_UNIT_NOTE
    return [str(n) for n in notes if not str(n).startswith(TIME_UNIT_NOTE)]


def parse_columns(text: str | None) -> tuple[int | str, ...] | None:
    """``--columns T,CMD,MEAS``: three different column names or 0-based indices.

    None (the reader's default columns) for no text.
    """
    if not text:
        return None
    parts = [c.strip() for c in text.split(',')]
    if len(parts) != 3:
        raise ConfigError('--columns needs three entries: time, command, measurement')
    columns = tuple(int(c) if c.lstrip('-').isdigit() else c for c in parts)
    if len(set(columns)) < 3:
        raise ConfigError(f'--columns {text}: time, command and measurement must be three '
                          'different columns')
    return columns


def prepare_outputs(args: argparse.Namespace, *, plot_is_folder: bool) -> None:
    """Before any work: make the folders the outputs go into, refuse paths that cannot be.

    A file output (``--json``, ``--params-out``, ``--sim-out``) that names a
    folder or lies under a file, and a ``--plot`` folder that is a file, are
    a :class:`ConfigError` (exit 2) before the identification runs, not an
    error after it. ``plot_is_folder``: ``--plot`` must name a folder
    (identify writes several figures; a figure's file name is refused); else
    a figure's file name is a file (diagnose's ``FILE.png|DIR``,
    :func:`hyst_id.io.outputs.names_folder`).
    """
    _refuse_overwriting_inputs(args)
    for opt in ('json', 'params_out', 'sim_out'):
        value = getattr(args, opt, None)
        if value:
            flag = '--' + opt.replace('_', '-')
            if Path(value).is_dir():
                raise ConfigError(f'{flag} {value}: a folder; give a file name')
            make_output_folder(Path(value).parent, flag, value)
    plot = getattr(args, 'plot', None)
    if plot:
        path = Path(plot)
        if names_folder(path):
            make_output_folder(path, '--plot', plot)
        elif plot_is_folder:
            raise ConfigError(f'--plot {plot}: a folder for the figures this command writes '
                              f'(several); give a folder name, e.g. {path.with_suffix("")}')
        else:
            make_output_folder(path.parent, '--plot', plot)


#: Arguments naming files a command reads, and those naming files it writes.
_INPUTS = ('recording', 'params', 'sim', 'domains')
_OUTPUTS = ('json', 'params_out', 'sim_out', 'plot')


def _refuse_links_in_folder(folder: Path, inputs: list[Path]) -> None:
    """A ConfigError when a file in the ``--plot`` folder is an input under another name.

    The figures are written over the folder's files of their names: one that is a hard or
    symbolic link to the recording would overwrite it (a review's ``identify_loop.png``).
    """
    if not folder.is_dir():
        return
    files = [f for f in folder.iterdir() if f.is_file()]
    for src in inputs:
        for f in files:
            if same_file(f, src):
                raise ConfigError(f'--plot {folder}: {f.name} there is the input {src} under '
                                  'another name, which a figure would overwrite; give another '
                                  'folder')


def _refuse_overwriting_inputs(args: argparse.Namespace) -> None:
    """A :class:`ConfigError` when an output would overwrite an input or another output.

    ``--json run.csv`` on ``run.csv`` would replace the recording by the
    result; an output that is an existing file inside an input bag folder
    (its ``metadata.yaml`` or ``.mcap``) would damage the bag.
    """
    inputs = [Path(v) for v in (getattr(args, k, None) for k in _INPUTS)
              if isinstance(v, str) and v and Path(v).exists()]
    seen: dict[Path, str] = {}
    for opt in _OUTPUTS:
        value = getattr(args, opt, None)
        if not value:
            continue
        if opt == 'plot' and names_folder(Path(value)):
            _refuse_links_in_folder(Path(value), inputs)
            continue
        flag, out = '--' + opt.replace('_', '-'), Path(value).resolve()
        for src in inputs:
            here = src.resolve()
            if out == here or same_file(out, here) or (
                    here.is_dir() and out.is_file() and here in out.parents):
                what = f'the input {src}' if out == here else f'a file of the input {src}'
                raise ConfigError(f'{flag} {value}: that is {what}, which the output would '
                                  'overwrite; give another file name')
        if out in seen:
            raise ConfigError(f'{flag} {value}: {seen[out]} writes the same file; give each '
                              'output its own name')
        seen[out] = flag


def make_settings(args: argparse.Namespace) -> IdentifySettings:
    """GAASS settings from the command line."""
    return config.make_settings(
        seeds=args.seeds, seed_offset=args.seed_offset, pop_size=args.pop_size,
        generations=args.generations, c=args.c, xi=args.xi, workers=args.workers,
        refine=not args.gaass_only, restarts=args.restarts, er_bound_percent=args.er_bound,
        global_evals=args.global_evals, global_runs=args.global_runs, hops=args.hops,
        search_samples=args.search_samples, more_starts=args.more_starts,
        start_state=not args.whole_record, loose_loops=not getattr(args, 'proper_loops', False))


def make_spec(args: argparse.Namespace, rec: Recording, family: str | None = None) -> ChainSpec:
    """Chain spec with the search domains asked for (``--domains``) and H's ``family``."""
    return config.make_spec(rec, args.domains, family=family)


def progress_bar(**kwargs) -> Any:
    """A tqdm bar on stderr that starts no monitor thread.

    tqdm's monitor thread would make the worker pools spawn instead of fork
    (:func:`hyst_id.identification.workers.mp_context` forks only while the
    process runs one thread), paying every import again in each worker, and
    basin hopping would run in one process. Every command's bar comes from here.
    ``tqdm.monitor_interval`` stays 0 for the rest of the process.

    Parameters
    ----------
    **kwargs
        Passed to ``tqdm`` (``total``, ``desc``, ``unit``, ...).

    Returns
    -------
    tqdm.tqdm
    """
    import sys

    from tqdm import tqdm
    tqdm.monitor_interval = 0
    return tqdm(file=sys.stderr, **kwargs)
