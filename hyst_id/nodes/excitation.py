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

"""Excitation node: publishes a command profile of :mod:`hyst_id.signals.excitation`.

Profiles: Eq. 24 and Eq. 25 of the paper (any sine, through their
parameters), multisine, chirp, steps.

Sample ``k`` carries the profile's value at profile time ``t = k *
sample_period_s`` (so values never depend on timer jitter) and is published
``sample_period_s / time_scale`` wall-clock seconds after sample ``k - 1``;
``time_scale`` > 1 runs the paper's experiment faster than real time.
A program that embeds the node can hold the run in lockstep with its
consumers through :attr:`Excitation.ready` (``ready(k)`` False keeps
sample ``k`` for a later tick): the bringup waits until sample ``k - 1``
was answered, so a slow or busy machine only takes longer.
The run starts when ``wait_for_subscribers`` subscribers are matched (then
``start_delay_s`` later) and ends after ``duration_s`` of profile time; with
``shutdown_when_done`` the process then exits 0.

``min_command``/``max_command`` bound what the node may publish, in the
output's units (mA on the command topic): a profile that leaves them over
the run's samples is refused when set (the parameter change, or the node's
start, fails with the first sample outside), and each published value is
clipped to them as a last guard (counted, a ``/diagnostics`` WARN).
"""

from __future__ import annotations

import inspect
import math
from typing import Any, Callable

import numpy as np

from hyst_id.errors import ConfigError
from hyst_id.nodes.support import (
    COMMAND_QOS,
    HystNode,
    OVERRIDABLE,
    Param,
    resolved,
    scalar_type_param,
    ScalarStream,
    spin_node,
    topic_params,
    try_publish,
)
from hyst_id.signals.excitation import (
    DEFAULT_MULTISINE_HZ,
    DEFAULT_STEP_LEVELS_MA,
    EXCITATIONS,
    make_excitation,
)

__all__ = ['CHECK_SAMPLES', 'Excitation', 'outside_limits', 'PARAMS', 'main', 'profile_kwargs']

_NAN = math.nan
#: Node parameter -> keyword of the profile functions in hyst_id.signals.excitation.
_KWARGS = ('offset_ma', 'amplitude_ma', 'period_s', 'decay_per_s', 'frequencies_hz', 'f0_hz',
           'f1_hz', 'sweep_s', 'levels_ma', 'hold_s')
_PROFILE_KEYS = ('profile',) + _KWARGS
#: Parameters the profile's check against the command limits reads.
_CHECKED_KEYS = _PROFILE_KEYS + ('min_command', 'max_command', 'duration_s', 'sample_period_s')
#: The check evaluates at most this many of the run's samples (evenly spread over it; the
#: clip at publication guards the others).
CHECK_SAMPLES = 1_000_000

PARAMS = [
    Param('profile', 'eq24', 'command profile (hyst_id.signals.excitation)',
          choices=tuple(EXCITATIONS)),
    Param('offset_ma', _NAN, "offset (eq24, eq25, multisine, chirp); .nan = the profile's "
          'default (9 mA)', unit='mA'),
    Param('amplitude_ma', _NAN, "amplitude; .nan = the profile's default (eq24 2, eq25 1, "
          'multisine/chirp 1.5 mA)', unit='mA'),
    Param('period_s', _NAN, "sine period (eq24 10 s, eq25 12 s); .nan = the profile's "
          'default', unit='s'),
    Param('decay_per_s', _NAN, 'decay rate of eq24 (.nan = 0.01)', unit='1/s'),
    Param('frequencies_hz', list(DEFAULT_MULTISINE_HZ), 'multisine frequencies', unit='Hz'),
    Param('f0_hz', 0.02, 'chirp start frequency', low=1e-9, high=1e4, unit='Hz'),
    Param('f1_hz', 0.25, 'chirp end frequency', low=1e-9, high=1e4, unit='Hz'),
    Param('sweep_s', 100.0, 'chirp sweep length (repeated)', low=1e-6, high=1e7, unit='s'),
    Param('levels_ma', list(DEFAULT_STEP_LEVELS_MA), 'step levels, cycled', unit='mA'),
    Param('hold_s', 5.0, 'hold time of each step', low=1e-6, high=1e6, unit='s'),
    Param('duration_s', 120.0, 'length of the run in profile time', low=0.0, high=1e7,
          unit='s'),
    Param('sample_period_s', 0.1, 'profile time between samples', low=1e-4, high=1e4,
          unit='s'),
    Param('min_command', -1e6, 'lowest value published (a profile below it is refused); '
          'units of the output (mA on the command topic)', low=-1e6, high=1e6),
    Param('max_command', 1e6, 'highest value published (a profile above it is refused); '
          'units of the output (mA on the command topic)', low=-1e6, high=1e6),
    Param('time_scale', 1.0, 'profile seconds per wall-clock second', low=1e-3, high=1e4),
    Param('autostart', True, 'start by itself (else on request_start())', read_only=True),
    Param('wait_for_subscribers', 0, 'start only once this many subscribers are matched',
          low=0, high=1000),
    Param('start_delay_s', 0.0, 'wall-clock delay after the subscribers are matched',
          low=0.0, high=3600.0, unit='s'),
    Param('shutdown_when_done', False, 'exit the process when the run ends', read_only=True),
    Param('topics.output_topic', topic_params(('command_topic',))[0].default,
          'topic the profile is published on (the command, or the desired value in front '
          'of a compensator)', read_only=True),
    scalar_type_param('topics.output_type', 'profile (the command or desired stream)'),
]


