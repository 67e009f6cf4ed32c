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

"""The identifier's sliding-window re-identification: schedule, worker job, swaps in the log.

With ``sliding.enabled``, once the node has identified a set, it refits the
newest ``sliding.window_s`` of live samples every ``sliding.period_s`` in a
worker thread (:class:`hyst_id.live.jobs.SlidingJob`, never on the
executor), holding the newest ``sliding.holdout_s`` out, and hands the new
set over (params file, compensator, latched topic) only when
:func:`hyst_id.live.sliding.reidentify_window` says it is significantly
better there and passes the quality gate. CPU is bounded: after a fit that
took ``E`` s the next waits at least ``E (1 / sliding.cpu_share - 1)`` s.
Every decision, swap or not, is logged with its reason and published
latched on ``~/sliding`` (JSON). The set refitted is the one last handed
over; a decision reached while another set was handed over (a full
identification) is discarded as superseded, and a full identification
cancels a running window fit. The fits hold the GIL most of the time: a
compensator in the same process (``bringup``) sees its latency rise while
one runs; run the identifier in its own process for a 1 kHz loop.
"""

from __future__ import annotations

import json
import time
from typing import Any

from std_msgs.msg import String

from hyst_id.errors import HystIdError
from hyst_id.identification.config import make_settings
from hyst_id.io.recording import validate_recording
from hyst_id.live.jobs import SlidingJob
from hyst_id.live.sliding import SwapRule
from hyst_id.nodes.support.params import Param
from hyst_id.nodes.support.qos import LATCHED_QOS

__all__ = ['SLIDING_PARAMS', 'SlidingLink']

SLIDING_PARAMS = [
    Param('sliding.enabled', False,
          'after the first identification, re-identify the newest samples on a sliding '
          'window and hand a new set over only when it is significantly better on the '
          'newest (held-out) samples'),
    Param('sliding.window_s', 60.0, 'newest seconds each re-identification uses (held-out '
          'part included)', low=1.0, high=1e6, unit='s'),
    Param('sliding.holdout_s', 10.0, 'newest seconds held out of the fit; the swap is '
          'decided on them', low=0.1, high=1e6, unit='s'),
    Param('sliding.period_s', 30.0, 'least time between the starts of two '
          're-identifications', low=0.1, high=1e6, unit='s'),
    Param('sliding.cpu_share', 0.25, 'largest average share of one core for '
          're-identification: after a fit of E s the next waits E (1/share - 1) s',
          low=0.01, high=1.0),
    Param('sliding.min_gain', 0.1, 'swap only when the held-out %e_r falls by at least this '
          'share', low=0.0, high=0.99),
    Param('sliding.max_p', 0.01, 'swap only when the block test of the held-out residuals '
          'gives at most this p-value', low=1e-12, high=0.5),
    Param('sliding.fresh_seeds', 1, 'GAASS seeds of a fresh identification tried beside the '
          'warm start (0 = warm start only)', low=0, high=1000),
    Param('sliding.fresh_generations', 100, 'GAASS generations of the fresh identification',
          low=1, high=10000000),
]


