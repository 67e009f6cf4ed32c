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

"""Throughput of the population kernel: chain samples per second on one core.

For each channel, a population of feasible candidates (the test chain's
parameters, jittered) is scored on the paper's Eq. 24 run (2000 samples)
by :func:`hyst_id.identification.chains.population_cost` through ``ChainSpec.cost_function``
(affine calibration profiled: one simulation pass and two passes for the
fit). One chain sample = one candidate advanced by one time step. The
kernel is single-threaded numba; the best of several repeats is reported.
Target: >= 50 M samples/s per core.

Usage: ``python bench/kernel_throughput.py [--pop 64] [--samples 2000] [--repeats 20]``
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))

from hyst_id.identification.chains import chain_spec  # noqa: E402

__all__ = ['throughput', 'main']

TRUE_PARAMS = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0,
                        1.0, -0.15, 0.15, 0.5, 0.6])
TARGET = 50e6


def throughput(channel: str, pop_size: int = 64, n_samples: int = 2000,
               repeats: int = 20, uniform: bool = True) -> float:
    """Chain samples per second of the population kernel for one channel.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    pop_size : int
        Candidates per call.
    n_samples : int
        Samples of the recording.
    repeats : int
        Timed calls; the fastest counts.
    uniform : bool
        Uniform sampling (sensor coefficients computed once) or jittered
        timestamps (recomputed per sample).
    """
    spec = chain_spec(channel)
    dt_s = 100.0 / n_samples
    t = np.arange(n_samples) * dt_s
    if not uniform:
        t = t + np.random.default_rng(0).uniform(0.0, 0.3 * dt_s, n_samples)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    x0 = TRUE_PARAMS[:spec.n_params]
    y = spec.simulate(x0, t, v)
    rng = np.random.default_rng(1)
    pop = np.empty((0, spec.n_params))
    while pop.shape[0] < pop_size:              # keep feasible jittered candidates
        draw = x0 * (1.0 + 0.01 * rng.standard_normal((pop_size, spec.n_params)))
        pop = np.vstack([pop, draw[spec.feasible(draw)]])
    pop = np.ascontiguousarray(pop[:pop_size])
    cost = spec.cost_function(t, v, y)
    cost(pop)                                   # compile / load the cache
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        cost(pop)
        best = min(best, time.perf_counter() - start)
    return pop_size * n_samples / best


def main(argv: list[str] | None = None) -> int:
    """Print samples per second per channel."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--pop', type=int, default=64)
    parser.add_argument('--samples', type=int, default=2000)
    parser.add_argument('--repeats', type=int, default=20)
    args = parser.parse_args(argv)
    print(f'population kernel, {args.pop} candidates x {args.samples} samples, one thread')
    print(f'{"channel":9s} {"sampling":10s} {"M samples/s":>12s}  target {TARGET / 1e6:.0f}')
    for channel in ('position', 'pressure', 'flow'):
        for uniform in (True, False):
            rate = throughput(channel, args.pop, args.samples, args.repeats, uniform)
            mark = 'ok' if rate >= TARGET else 'BELOW'
            print(f'{channel:9s} {"uniform" if uniform else "jittered":10s} '
                  f'{rate / 1e6:12.1f}  {mark}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
