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

"""A recording whose actuator rests inside its play at the start (independent reviewer's case).

The data come from a play operator written apart from the package (``test/play_reference.py``):
``y = 2 play(u, 0.8) + 1`` with white noise of 0.01, the command resting at 0
(the output in the middle of the play) for 10 s, then a sine of varying
amplitude. Before the fix the whole record was fitted: on the reviewer's own
files of the same equations identify stopped at 34 x the noise floor (a 20 s
rest) and 6.8 x (no rest: the play taken up during the first rise only).
Measured on noise seeds 0-2 with this test's settings: the refit from the
first reversal reaches 0.975-0.995 x; the edge start, fitted whole, 0.978-0.998 x,
and is never refitted. The margin 1.2 x is the package's usual one over the floor.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from play_reference import mild_start, rest_then_sine
import pytest

from hyst_id.diagnosis import DiagnoseSettings
from hyst_id.diagnosis.baseline import identify_base
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.start_state import keep_refit, refit_start

SETTINGS = IdentifySettings(seeds=(0, 1, 2), workers=1)


def _recording(seed: int, rest_s: float, inside: bool):
    return rest_then_sine(seed, rest_s, inside, sine_s=30.0)


@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])  # 0 stays
def test_a_start_inside_the_play_is_left_out_and_the_rest_fits_to_the_floor(seed):
    said: list[str] = []

    def progress(done, total, run):
        pass

    progress.restart = said.append          # as the CLI's bar: it starts again, says why
    ident = identify(_recording(seed, 10.0, inside=True), settings=SETTINGS, progress=progress)
    assert said == ['probing from the first reversal', 'GAASS seeds, from the first reversal']
    assert ident.er_percent <= 1.2 * ident.noise_floor_percent, ident.warnings
    assert 'are left out of the fit' in ident.warnings[0], ident.warnings
    assert 'inside its play or loop' in ident.warnings[0]


def test_the_retry_is_off_where_the_whole_record_is_judged():
    """The paper's experiment and a diagnosis's baseline fit the whole record, as before."""
    ident = identify(_recording(0, 10.0, inside=True),
                     settings=replace(SETTINGS, start_state=False))
    assert ident.er_percent > 5 * ident.noise_floor_percent
    assert not any('left out of the fit' in w for w in ident.warnings), ident.warnings
    assert not identify_base(DiagnoseSettings())['start_state']


def test_a_start_on_the_edge_of_the_play_is_fitted_whole():
    ident = identify(_recording(0, 10.0, inside=False), settings=SETTINGS)
    assert ident.er_percent <= 1.2 * ident.noise_floor_percent
    assert not any('left out of the fit' in w for w in ident.warnings), ident.warnings


@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])  # 0 stays
def test_a_mild_start_inside_the_play_is_left_out_too(seed):
    """A fit a quarter above its floor is tried from the first reversal too.

    The whole record fits 1.21-1.25 x its floor with the lag 31-33 % long (noise seeds
    0-2, these settings; ``python bench/start_state.py --mild``): below the 1.5 x that used
    to trigger the retry, so the lag was reported wrong with no sign. From the first
    reversal: 0.979-0.997 x, the lag within 1.2 %.
    """
    fast = replace(SETTINGS, global_runs=0, hops=0)
    whole = identify(mild_start(seed), settings=replace(fast, start_state=False))
    assert whole.er_percent > 1.1 * whole.noise_floor_percent and whole.params['tau_s'] > 0.18
    ident = identify(mild_start(seed), settings=fast)
    assert 'are left out of the fit' in ident.warnings[0], ident.warnings
    assert ident.er_percent <= 1.1 * ident.noise_floor_percent
    assert ident.params['tau_s'] == pytest.approx(0.15, rel=0.05)


def test_only_a_poor_fit_of_a_record_that_reverses_after_a_stretch_is_tried_again():
    v = np.sin(np.linspace(0.0, 6 * np.pi, 600))        # first reversal at sample 50
    assert refit_start(v, 1.0, 0.5) == 50
    assert refit_start(v, 0.54, 0.5) is None            # within 1.1 x the floor
    assert refit_start(v, 0.6, 0.5) == 50               # 1.2 x: tried (the probe decides)
    assert keep_refit(1.24, 1.0) and keep_refit(3.0, 1.9)
    assert not keep_refit(1.15, 1.08) and not keep_refit(1.3, 1.15) and not keep_refit(2.0, 1.4)
    assert refit_start(v, 1.0, 0.0) is None             # no floor to judge by
    assert refit_start(v, 1.0, 1e-4) is None            # a noise-free record
    assert refit_start(np.sin(np.linspace(0.0, 2 * np.pi, 600)), 1.0, 0.5) is None
    late = np.concatenate([np.zeros(400), v[:400]])     # the reversal past half the record
    assert refit_start(late, 1.0, 0.5) is None