class SlidingLink:
    """Schedules sliding-window re-identifications of an identifier node and acts on them."""

    def __init__(self, node: Any) -> None:
        self.node = node
        self.job: SlidingJob | None = None
        self.last: dict | None = None
        self.decisions = 0
        self.swaps = 0
        self._last_start = -float('inf')
        self._next_allowed = -float('inf')
        self._pub = node.create_publisher(String, '~/sliding', LATCHED_QOS)

    @staticmethod
    def validate(values: dict[str, Any]) -> str | None:
        """Why the sliding settings cannot work, or None."""
        if values['sliding.holdout_s'] >= values['sliding.window_s']:
            return (f'sliding.holdout_s ({values["sliding.holdout_s"]:g} s) must be shorter '
                    f'than sliding.window_s ({values["sliding.window_s"]:g} s)')
        return None

    def _due(self, now: float) -> bool:
        p = self.node.p
        return (p('sliding.enabled') and self.job is None and self.node.job is None
                and self.node.handed_over is not None
                and now - self._last_start >= p('sliding.period_s')
                and now >= self._next_allowed)

    def tick(self) -> None:
        """Collect a finished job; start the next one when it is due (executor thread)."""
        now = time.monotonic()
        if self.job is not None and self.job.done:
            job, self.job = self.job, None
            self._next_allowed = now + job.elapsed_s * (1.0 / self.node.p('sliding.cpu_share')
                                                        - 1.0)
            self._finished(job)
        if not self._due(now):
            return
        node, p = self.node, self.node.p
        if node.buffer.span_s < p('sliding.window_s'):
            return
        self._last_start = now
        try:
            window = validate_recording(node.collected_recording(last_s=p('sliding.window_s')))
        except HystIdError as exc:
            node.get_logger().warning(f'sliding window not usable: {exc}')
            self._publish({'swap': False, 'reason': f'window not usable: {exc}'})
            return
        fresh = None
        if p('sliding.fresh_seeds') > 0:
            # no global phase nor hopping: a drifting window often ends above 1.1 x the
            # floor, and the phase's 200,000 evaluations would dwarf fresh_generations
            fresh = make_settings(
                seeds=p('sliding.fresh_seeds'), seed_offset=p('seed_offset'),
                pop_size=p('pop_size'), generations=p('sliding.fresh_generations'), c=p('c'),
                xi=p('xi'), workers=1, refine=True, restarts=0, er_bound_percent=None,
                global_evals=0, hops=0)
        rule = SwapRule(holdout_s=p('sliding.holdout_s'), min_gain=p('sliding.min_gain'),
                        max_p=p('sliding.max_p'))
        self.job = SlidingJob(node.handed_over, window, rule=rule,
                              gate=node.quality_gate(), fresh_settings=fresh)

    def _finished(self, job: SlidingJob) -> None:
        log = self.node.get_logger()
        if job.cancelled:
            return
        self.decisions += 1
        if job.error:
            log.error(f'sliding re-identification failed: {job.error}; the current set stays')
            self._publish({'swap': False, 'reason': f'failed: {job.error}'})
            return
        d = job.result
        doc = {**d.to_dict(), 'elapsed_s': job.elapsed_s}
        if d.swap and job.current is not self.node.handed_over:
            doc['swap'] = False
            doc['reason'] = ('superseded: another set was handed over while this window was '
                             f'fitted (its decision was: {d.reason})')
        elif d.swap and not self.node.p('sliding.enabled'):
            doc['swap'] = False
            doc['reason'] = f'sliding was disabled while this window was fitted ({d.reason})'
        if not doc['swap']:
            log.info(f'sliding re-identification kept the current set: {doc["reason"]}')
            self._publish(doc)
            return
        if not self.node.publish_identified(d.candidate, job.window, job.elapsed_s,
                                            sliding=doc):
            doc['swap'] = False
            doc['reason'] = f'not handed over (see the identifier log): {d.reason}'
            log.warning(f'sliding re-identification: {doc["reason"]}')
            self._publish(doc)
            return
        self.swaps += 1
        log.warning(f'sliding re-identification swapped the set: {d.reason}')
        self._publish(doc)

    def _publish(self, doc: dict) -> None:
        self.last = doc
        self._pub.publish(String(data=json.dumps(doc)))

    def status(self) -> dict[str, Any]:
        """Key values for ``/diagnostics``."""
        if not self.node.p('sliding.enabled'):
            return {'sliding': 'off'}
        out: dict[str, Any] = {'sliding': 'fitting' if self.job is not None else 'waiting',
                               'sliding_decisions': self.decisions,
                               'sliding_swaps': self.swaps}
        if self.last is not None:
            out['sliding_last'] = self.last.get('reason', '')
        return out

    def cancel(self, why: str) -> SlidingJob | None:
        """Cancel a running job; return it so the caller can wait for its thread."""
        job, self.job = self.job, None
        if job is not None:
            job.cancel()
            self.node.get_logger().info(f'sliding re-identification cancelled: {why}')
        return job
