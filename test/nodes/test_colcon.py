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

"""colcon builds the package; executables resolve and start the way ``ros2 run`` does."""

from __future__ import annotations

import os
from pathlib import Path
import shutil
import signal
import subprocess
import sys
import time

import pytest

ROOT = Path(__file__).resolve().parents[2]
NODES = ('actuator_driver', 'pipeline_sim', 'excitation', 'identifier', 'compensator',
         'lifecycle_compensator', 'recorder', 'replay', 'bringup')
#: Executables that read another node's params file (same node, managed).
SHARED_PARAMS = {'lifecycle_compensator': 'compensator'}

pytestmark = pytest.mark.ros


def _colcon() -> str:
    exe = shutil.which('colcon') or str(Path(sys.executable).parent / 'colcon')
    if not Path(exe).exists():
        pytest.skip('colcon is not installed')
    return exe


def _ros2_run(prefixes: list[str], package: str, executable: str) -> Path:
    """Find ``lib/<package>/<executable>`` in the first AMENT_PREFIX_PATH prefix that has it.

    ``ros2 run`` looks the package up in the ament index
    (``share/ament_index/resource_index/packages/<package>``) and runs the
    executable from that prefix's ``lib/<package>``.
    """
    for prefix in prefixes:
        marker = Path(prefix) / 'share' / 'ament_index' / 'resource_index' / 'packages' / package
        if marker.exists():
            exe = Path(prefix) / 'lib' / package / executable
            if exe.exists() and os.access(exe, os.X_OK):
                return exe
            raise AssertionError(f'{package} is indexed in {prefix} but has no {executable}')
    raise AssertionError(f'package {package} not found in {prefixes}')


def _interrupt_once_started(proc: subprocess.Popen) -> tuple[str, str]:
    """Read the compensator's log until it says it is compensating, then Ctrl-C it.

    Returns what it printed before and after the interrupt.
    """
    deadline = time.monotonic() + 30.0
    seen = ''
    while time.monotonic() < deadline and 'compensating' not in seen:
        line = proc.stdout.readline()
        if not line and proc.poll() is not None:
            break
        seen += line
    assert 'compensating /hyst_id/desired -> /hyst_id/command' in seen, seen
    proc.send_signal(signal.SIGINT)
    rest, _ = proc.communicate(timeout=15)
    return seen, rest


@pytest.fixture(scope='module')
def install(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('colcon')
    env = os.environ.copy()
    for var in ('AMENT_PREFIX_PATH', 'CMAKE_PREFIX_PATH'):   # the wheels' CMake packages
        env[var] = os.pathsep.join([sys.prefix] + [p for p in env.get(var, '').split(
            os.pathsep) if p])
    out = subprocess.run(
        [_colcon(), '--log-base', str(tmp / 'log'), 'build', '--base-paths', str(ROOT),
         str(ROOT / 'interfaces'), '--build-base', str(tmp / 'build'),
         '--install-base', str(tmp / 'install')],
        cwd=tmp, capture_output=True, text=True, timeout=600, env=env)
    assert out.returncode == 0, out.stdout + out.stderr
    return tmp / 'install'


def test_colcon_installs_every_executable_and_the_params(install):
    prefix = install / 'hyst_id'      # colcon's default isolated layout
    for node in NODES:
        _ros2_run([str(prefix)], 'hyst_id', node)
    params = sorted(p.name for p in (prefix / 'share' / 'hyst_id' / 'params').glob('*.yaml'))
    assert {f'{SHARED_PARAMS.get(n, n)}.yaml' for n in NODES} <= set(params)


def test_installed_compensator_starts_and_exits_0_on_sigint(install, ros_domain):
    prefix = install / 'hyst_id'
    env = os.environ.copy()
    env['AMENT_PREFIX_PATH'] = os.pathsep.join(
        [str(prefix)] + [p for p in env.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p])
    site = prefix / 'lib' / f'python{sys.version_info[0]}.{sys.version_info[1]}' / \
        'site-packages'
    env['PYTHONPATH'] = os.pathsep.join([str(site)] + [p for p in env.get(
        'PYTHONPATH', '').split(os.pathsep) if p])
    exe = _ros2_run(env['AMENT_PREFIX_PATH'].split(os.pathsep), 'hyst_id', 'compensator')
    params = prefix / 'share' / 'hyst_id' / 'params' / 'compensator.yaml'
    proc = subprocess.Popen([str(exe), '--ros-args', '--params-file', str(params)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        seen, rest = _interrupt_once_started(proc)
        assert proc.returncode == 130, seen + rest   # Ctrl-C
        assert 'Traceback' not in seen + rest
        # the module came from the install space, not the source tree
        probe = subprocess.run([sys.executable, '-c', 'import hyst_id.nodes.compensator as m;'
                                'print(m.__file__)'], env=env, capture_output=True, text=True,
                               cwd=install)
        assert str(site) in probe.stdout, probe.stdout + probe.stderr
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_installed_interfaces_carry_stamped_streams(install, ros_domain):
    """The interfaces package colcon built here (not the one ./run built) serves the nodes."""
    own = install / 'hyst_id_interfaces'
    pyver = f'python{sys.version_info[0]}.{sys.version_info[1]}'
    env = os.environ.copy()

    def paths(var, first):
        rest = [p for p in env.get(var, '').split(os.pathsep)
                if p and 'hyst_id_interfaces' not in p]
        env[var] = os.pathsep.join([str(x) for x in first] + rest)

    paths('AMENT_PREFIX_PATH', [own, install / 'hyst_id'])
    paths('PYTHONPATH', [own / 'lib' / pyver / 'site-packages',
                         install / 'hyst_id' / 'lib' / pyver / 'site-packages'])
    paths('LD_LIBRARY_PATH', [own / 'lib'])
    probe = subprocess.run(
        [sys.executable, '-c', 'import hyst_id_interfaces.msg as m; print(m.__file__); '
         'print(m.StampedValue(value=2.5).value, m.IdentifiedParams(names=["a"]).names)'],
        env=env, capture_output=True, text=True, cwd=install, timeout=60)
    assert probe.returncode == 0, probe.stderr
    assert str(own) in probe.stdout and "2.5 ['a']" in probe.stdout, probe.stdout
    exe = _ros2_run(env['AMENT_PREFIX_PATH'].split(os.pathsep), 'hyst_id', 'compensator')
    share = install / 'hyst_id' / 'share' / 'hyst_id' / 'params'
    proc = subprocess.Popen([str(exe), '--ros-args', '--params-file',
                             str(share / 'compensator.yaml'), '--params-file',
                             str(share / 'stamped.yaml')], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        seen, rest = _interrupt_once_started(proc)
        assert proc.returncode == 130, seen + rest
        assert 'desired hyst_id_interfaces/msg/StampedValue; command hyst_id_interfaces/msg/' \
            'StampedValue' in seen, seen
        assert 'Traceback' not in seen + rest and 'unknown' not in seen + rest, seen + rest
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
