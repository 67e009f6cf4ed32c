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

"""Fleet throughput: recordings per second and per core, and the scaling from 1 to 2 workers.

Writes ``--n`` bags of the independent reference simulator (1,200 samples
each, a paper loop with backlash, 1 % noise) and runs ``run_fleet`` on them
with a local process pool of 1 and of 2 workers and on a local Dask cluster
of 2 workers (settings: ``--seeds`` seeds of ``--generations``
generations). Prints wall time, recordings per second, per core, and the
speed-up of 2 workers over 1.

Usage: ``python bench/fleet_throughput.py [--n 16] [--seeds 2] [--generations 200]``
(with ``test/`` on ``PYTHONPATH``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test' / 'fleet'))
from test_fleet import _recording  # noqa: E402, I100

from hyst_id.fleet import FleetOptions, run_fleet  # noqa: E402
from hyst_id.io.bag import write_recording_bag  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=16)
    ap.add_argument('--seeds', type=int, default=2)
    ap.add_argument('--generations', type=int, default=200)
    args = ap.parse_args()
    options = FleetOptions(seeds=args.seeds, generations=args.generations)
    with tempfile.TemporaryDirectory() as d:
        root = Path(d)
        recs = []
        for k in range(args.n):
            recs.append(write_recording_bag(root / 'bags' / f'rec{k:03d}',
                                            _recording(0.1 + 0.005 * k, k)))
        print(f'# {args.n} recordings of 1,200 samples; {args.seeds} seed(s) x '
              f'{args.generations} generations each')
        print('| engine | workers | wall s | recordings/s | per worker | speed-up |')
        print('|---|---|---|---|---|---|')
        base = None
        for engine, workers, address in (('process pool', 1, None), ('process pool', 2, None),
                                         ('Dask LocalCluster', 2, 'local')):
            out = root / f'out_{engine.split()[0]}_{workers}'
            t0 = time.monotonic()
            docs = run_fleet(recs, out, options, workers=workers, address=address)
            wall = time.monotonic() - t0
            ok = sum(d['status'] == 'ok' for d in docs)
            base = base or wall
            print(f'| {engine} | {workers} | {wall:.1f} | {ok / wall:.2f} | '
                  f'{ok / wall / workers:.2f} | {base / wall:.2f} |', flush=True)


if __name__ == '__main__':
    main()
