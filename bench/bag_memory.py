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

"""Peak memory of reading a long bag against the size of what is read.

Writes a pressure bag of ``--samples`` samples at 1 kHz (one command and one
``FluidPressure`` message per sample, as the recorder logs them), then reads
it back with :func:`hyst_id.io.readers.read_recording` under ``tracemalloc``
(numpy's buffers are traced too) and prints, per length: the bag's size on
disk, the recording's arrays (time, command, measurement: 24 bytes a
sample), the peak traced during the read and the peak per sample. A reader
that loads the whole bag, or keeps Python lists of numbers, shows as a peak
many times the arrays and growing faster than them.

Usage: ``python bench/bag_memory.py [--samples 100000 300000] [--keep DIR]``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import tempfile
import time
import tracemalloc

import numpy as np

from hyst_id.io.bag import write_recording_bag
from hyst_id.io.readers import read_recording
from hyst_id.io.recording import Recording


def _bag(directory: Path, n: int) -> Path:
    t = np.arange(n) * 0.001
    v = 9.0 + 2.0 * np.sin(2 * np.pi * t / 10.0)
    y = 2.0e5 + 1.0e3 * v + np.random.default_rng(0).normal(0.0, 50.0, n)
    return write_recording_bag(directory / f'bag_{n}',
                               Recording(t, v, y, 'pressure', 'mA', 'Pa', 'bench'))


def _size_mb(path: Path) -> float:
    return sum(f.stat().st_size for f in path.rglob('*') if f.is_file()) / 1e6


def main(argv: list[str] | None = None) -> int:
    """Print one row per length."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--samples', type=int, nargs='+', default=[100_000, 300_000])
    ap.add_argument('--keep', metavar='DIR', help='write the bags here and keep them')
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        where = Path(args.keep) if args.keep else Path(tmp)
        where.mkdir(parents=True, exist_ok=True)
        print('| samples | bag on disk [MB] | arrays [MB] | peak while reading [MB] | '
              'peak / arrays | peak per sample [B] | read [s] |')
        print('|---|---|---|---|---|---|---|')
        for n in args.samples:
            path = _bag(where, n)
            tracemalloc.start()
            t0 = time.perf_counter()
            rec = read_recording(path, 'pressure')
            seconds = time.perf_counter() - t0
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            arrays = rec.t_s.nbytes + rec.command.nbytes + rec.measurement.nbytes
            print(f'| {n} | {_size_mb(path):.1f} | {arrays / 1e6:.1f} | {peak / 1e6:.1f} | '
                  f'{peak / arrays:.2f} | {peak / n:.0f} | {seconds:.1f} |', flush=True)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
