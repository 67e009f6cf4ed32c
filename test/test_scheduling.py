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

"""The test suite's own scheduling: tests sharing a module fixture run on one worker."""

from __future__ import annotations

from pathlib import Path
import re
import subprocess
import sys

HERE = Path(__file__).resolve().parent


def test_tests_sharing_a_module_fixture_run_on_one_worker():
    """``./run test`` runs ``--dist loadgroup``; test/conftest.py groups fixture users.

    A module-scoped fixture is computed once per worker that runs one of
    its tests, so its users must reach one worker. If pytest and
    pytest-xdist stop agreeing on how a group is written into a test's id
    (they did with pytest 9.2), the groups are silently dropped: this
    catches that.
    """
    out = subprocess.run(
        [sys.executable, '-m', 'pytest', '-n', '2', '--dist', 'loadgroup', '-v',
         '-p', 'no:cacheprovider', str(HERE / 'diagnosis' / 'test_stick_events.py')],
        capture_output=True, text=True, timeout=600, cwd=HERE.parent)
    assert out.returncode == 0, out.stdout[-2000:]
    runs = re.findall(r'\[(gw\d)\].*?::(test_\w+)', out.stdout)
    users = {'test_plateaus_cut_exactly_at_the_slips_and_ignore_a_noise_spike',
             'test_true_band_and_initial_state_lie_in_the_allowed_intervals',
             'test_chain_and_band_are_recovered_from_a_perturbed_start'}
    assert {name for _, name in runs} >= users, out.stdout[-2000:]
    assert len({worker for worker, name in runs if name in users}) == 1, out.stdout[-2000:]
