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

"""Shared fixtures: recordings simulated from known parameters with fixed seeds."""

from __future__ import annotations

import contextlib

import itertools
import os
import time

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording

#: One BLAS thread per test process, and in the processes tests start. The suite runs on
#: two xdist workers on two cores; each OpenBLAS of two threads then spun against the
#: other worker (a test of the exchange step, its fits made outside the diagnosis's own
#: one-thread limit, took 50 s beside another worker and 8 s with one thread). The
#: package's parallel paths already run under ``threadpool_limits(limits=1)``.
for _name in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_name, '1')
threadpool_limits(limits=1)

#: The paper's induced hysteresis plus a unit-slope backlash of 0.3 mA width,
#: a 0.5 s pressure lag and a 0.6 / 0.5 rad/s flow sensor.
TRUE_PARAMS = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0,
                        1.0, -0.15, 0.15, 0.5, 0.6])
#: Affine sensor calibration per channel (output units per position unit, offset).
CALIBRATION = {'position': (1.0, 0.0), 'pressure': (50.0, 1000.0), 'flow': (4.0, 2.0)}

_domain_ids = itertools.count(0)


def simulate_channel(channel: str, *, noise_percent: float = 0.5, seed: int = 1,
                     duration_s: float = 100.0, dt_s: float = 0.05):
    """Simulate the Eq. 24 run of a channel; return (recording, noise-free output)."""
    spec = chain_spec(channel)
    t = np.arange(0.0, duration_s, dt_s)
    v = 9.0 + 2.0 * np.exp(-0.01 * t) * np.sin(2 * np.pi * t / 10.0)
    y0 = spec.simulate(TRUE_PARAMS[:spec.n_params], t, v, CALIBRATION[channel])
    sigma = noise_percent / 100.0 * np.sqrt(np.mean(y0 ** 2))
    y = y0 + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    rec = Recording(t, v, y, channel, 'mA', '', f'simulated {channel}')
    return rec, y0


@pytest.fixture(scope='session')
def simulated():
    """Factory of simulated recordings, cached per channel."""
    cache = {}

    def get(channel: str):
        if channel not in cache:
            cache[channel] = simulate_channel(channel)
        return cache[channel]

    return get


@pytest.fixture(autouse=True)
def _no_kept_searches():
    """Every test starts without the family swaps' kept searches of earlier tests."""
    from hyst_id.diagnosis.baseline import forget_quick

    forget_quick()
    yield


@pytest.fixture
def ros_domain(monkeypatch):
    """A ROS domain id of its own for this test, localhost discovery only.

    Distinct per test and per pytest-xdist worker (workers of one run share
    their parent's pid, so runs started side by side also differ).
    """
    worker = int(os.environ.get('PYTEST_XDIST_WORKER', 'gw0')[2:] or 0)
    workers = int(os.environ.get('PYTEST_XDIST_WORKER_COUNT', '1'))
    base = (os.getppid() if workers > 1 else os.getpid()) % 20
    domain = str(1 + ((base + next(_domain_ids)) * workers + worker) % 230)
    monkeypatch.setenv('ROS_DOMAIN_ID', domain)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return int(domain)


@pytest.fixture
def ctx(ros_domain, tmp_path, monkeypatch):
    """A fresh rclpy context (own domain) and a list of nodes destroyed at teardown.

    ROS_HOME points into the test's tmp dir. Skipped where rclpy is missing.
    """
    rclpy = pytest.importorskip('rclpy')
    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    context = rclpy.Context()
    rclpy.init(context=context)
    nodes: list = []
    yield context, nodes
    for node in nodes:
        node.destroy_node()
    context.try_shutdown()


def make_node(ctx, cls, *args, **kwargs):
    """Build a node in the test's context and register it for teardown."""
    context, nodes = ctx
    node = cls(*args, context=context, **kwargs)
    nodes.append(node)
    return node


def spin_nodes_until(context, nodes, predicate, timeout=10.0) -> bool:
    """Spin ``nodes`` until ``predicate()`` holds or ``timeout`` s pass; return it."""
    from rclpy.executors import SingleThreadedExecutor

    ex = SingleThreadedExecutor(context=context)
    for n in nodes:
        ex.add_node(n)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            if predicate():
                return True
            ex.spin_once(timeout_sec=0.02)
        return predicate()
    finally:
        for n in nodes:
            ex.remove_node(n)
        ex.shutdown()


@contextlib.contextmanager
def other_participant(name: str = 'io'):
    """A node in a context of its own: another DDS participant, as another process would be.

    One participant cannot hold two types on one topic; a publisher of a wrong
    type has to come from elsewhere.
    """
    import rclpy
    from rclpy.node import Node

    other = rclpy.Context()
    rclpy.init(context=other)
    node = Node(name, context=other)
    try:
        yield node
    finally:
        node.destroy_node()
        other.try_shutdown()


def _module_fixture_user(item: pytest.Item) -> bool:
    """Whether a test uses a module-scoped fixture (computed once per module and worker)."""
    info = getattr(item, '_fixtureinfo', None)
    if info is None:
        return False
    return any(defs and defs[-1].scope == 'module'
               for name, defs in info.name2fixturedefs.items() if name in item.fixturenames)


def pytest_addoption(parser):
    """``--thorough``: also run the tests marked ``thorough`` (``./run test-all``)."""
    parser.addoption('--thorough', action='store_true', default=False,
                     help='also run the thorough tier: further seeds, stress counts and '
                          'second cases of checks that run once without it (./run test-all; '
                          'HYST_ID_THOROUGH=1 does the same)')


def thorough_requested(config) -> bool:
    """Whether this run includes the thorough tier."""
    return bool(config.getoption('--thorough')
                or os.environ.get('HYST_ID_THOROUGH', '') not in ('', '0'))


#: Why a thorough test is skipped by ``./run test`` (what CI runs).
THOROUGH_SKIP = ('thorough tier (further seeds, a stress count or a second case of a check '
                 'that runs here once): ./run test-all runs it')


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Group the tests for two workers (``./run test``: ``--dist loadgroup``).

    The tests of a module that share a module-scoped fixture go to one
    worker together (an ``xdist_group``), so the fixture is computed once,
    not once per worker. The order is left as collected. Tests marked
    ``thorough`` are skipped, with the reason shown, unless the run asks
    for them (``--thorough``).
    """
    skip = None if thorough_requested(config) else pytest.mark.skip(reason=THOROUGH_SKIP)
    for item in items:
        if _module_fixture_user(item) and item.get_closest_marker('xdist_group') is None:
            item.add_marker(pytest.mark.xdist_group(name=item.nodeid.split('::')[0]))
        if skip is not None and item.get_closest_marker('thorough') is not None:
            item.add_marker(skip)