def profile_kwargs(values: dict[str, Any]) -> dict[str, Any]:
    """Keyword arguments of the chosen profile function from node parameter values.

    Parameters the function does not take are left out, and so are ``.nan``
    scalars (the function's own default applies).
    """
    fun = EXCITATIONS.get(values['profile'])
    if fun is None:
        raise ConfigError(f'unknown profile {values["profile"]!r}')
    accepted = inspect.signature(fun).parameters
    out: dict[str, Any] = {}
    for key in _KWARGS:
        if key not in accepted:
            continue
        value = values[key]
        if isinstance(value, float) and math.isnan(value):
            continue
        out[key] = list(value) if isinstance(value, (list, tuple)) else value
    return out


def _make_profile(values: dict[str, Any]) -> Callable[[float], float]:
    name, kwargs = values['profile'], profile_kwargs(values)
    probe = np.asarray(make_excitation(name, np.array([0.0, 1.0]), **kwargs), dtype=float)
    if not np.all(np.isfinite(probe)):
        raise ConfigError(f'profile {name} gives non-finite values with {kwargs}')
    return lambda t_s: float(make_excitation(name, t_s, **kwargs))


def outside_limits(values: dict[str, Any]) -> str:
    """Words for the first run sample of the profile outside the command limits ('' if none).

    The run's sample times ``k * sample_period_s`` up to ``duration_s`` are
    evaluated (at most :data:`CHECK_SAMPLES` of them, evenly spread).
    """
    lo, hi = values['min_command'], values['max_command']
    if not lo < hi:
        return f'min_command ({lo:g}) must be below max_command ({hi:g})'
    n = int(math.floor(values['duration_s'] / values['sample_period_s'] + 1e-9)) + 1
    k = np.unique(np.linspace(0, n - 1, min(n, CHECK_SAMPLES)).round().astype(np.int64))
    t_s = k * values['sample_period_s']
    u = np.asarray(make_excitation(values['profile'], t_s, **profile_kwargs(values)),
                   dtype=float)
    bad = np.flatnonzero(~((u >= lo) & (u <= hi)))
    if bad.size == 0:
        return ''
    i = int(bad[0])
    return (f'profile {values["profile"]} leaves the command limits [{lo:g}, {hi:g}]: '
            f'{u[i]:.6g} at t = {t_s[i]:.6g} s (range over the run {np.nanmin(u):.6g} to '
            f'{np.nanmax(u):.6g}); change the profile or the limits')


