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

"""Compensator under load: 1 kHz desired values over DDS with parameter updates mid-stream.

The compensator node runs as its own process (own ROS domain, localhost
discovery) with the paper's model. This script publishes desired values at
``--rate`` Hz for ``--seconds`` (with a few NaN/inf among them), and every
``--update-every`` seconds sends a ``set_parameters_atomically`` request,
cycling through valid sets (new model, new model together with new command
limits) and invalid ones (a loop that is not proper, an incomplete set,
``output_sign`` 0.5, an infinite slope). It then checks:

* **nothing lost**: commands received == desired values sent (reliable,
  keep-all QoS; a refused publish is retried and counted);
* **limits**: every command within the limits of the set in force for it;
* **updates**: every valid update applied, every invalid one rejected with
  a reason, and each applied one announced once on ``/compensator/active_set``
  (generation and first sample);
* **atomicity**: a shadow :class:`hyst_id.compensation.Compensator`, run
  offline over the sent desired values and switched to each announced set
  at its first sample, reproduces every received command exactly: each
  command came from exactly one complete parameter set, and the switches
  happened where the node said.

``run_load`` is also what ``test/nodes/test_reliability_ros.py`` runs (5 s).

Usage: ``python bench/compensator_load.py [--seconds 60] [--rate 1000] [--domain 92]``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import time
from typing import Any

import numpy as np

PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}

#: (name, parameters, should be accepted), sent in turn.
UPDATES: list[tuple[str, dict[str, float], bool]] = [
    ('wider loop', {**PAPER, 'c_r': 0.6}, True),
    ('not proper', {**PAPER, 'c_l': 0.9}, False),
    ('model + limits', {**PAPER, 'm_t': 0.12, 'c_br': 0.3, 'max_command': 10.2}, True),
    ('incomplete', {'m_l': math.nan}, False),
    ('paper again', {**PAPER, 'max_command': 20.0, 'min_command': 8.6}, True),
    ('output_sign 0.5', {**PAPER, 'output_sign': 0.5}, False),
    ('narrow backlash', {**PAPER, 'c_bl': -0.1, 'c_br': 0.1, 'min_command': 4.0}, True),
    ('infinite slope', {**PAPER, 'm_l': math.inf}, False),
]


def desired_values(n: int, rate_hz: float) -> np.ndarray:
    """A 2 s sine of 1.2 units around 9 with a NaN and an inf every 1000 samples."""
    t = np.arange(n) / rate_hz
    out = 9.0 + 1.2 * np.sin(2 * np.pi * t / 2.0)
    out[499::1000] = np.nan
    out[999::1000] = np.inf
    return out


def _start_compensator(log_path: str) -> subprocess.Popen:
    overrides = [a for k, v in PAPER.items() for a in ('-p', f'{k}:={v!r}')]
    log = open(log_path, 'w')
    return subprocess.Popen(
        [sys.executable, '-m', 'hyst_id.nodes.compensator', '--ros-args', *overrides,
         '-p', 'max_rate_per_s:=0.0', '-p', 'follow_identified_params:=false'],
        stdout=log, stderr=subprocess.STDOUT, env=os.environ.copy())


def run_load(rate_hz: float = 1000.0, seconds: float = 60.0, update_every_s: float = 1.0,
             log_path: str = 'compensator_load.log') -> dict[str, Any]:
    """Drive a compensator process at ``rate_hz``; return the counts (see module docstring)."""
    from rcl_interfaces.srv import SetParametersAtomically
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float64, String

    from hyst_id.nodes.compensator import ACTIVE_SET_QOS
    from hyst_id.nodes.support import COMMAND_QOS, spin_in_background, try_publish

    proc = _start_compensator(log_path)
    context = rclpy.Context()
    rclpy.init(context=context)
    node = Node('load_driver', context=context)
    recv: list[tuple[int, float]] = []
    sets: list[dict] = []
    pub = node.create_publisher(Float64, '/hyst_id/desired', COMMAND_QOS)
    node.create_subscription(Float64, '/hyst_id/command',
                             lambda m: recv.append((time.monotonic_ns(), m.data)), COMMAND_QOS)
    node.create_subscription(String, '/compensator/active_set',
                             lambda m: sets.append(json.loads(m.data)), ACTIVE_SET_QOS)
    client = node.create_client(SetParametersAtomically,
                                '/compensator/set_parameters_atomically')
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    stop_spinning = spin_in_background(ex)
    try:
        deadline = time.monotonic() + 30.0
        while not (pub.get_subscription_count() >= 1 and client.service_is_ready() and sets
                   and node.count_publishers('/hyst_id/command') >= 1):
            if time.monotonic() > deadline or proc.poll() is not None:
                raise RuntimeError(f'compensator not ready (see {log_path})')
            time.sleep(0.05)
        time.sleep(0.3)
        n = int(round(rate_hz * seconds))
        period = 1.0 / rate_hz
        desired = desired_values(n, rate_hz)
        every = max(1, int(round(update_every_s * rate_hz)))
        requests = []
        sent_ns = np.empty(n, dtype=np.int64)
        retries = 0
        start = time.monotonic()
        for k in range(n):
            due = start + k * period
            while True:
                now = time.monotonic()
                if now >= due:
                    break
                time.sleep(min(due - now, 0.0005))
            if k and k % every == 0:
                name, values, ok = UPDATES[(k // every - 1) % len(UPDATES)]
                params = [Parameter(p, value=float(v)) for p, v in values.items()]
                requests.append((k, name, ok, client.call_async(SetParametersAtomically.Request(
                    parameters=[p.to_parameter_msg() for p in params]))))
            sent_ns[k] = time.monotonic_ns()
            while not try_publish(pub, Float64(data=float(desired[k]))):
                retries += 1
        publish_s = time.monotonic() - start
        deadline = time.monotonic() + 10.0 + seconds
        while len(recv) < n and time.monotonic() < deadline:
            time.sleep(0.05)
        while not all(f.done() for *_, f in requests) and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.3)
    finally:
        stop_spinning()
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
        ex.remove_node(node)
        node.destroy_node()
        context.try_shutdown()
    return _analyse(desired, sent_ns, recv, sets, requests, rate_hz, seconds, publish_s,
                    retries, code)


def _analyse(desired: np.ndarray, sent_ns: np.ndarray, recv: list, sets: list, requests: list,
             rate_hz: float, seconds: float, publish_s: float, retries: int,
             code: int) -> dict[str, Any]:
    from hyst_id.compensation import CommandLimits, Compensator, InverseModel

    n = desired.size
    out = np.array([v for _, v in recv])
    sets = sorted({s['generation']: s for s in sets}.values(), key=lambda s: s['generation'])
    applied = [r for r in requests if r[3].done() and r[3].result().result.successful]
    rejected = [r for r in requests if r[3].done() and not r[3].result().result.successful]
    wrong = [r[1] for r in applied if not r[2]] + [r[1] for r in rejected if r[2]]
    reasons = sorted({f'{r[1]}: {r[3].result().result.reason}' for r in rejected})
    # limits of the set in force for each sample
    firsts = np.array([s['first_sample'] for s in sets])
    gen_of = np.searchsorted(firsts, np.arange(out.size), side='right') - 1
    lo = np.array([s['min_command'] for s in sets])[gen_of]
    hi = np.array([s['max_command'] for s in sets])[gen_of]
    outside = int(np.sum((out < lo) | (out > hi) | ~np.isfinite(out)))
    # shadow compensator switched at the announced boundaries

    def model_of(s: dict) -> InverseModel | None:
        return None if s['model'] is None else InverseModel.from_mapping(s['model'])

    shadow = Compensator(model_of(sets[0]), CommandLimits(sets[0]['min_command'],
                                                          sets[0]['max_command']), v0=9.0)
    expect = np.empty(n)
    g = 1
    for j in range(n):
        while g < len(sets) and sets[g]['first_sample'] == j:
            s = sets[g]
            model = model_of(s)
            shadow.limits = CommandLimits(s['min_command'], s['max_command'])
            if model != shadow.model:
                shadow.set_model(model)
            g += 1
        expect[j] = shadow.step(float(desired[j]))
    m = min(n, out.size)
    mismatched = int(np.sum(np.abs(out[:m] - expect[:m]) > 1e-9)) + (n - m)
    lat_us = (np.array([t for t, _ in recv[:m]]) - sent_ns[:m]) / 1e3 if m else np.array([0.])
    valid_sent = sum(1 for r in requests if r[2])
    return {
        'rate_hz': rate_hz, 'seconds': seconds, 'sent': n, 'received': int(out.size),
        'lost': int(n - out.size), 'publish_retries': retries,
        'achieved_rate_hz': n / publish_s if publish_s > 0 else math.nan,
        'out_of_limits': outside, 'updates_sent': len(requests), 'valid_sent': valid_sent,
        'applied': len(applied), 'rejected': len(rejected),
        'unanswered': len(requests) - len(applied) - len(rejected),
        'wrong_outcome': wrong, 'reasons': reasons,
        'generations': [s['generation'] for s in sets],
        'boundaries': [s['first_sample'] for s in sets],
        'shadow_mismatches': mismatched,
        'latency_median_us': float(np.median(lat_us)),
        'latency_p99_us': float(np.percentile(lat_us, 99)),
        'latency_max_us': float(np.max(lat_us)), 'compensator_exit': code,
    }


def report(r: dict[str, Any]) -> str:
    """Human-readable summary of :func:`run_load`."""
    return '\n'.join([
        f'compensator under load: {r["rate_hz"]:.0f} Hz for {r["seconds"]:g} s '
        f'(achieved {r["achieved_rate_hz"]:.0f} Hz), separate processes, localhost DDS',
        f'  messages: sent {r["sent"]}, received {r["received"]}, lost {r["lost"]} '
        f'(publish retries {r["publish_retries"]})',
        f'  outputs outside the command limits: {r["out_of_limits"]}',
        f'  updates: {r["updates_sent"]} sent ({r["valid_sent"]} valid), {r["applied"]} '
        f'applied, {r["rejected"]} rejected, {r["unanswered"]} unanswered, wrong outcome: '
        f'{r["wrong_outcome"] or "none"}',
        f'  generations announced: {len(r["generations"])} (0..{r["generations"][-1]}); '
        f'shadow compensator mismatches: {r["shadow_mismatches"]}',
        f'  latency desired -> command: median {r["latency_median_us"]:.0f} us, p99 '
        f'{r["latency_p99_us"]:.0f} us, max {r["latency_max_us"]:.0f} us',
        '  rejection reasons: ' + ('; '.join(r['reasons']) or 'none'),
        f'  compensator exit code: {r["compensator_exit"]}',
    ])


def main(argv: list[str] | None = None) -> int:
    """Run the full load test and print the counts; exit 1 if anything was lost or wrong."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=60.0)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--update-every', type=float, default=1.0, help='seconds')
    parser.add_argument('--domain', type=int, default=92, help='ROS_DOMAIN_ID to use')
    parser.add_argument('--log', default='/tmp/compensator_load.log')
    args = parser.parse_args(argv)
    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    r = run_load(args.rate, args.seconds, args.update_every, args.log)
    print(report(r))
    bad = (r['lost'] or r['out_of_limits'] or r['wrong_outcome'] or r['unanswered']
           or r['shadow_mismatches'] or r['compensator_exit'] not in (0, 130))
    return 1 if bad else 0


if __name__ == '__main__':
    raise SystemExit(main())
