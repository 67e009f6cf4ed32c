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

"""Replay node: plays a rosbag2 bag onto its topics at its original timing or ``rate`` x.

Messages are read with :func:`hyst_id.io.bag.iter_bag_messages`, serialised
again (CDR) and published in log-time order from a background thread, each
``(log_time - first_log_time) / rate`` after the start; header stamps are
left as recorded. With ``publish_clock`` (the default) the bag's log time of
each message is published on ``/clock`` (rosgraph_msgs/Clock) just before the
message, so that nodes started with ``use_sim_time:=true`` time unstamped
messages (Float64 commands, flow) in the bag's time at any ``rate``; without
it a subscriber timing them by arrival sees time ``rate`` times faster (a
pressure sensor's 1.4 s lag identified as 0.34 s at rate 4). The clock and
the message travel on two topics, so a subscriber may take a message before
its clock tick: its time is then the previous message's, at most one
sample period early. Publishers are reliable (depth 1000) so they match both
reliable and best-effort subscribers; the identified-parameters topic is
also transient local. A bag that cannot be read ends the process with a
one-line error and exit code 2.
"""

from __future__ import annotations

from pathlib import Path
import threading
import time
from typing import Any

from builtin_interfaces.msg import Time
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock

from hyst_id.errors import ConfigError, HystIdError, RecordingError
from hyst_id.io.bag import default_typestore, iter_bag_messages, open_bag
from hyst_id.nodes.support import (
    HystNode,
    IDENTIFIED_PARAMS_TOPIC,
    message_class,
    Param,
    spin_node,
)

__all__ = ['PARAMS', 'Replay', 'main']

PARAMS = [
    Param('bag', '', 'bag directory or .mcap file to play (required)', read_only=True),
    Param('rate', 1.0, 'playback speed factor (2 = twice as fast)', low=1e-3, high=1e4,
          read_only=True),
    Param('topics', ['*'], "topics to play; ['*'] = all", read_only=True),
    Param('start_delay_s', 0.5, 'wall-clock wait before the first message (discovery)',
          low=0.0, high=3600.0, unit='s', read_only=True),
    Param('wait_for_subscribers', 0, 'start only once the publishers have this many '
          'subscriptions in total', low=0, high=1000, read_only=True),
    Param('wait_timeout_s', 30.0, 'give up waiting for subscribers after this long (then '
          'play anyway)', low=0.0, high=3600.0, unit='s', read_only=True),
    Param('recover_truncated', False, 'play the complete chunks of a bag whose recorder was '
          'killed', read_only=True),
    Param('shutdown_when_done', True, 'exit the process when the bag is played',
          read_only=True),
    Param('publish_clock', True, "publish the bag's log time on /clock before each message "
          '(for nodes with use_sim_time)', read_only=True),
]


def _qos(topic: str, latched: bool = False) -> QoSProfile:
    latched = latched or ('/' + topic.lstrip('/')).endswith('/' + IDENTIFIED_PARAMS_TOPIC)
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1 if latched else 1000,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=(DurabilityPolicy.TRANSIENT_LOCAL if latched
                                  else DurabilityPolicy.VOLATILE))


