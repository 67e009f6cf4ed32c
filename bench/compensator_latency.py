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

"""Compensator latency: compute time per sample, and desired -> command through DDS.

1. Compute: :meth:`hyst_id.compensation.Compensator.step` with the paper's
   hysteresis and with a smooth-family set (with and without the slope past
   saturation, ``w_l``: closed-form and Newton inverse), timed sample by
   sample (target: median < 20 us).
2. Loopback: the compensator node runs as its own process (own ROS domain,
   localhost discovery); this script publishes Eq. 25 desired values at
   100 Hz and 1 kHz and times each compensated command's arrival. Commands
   are matched to desired values by order (both streams are reliable,
   keep-all: ``hyst_id.nodes.COMMAND_QOS``; with the former keep-last depth
   100, 280 of 5000 were lost at 1 kHz under load) and checked against a
   local Compensator fed the same values.

``bench/compensator_load.py`` adds parameter updates mid-stream (60 s).

Usage: ``python bench/compensator_latency.py [--seconds 5] [--domain 91] [--compute-only]
[--stamped]``
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time

import numpy as np

PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}
#: A smooth-family set around the same operating point (9 mA -> 9 out).
SMOOTH = {'family': 'smooth', 'w_0': 0.5, 'w_1': 0.2, 'w_2': 0.1, 'w_3': 0.1, 'w_4': 0.05,
          'w_5': 0.05, 'w_l': 0.0, 'r_max': 0.8, 'v_s': 4.0, 'v_c': 9.0, 'c_o': 9.0,
          'm_bl': 1.0, 'c_bl': -0.1, 'c_br': 0.1}
MODELS = {'tk (paper)': PAPER, 'smooth, w_l = 0 (closed form)': SMOOTH,
          'smooth, w_l > 0 (Newton)': {**SMOOTH, 'w_l': 0.1}}


def compute_times(n: int = 100_000, model: dict | None = None) -> np.ndarray:
    """Per-sample compute time (ns) of Compensator.step on Eq. 25 desired values."""
    from hyst_id.compensation import CommandLimits, Compensator, InverseModel
    comp = Compensator(InverseModel.from_mapping(model or PAPER), CommandLimits(4.0, 20.0),
                       v0=9.0)
    desired = 9.0 + np.sin(2 * np.pi * np.arange(n) * 0.01 / 12.0)
    for d in desired[:2000]:                       # JIT / cache warm-up
        comp.step(float(d), 0.0)
    out = np.empty(n, dtype=np.int64)
    clock = time.perf_counter_ns
    for k, d in enumerate(desired.tolist()):
        t0 = clock()
        comp.step(d, k * 0.01)
        out[k] = clock() - t0
    return out


def loopback(rate_hz: float, seconds: float, context, ref, stamped: bool = False) -> dict:
    """Publish desired values at ``rate_hz`` and time the compensated commands.

    ``ref`` is a local Compensator that has seen everything the node has;
    ``stamped``: both streams ``hyst_id_interfaces/msg/StampedValue``.
    """
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from hyst_id.io.interface_types import FLOAT64_TYPE, STAMPED_VALUE_TYPE
    from hyst_id.nodes.support import COMMAND_QOS, ScalarStream, spin_in_background

    stream = ScalarStream(STAMPED_VALUE_TYPE if stamped else FLOAT64_TYPE)
    node = Node(f'latency_{int(rate_hz)}', context=context)
    pub = node.create_publisher(stream.cls, '/hyst_id/desired', COMMAND_QOS)
    recv: list[tuple[int, float]] = []
    node.create_subscription(stream.cls, '/hyst_id/command',
                             lambda m: recv.append((time.monotonic_ns(), stream.value(m))),
                             COMMAND_QOS)
    clock = node.get_clock()
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    stop_spinning = spin_in_background(ex)
    deadline = time.monotonic() + 20.0
    while (pub.get_subscription_count() < 1 or node.count_publishers('/hyst_id/command') < 1) \
            and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    n = int(rate_hz * seconds)
    period = 1.0 / rate_hz
    desired = 9.0 + np.sin(2 * np.pi * np.arange(n) * period / 12.0)
    sent = np.empty(n, dtype=np.int64)
    start = time.monotonic()
    for k in range(n):
        due = start + k * period
        while True:
            now = time.monotonic()
            if now >= due:
                break
            time.sleep(min(due - now, 0.0005))
        sent[k] = time.monotonic_ns()
        pub.publish(stream.make(float(desired[k]), clock.now().to_msg() if stamped else None))
    time.sleep(1.0)
    stop_spinning()
    ex.remove_node(node)
    node.destroy_node()
    # Match each command to the desired sample it answers: the next sample, in order,
    # whose locally compensated value it equals (a lost input changes the inverse's
    # output only around a reversal, so the search resynchronises).
    expect = np.array([ref.step(float(d)) for d in desired])
    lat_us, unmatched, j = [], 0, 0
    for t_ns, value in recv:
        hits = np.flatnonzero(np.abs(expect[j:j + 2000] - value) <= 1e-9)
        if hits.size == 0:
            unmatched += 1
            continue
        k = j + int(hits[0])
        lat_us.append((t_ns - sent[k]) / 1e3)
        j = k + 1
    lat = np.array(lat_us) if lat_us else np.array([np.nan])
    return {'rate_hz': rate_hz, 'sent': n, 'received': len(recv), 'lost': n - len(recv),
            'median_us': float(np.median(lat)), 'p99_us': float(np.percentile(lat, 99)),
            'max_us': float(np.max(lat)), 'mismatched': unmatched}


def main(argv: list[str] | None = None) -> int:
    """Run both benchmarks and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='length of each DDS run')
    parser.add_argument('--domain', type=int, default=91, help='ROS_DOMAIN_ID to use')
    parser.add_argument('--compute-only', action='store_true', help='skip the DDS loopback')
    parser.add_argument('--stamped', action='store_true',
                        help='desired and command as hyst_id_interfaces/msg/StampedValue '
                             '(params/stamped.yaml; needs the interfaces package built)')
    args = parser.parse_args(argv)

    print('compute: Compensator.step (H^-1 and B^-1), per sample')
    for name, model in MODELS.items():
        ns = compute_times(model=model)
        print(f'  {name:32s} median {np.median(ns) / 1e3:7.2f} us   p99 '
              f'{np.percentile(ns, 99) / 1e3:7.2f} us   (target median < 20 us: '
              f'{"met" if np.median(ns) < 20e3 else "NOT met"})')
    if args.compute_only:
        return 0

    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    overrides = [a for k, v in PAPER.items() for a in ('-p', f'{k}:={v!r}')]
    if args.stamped:
        overrides += ['-p', 'topics.desired_type:=hyst_id_interfaces/msg/StampedValue',
                      '-p', 'topics.command_type:=hyst_id_interfaces/msg/StampedValue']
    import rclpy

    from hyst_id.compensation import CommandLimits, Compensator, InverseModel
    context = rclpy.Context()
    rclpy.init(context=context)
    rows = []
    try:
        for rate in (100.0, 1000.0):      # a fresh compensator process per rate
            comp = subprocess.Popen([sys.executable, '-m', 'hyst_id.nodes.compensator',
                                     '--ros-args', *overrides, '-p', 'max_rate_per_s:=0.0'],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
            try:
                ref = Compensator(InverseModel.from_mapping(PAPER), CommandLimits(4.0, 20.0),
                                  v0=9.0)
                rows.append(loopback(rate, args.seconds, context, ref, args.stamped))
            finally:
                comp.send_signal(signal.SIGINT)
                comp.wait(15)
    finally:
        context.try_shutdown()
    print('\nloopback through DDS: desired -> compensator node -> command '
          '(separate processes, localhost'
          + (', StampedValue streams)' if args.stamped else ', Float64 streams)'))
    print(f'  {"rate":>7} {"sent":>6} {"lost":>5} {"median":>9} {"p99":>9} {"max":>9} '
          f'{"unmatched":>9}')
    for r in rows:
        print(f'  {r["rate_hz"]:5.0f}Hz {r["sent"]:6d} {r["lost"]:5d} {r["median_us"]:7.0f}us '
              f'{r["p99_us"]:7.0f}us {r["max_us"]:7.0f}us {r["mismatched"]:9d}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
