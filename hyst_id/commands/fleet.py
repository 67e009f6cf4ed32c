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

"""``hyst-id fleet DIR_OR_GLOB ...``: identify (and diagnose) many recordings, one row each."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
import re
import sys

from hyst_id.commands.common import parse_columns, progress_bar
from hyst_id.errors import ConfigError
from hyst_id.fleet import find_recordings, FleetOptions, loop_trends, run_fleet, write_table
from hyst_id.fleet.table import fleet_rows
from hyst_id.identification.config import make_settings
from hyst_id.io.csv_reader import time_unit_notes
from hyst_id.io.outputs import make_output_folder
from hyst_id.io.recording import CHANNELS

__all__ = ['add_arguments', 'run']


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``fleet``."""
    parser.add_argument('inputs', nargs='+', metavar='DIR_OR_GLOB',
                        help='bag directories, .mcap or CSV files, directories searched '
                        'recursively, or globs')
    parser.add_argument('--out', required=True, metavar='DIR',
                        help='fleet.csv (and fleet.parquet with pyarrow), trends.json and '
                        'recordings/*.json go here; recordings already done are skipped')
    parser.add_argument('--channel', default='position', choices=CHANNELS)
    parser.add_argument('--topics', metavar='YAML', help='topic configuration of the bags '
                        '(params/topics.yaml layout)')
    parser.add_argument('--seeds', type=int, default=4, help='GAASS seeds per recording')
    parser.add_argument('--generations', type=int, default=500)
    parser.add_argument('--model', default='tk', choices=('tk', 'smooth'))
    parser.add_argument('--diagnose', action='store_true', help='also run hyst-id diagnose')
    parser.add_argument('--workers', type=int, default=0,
                        help='worker processes (0 = one per core)')
    parser.add_argument('--address', metavar='ADDR', help='a Dask scheduler address '
                        '(tcp://host:8786), or "local" for a Dask cluster on this machine; '
                        'default: a local process pool')
    parser.add_argument('--valve-regex', metavar='REGEX', help='the valve of a recording: '
                        'group 1 of REGEX searched in its path (default: the name of the '
                        'parent directory)')
    parser.add_argument('--columns', metavar='T,CMD,MEAS', default=None,
                        help='CSV columns by name or 0-based index (default t,command,'
                        'measurement)')
    parser.add_argument('--time-scale', type=float, default=None,
                        help='multiply the CSV time column by this to get seconds')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')


def _valve_of(regex: str):
    try:
        pattern = re.compile(regex)
    except re.error as exc:
        raise ConfigError(f'--valve-regex: {exc}') from None

    def valve_of(path: str) -> str:
        m = pattern.search(path)
        if m is None:
            return Path(path).parent.name
        return m.group(1) if m.groups() else m.group(0)
    return valve_of


def run(args: argparse.Namespace) -> int:
    """Run the fleet; exit 0 when every recording was identified, 1 when some failed."""
    make_settings(seeds=args.seeds, generations=args.generations, workers=args.workers)
    columns = parse_columns(args.columns)
    if args.time_scale is not None and not (math.isfinite(args.time_scale)
                                            and args.time_scale > 0.0):
        raise ConfigError(f'--time-scale must be a finite number > 0, got {args.time_scale}')
    recordings = find_recordings(args.inputs)
    out = Path(args.out).resolve()      # the fleet's own table and results are no recordings
    own = [r for r in recordings if out in r.resolve().parents]
    if own:
        print(f'note: {len(own)} file(s) under --out {args.out} skipped (this command writes '
              f'its results there): {", ".join(r.name for r in own[:3])}'
              f'{" ..." if len(own) > 3 else ""}', file=sys.stderr)
        recordings = [r for r in recordings if r not in own]
    if not recordings:
        raise ConfigError(f'no recordings found under {", ".join(args.inputs)}')
    make_output_folder(Path(args.out), '--out', args.out)
    topics = None
    if args.topics:
        from hyst_id.io.topics import load_topic_config
        topics = load_topic_config(args.topics, args.channel)
    valve_of = _valve_of(args.valve_regex) if args.valve_regex else None
    options = FleetOptions(channel=args.channel, seeds=args.seeds,
                           generations=args.generations, model=args.model,
                           diagnose=args.diagnose, topics=topics, columns=columns,
                           time_scale=args.time_scale)
    bar = None
    if not args.no_progress:
        bar = progress_bar(total=len(recordings), unit='rec', desc='fleet')

    def progress(done: int, total: int, doc: dict) -> None:
        if bar is not None:
            bar.total = total
            bar.update(1)
            bar.set_postfix_str(f'{Path(doc["recording"]).name}: {doc["status"]}')

    print(f'{len(recordings)} recording(s); results in {args.out}', file=sys.stderr)
    try:
        docs = run_fleet(recordings, args.out, options, workers=args.workers,
                         address=args.address, progress=progress)
    finally:
        if bar is not None:
            bar.close()
    rows = fleet_rows(docs, valve_of)
    for path in write_table(rows, args.out):
        print(f'wrote {path}', file=sys.stderr)
    trends = loop_trends(rows)
    (Path(args.out) / 'trends.json').write_text(json.dumps(trends, indent=1))
    ok = [r for r in rows if r['status'] == 'ok']
    bad = [r for r in rows if r['status'] != 'ok']
    resumed = sum(1 for d in docs if d.get('resumed'))
    print(f'{len(ok)} identified ({resumed} from an earlier run), {len(bad)} failed')
    for r in bad:     # a reader's error names the file already
        print(f'  failed: {r["recording"]}: '
              f'{str(r["error"]).removeprefix(str(r["recording"]) + ": ")}')
    for d in docs:    # a CSV time column read as seconds that looks like another unit
        for note in time_unit_notes(d.get('notes') or []):
            print(f'  note: {Path(d["recording"]).name}: {note}')
    for t in trends:
        if t['flagged']:
            print(f'  trend: valve {t["valve"]}: {t["metric"]} {t["first"]:.4g} -> '
                  f'{t["last"]:.4g} over {t["n"]} recordings ({t["change_percent"]:+.0f} %)')
    return 1 if bad else 0