class Excitation(HystNode):
    """Publish a command profile sample by sample."""

    def __init__(self, node_name: str = 'excitation', **kwargs: Any) -> None:
        super().__init__(node_name, PARAMS, **kwargs)
        self._out = ScalarStream(self.p('topics.output_type'))
        self._pub = self.create_publisher(self._out.cls, self.p('topics.output_topic'),
                                          COMMAND_QOS, qos_overriding_options=OVERRIDABLE)
        values = self.param_values()
        self._profile = _make_profile(values)
        problem = outside_limits(values)
        if problem:
            raise ConfigError(problem)
        self._clipped = 0
        #: the last value published (held where the profile gives a non-finite one)
        self._last_sent = min(max(0.0, self.p('min_command')), self.p('max_command'))
        self._timer = None
        self._k = 0
        self._n_samples = 0
        self._state = 'idle'
        self._wait_since: float | None = None
        self._start_requested = bool(self.p('autostart'))
        self.on_finished: Callable[[], None] | None = None
        #: ``ready(k)`` -> bool, asked before sample ``k`` goes out; False holds it.
        self.ready: Callable[[int], bool] | None = None
        self.create_steady_timer(1.0, self._status)
        self.create_steady_timer(0.02, self._wait_and_start)

    # ---------------------------------------------------------------- params
    def validate_params(self, values: dict[str, Any], changed: set[str]) -> str | None:
        if changed & set(_CHECKED_KEYS):
            try:
                _make_profile(values)
                return outside_limits(values) or None
            except ConfigError as exc:
                return str(exc)
        return None

    def apply_params(self, values: dict[str, Any], changed: set[str]) -> None:
        if changed & set(_PROFILE_KEYS) and hasattr(self, '_profile'):
            self._profile = _make_profile(values)
            if self._state == 'running':
                self.get_logger().info('profile changed: applies from the next sample')

    # ------------------------------------------------------------------ run
    @property
    def state(self) -> str:
        """``idle``, ``waiting``, ``running`` or ``finished``."""
        return self._state

    @property
    def finished(self) -> bool:
        """True once the run has ended."""
        return self._state == 'finished'

    def request_start(self) -> None:
        """Start a run from the node's own executor thread (thread-safe)."""
        self._start_requested = True

    def _wait_and_start(self) -> None:
        if not self._start_requested:
            return
        need = self.p('wait_for_subscribers')
        have = self._pub.get_subscription_count()
        now = self.get_clock().now().nanoseconds * 1e-9
        if have < need:
            if self._state != 'waiting':
                topic = resolved(self, self.p('topics.output_topic'))
                self.get_logger().info(f'waiting for {need} subscriber(s) on {topic} '
                                       f'(have {have})')
                self._state = 'waiting'
            self._wait_since = None
            return
        self._state = 'waiting'
        if self._wait_since is None:
            self._wait_since = now
        if now - self._wait_since >= self.p('start_delay_s'):
            self._start_requested = False
            self.start()

    def start(self) -> None:
        """Start (or restart) the run from profile time 0."""
        if self._timer is not None:
            self._timer.cancel()
            self.destroy_timer(self._timer)
        self._k = 0
        self._wait_since = None
        self._n_samples = int(math.floor(self.p('duration_s') / self.p('sample_period_s')
                                         + 1e-9)) + 1
        self._state = 'running'
        period = self.p('sample_period_s') / self.p('time_scale')
        self.get_logger().info(
            f'{self.p("profile")} on {resolved(self, self.p("topics.output_topic"))}: '
            f'{self._n_samples} '
            f'samples every {self.p("sample_period_s"):g} s of profile time '
            f'({period * 1e3:.3g} ms wall clock, time_scale {self.p("time_scale"):g})')
        self._tick()
        if self._state == 'running':
            self._timer = self.create_timer(period, self._tick)

    def stop(self) -> None:
        """End the run now."""
        if self._timer is not None:
            self._timer.cancel()
        if self._state == 'running':
            self._finish()

    def _tick(self) -> None:
        if self._state != 'running':
            return
        if self._k >= self._n_samples:
            self._timer.cancel()
            self._finish()
            return
        if self.ready is not None and not self.ready(self._k):
            return
        t_s = self._k * self.p('sample_period_s')
        value = self._profile(t_s)
        lo, hi = self.p('min_command'), self.p('max_command')
        if not lo <= value <= hi:     # between the checked samples of a very long run
            self._clipped += 1
            self.get_logger().warning(f'profile value {value:.6g} at t = {t_s:.6g} s clipped '
                                      f'to [{lo:g}, {hi:g}] ({self._clipped} so far)',
                                      throttle_duration_sec=1.0)
            value = min(max(value, lo), hi) if math.isfinite(value) else self._last_sent
        sample = self._out.make(value, self.get_clock().now().to_msg()
                                if self._out.stamped else None)
        if not try_publish(self._pub, sample):
            self.get_logger().warning(f'sample {self._k} refused by the middleware (a '
                                      'subscriber stalled?): retrying it on the next tick',
                                      throttle_duration_sec=1.0)
            return
        self._last_sent = value
        self._k += 1

    def _finish(self) -> None:
        self._state = 'finished'
        self.get_logger().info(f'run finished: {self._k} samples published')
        if self.on_finished is not None:
            self.on_finished()
        if self.p('shutdown_when_done'):
            self.context.try_shutdown()

    def _status(self) -> None:
        t = self._k * self.p('sample_period_s')
        clipped = (f'; {self._clipped} value(s) clipped to [{self.p("min_command"):g}, '
                   f'{self.p("max_command"):g}]') if self._clipped else ''
        self.publish_diagnostics(1 if self._clipped else 0,
                                 f'{self._state}: {self.p("profile")} t={t:.1f} s{clipped}',
                                 {'samples': self._k, 'profile': self.p('profile'),
                                  'clipped': self._clipped})


def main(args: list[str] | None = None) -> int:
    """Run the excitation node until the run ends (with shutdown_when_done) or Ctrl-C."""
    return spin_node(Excitation, 'excitation', args)


if __name__ == '__main__':
    raise SystemExit(main())