class Replay(HystNode):
    """Publish the messages of a bag with their original spacing."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('replay', PARAMS, **kwargs)
        if not self.p('bag'):
            raise ConfigError('replay: set the bag parameter (-p bag:=PATH)')
        self.path = Path(self.p('bag')).expanduser()
        selected = [t for t in self.p('topics') if t]
        with open_bag(self.path, recover_truncated=self.p('recover_truncated'),
                      remedy='-p recover_truncated:=true') as bag:
            available = dict(bag.topics)
            counts = dict(bag.counts)
            latched = set(bag.latched)
            if selected and selected != ['*']:
                bag.check_topics(selected)
                available = {t: available[t] for t in selected}
        self._topics = available
        self._typestore = default_typestore()
        self._pubs = {}
        for topic, msgtype in available.items():
            try:
                cls = message_class(msgtype)
            except ConfigError as exc:
                self.get_logger().warning(f'skipping {topic}: {exc}')
                continue
            self._pubs[topic] = self.create_publisher(cls, topic, _qos(topic, topic in latched))
        if not self._pubs:
            raise RecordingError(f'{self.path}: no playable topics')
        if not any(counts.get(t, 0) for t in self._pubs):
            raise RecordingError(f'{self.path}: its topics hold no messages '
                                 f'({", ".join(sorted(self._pubs))}): nothing to replay')
        self._clock_pub = (self.create_publisher(Clock, '/clock', _qos('/clock'))
                           if self.p('publish_clock') else None)
        self.published = 0
        self.exit_code = 0
        self.done = threading.Event()
        self._stop = threading.Event()
        self.get_logger().info(
            f'playing {self.path} at rate {self.p("rate"):g}: ' + ', '.join(
                f'{t} ({counts.get(t, 0)})' for t in self._pubs))
        self._thread = threading.Thread(target=self._run, name='replay', daemon=True)
        self._thread.start()
        self.create_steady_timer(0.1, self._check_done)

    def _wait_for_subscribers(self) -> None:
        need = self.p('wait_for_subscribers')
        deadline = time.monotonic() + self.p('wait_timeout_s')
        while need and not self._stop.is_set():
            have = sum(p.get_subscription_count() for p in self._pubs.values())
            if have >= need:
                break
            if time.monotonic() > deadline:
                self.get_logger().warning(f'only {have} of {need} subscriptions after '
                                          f'{self.p("wait_timeout_s"):g} s; playing anyway')
                break
            self._stop.wait(0.05)
        self._stop.wait(self.p('start_delay_s'))
        alone = [t for t, pub in self._pubs.items() if pub.get_subscription_count() == 0]
        if alone and not self._stop.is_set():
            self.get_logger().warning(
                f'nothing subscribes to {", ".join(alone)} yet: what is played before a '
                'subscriber is matched is lost (wait_for_subscribers:=N waits for N)')

    def _run(self) -> None:
        try:
            self._wait_for_subscribers()
            rate = self.p('rate')
            t0_bag = None
            t0_wall = time.monotonic()
            for topic, msgtype, t_ns, msg in iter_bag_messages(
                    self.path, list(self._pubs), recover_truncated=self.p('recover_truncated')):
                if self._stop.is_set():
                    return
                if t0_bag is None:
                    t0_bag = t_ns
                    t0_wall = time.monotonic()
                delay = t0_wall + (t_ns - t0_bag) * 1e-9 / rate - time.monotonic()
                if delay > 0 and self._stop.wait(delay):
                    return
                if self._clock_pub is not None:
                    self._clock_pub.publish(Clock(clock=Time(sec=t_ns // 1_000_000_000,
                                                             nanosec=t_ns % 1_000_000_000)))
                data = self._typestore.serialize_cdr(msg, msgtype)
                self._pubs[topic].publish(bytes(data))
                self.published += 1
            self.get_logger().info(f'replay finished: {self.published} messages in '
                                   f'{time.monotonic() - t0_wall:.2f} s')
        except HystIdError as exc:
            played = (f' ({self.published} message(s) were played before it; the rest of the '
                      'bag was not)' if self.published else '')
            self.get_logger().error(f'{exc}{played}')
            self.exit_code = 2
        except Exception as exc:  # noqa: BLE001 - report in one line, never a traceback
            self.get_logger().error(f'replay failed: {type(exc).__name__}: {exc}')
            self.exit_code = 3
        finally:
            self.done.set()

    def _check_done(self) -> None:
        if self.done.is_set() and self.p('shutdown_when_done'):
            time.sleep(0.2)  # let the last messages leave before the context goes
            self.context.try_shutdown()

    def destroy_node(self) -> None:
        """Stop the playback thread, then the node."""
        if hasattr(self, '_stop'):    # also called on a node whose __init__ failed
            self._stop.set()
        if hasattr(self, '_thread') and self._thread.is_alive():
            self._thread.join(timeout=2.0)
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Play the bag; exit 0 when done, 2 on an unreadable bag."""
    return spin_node(Replay, 'replay', args)


if __name__ == '__main__':
    raise SystemExit(main())
