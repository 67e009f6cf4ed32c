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

"""Stops under stress: start and stop every executable many times; count what goes wrong.

Each executable is started ``--repeats`` times (default 20) in its own ROS
domain and stopped with SIGINT or SIGTERM (alternating) at a random delay
after its first log line (0 - 1 s: during construction, warm-up and the
first spins). Printed per executable: hangs (no exit within 20 s), wrong
exit codes (130 after SIGINT, 0 after SIGTERM), tracebacks, and the median
and longest time from the signal to the exit. Then an identification with
two worker processes is killed (SIGKILL) and interrupted (SIGINT)
``--repeats`` / 4 times each, counting worker processes left behind.

Usage: ``python bench/stop_stress.py [--repeats 20] [--nodes compensator,identifier]``
(run with ``test/`` on ``PYTHONPATH``; about 10 minutes for the default).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import random
import signal
import statistics
import sys
import tempfile

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test' / 'nodes'))
from test_interrupts import node_command, NODES, orphans_after, stop_once  # noqa: E402, I100


def stress_node(node: str, repeats: int, rng: random.Random, tmp: Path) -> dict:
    """Start/stop ``node`` ``repeats`` times; the counts and stop times."""
    problems, times = [], []
    for k in range(repeats):
        sig = signal.SIGINT if k % 2 == 0 else signal.SIGTERM
        env = dict(os.environ, ROS_HOME=str(tmp), ROS_DOMAIN_ID=str(100 + k % 100),
                   ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
        problem, elapsed = stop_once(node_command(node, tmp), env, sig, rng.uniform(0.0, 1.0))
        if problem:
            problems.append(problem.splitlines()[0])
        if elapsed != float('inf'):
            times.append(elapsed)
    return {'hangs': sum('hung' in p for p in problems),
            'bad_exits': sum('exit' in p for p in problems), 'problems': problems,
            'median_s': statistics.median(times) if times else float('nan'),
            'max_s': max(times) if times else float('nan')}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--repeats', type=int, default=20)
    ap.add_argument('--nodes', default=','.join(NODES))
    ap.add_argument('--seed', type=int, default=0)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    print(f'# {args.repeats} starts per executable, SIGINT / SIGTERM alternating, '
          'random delay 0 - 1 s after the first log line')
    print('| executable | starts | hangs | wrong exit codes | stop time median / max [s] |')
    print('|---|---|---|---|---|')
    total = 0
    with tempfile.TemporaryDirectory() as d:
        for node in args.nodes.split(','):
            r = stress_node(node, args.repeats, rng, Path(d))
            total += r['hangs'] + r['bad_exits']
            print(f'| {node} | {args.repeats} | {r["hangs"]} | {r["bad_exits"]} | '
                  f'{r["median_s"]:.2f} / {r["max_s"]:.2f} |', flush=True)
            for p in r['problems'][:3]:
                print(f'#   {node}: {p}')
        n = max(1, args.repeats // 4)
        for sig in (signal.SIGKILL, signal.SIGINT):
            left = [orphans_after(sig, f'{Path(d).name}-{sig}-{k}') for k in range(n)]
            print(f'# identification with 2 workers, {signal.Signals(sig).name} x {n}: '
                  f'{sum(x for x in left if x > 0)} worker process(es) left behind'
                  + (f', {left.count(-1)} runs whose workers never started'
                     if -1 in left else ''), flush=True)
    print(f'# problems in total: {total}')


if __name__ == '__main__':
    main()
