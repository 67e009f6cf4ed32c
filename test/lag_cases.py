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

"""Recordings for the exchange step (``hyst_id/diagnosis/exchange.py``), made apart from it.

:func:`forced`: the reference chain (``reference_sim``) with a static curve and a
lag, the final model built round by round with a chosen lag block forced in.
:func:`mirror_of_24`: blind #24 of ``bench/blind_family.py`` with a dead time in
place of its sensor lag. Used by ``test/diagnosis/test_exchange.py`` and
``bench/exchange_trial.py``.
"""

from __future__ import annotations

from pathlib import Path
import sys
from typing import Callable

import numpy as np
from reference_sim import first_order_sensor, simulate as reference_simulate

from hyst_id.diagnosis import DiagnoseSettings
from hyst_id.diagnosis.exchange import LAGS
from hyst_id.diagnosis.locate import locate
from hyst_id.diagnosis.mechanisms import Context, get_mechanisms
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import Data, evaluate, FitResult
from hyst_id.diagnosis.trial import try_all
from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording
from hyst_id.signals.excitation import multisine
from hyst_id.signals.split import inside_rows

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'bench'))
import blind_family  # noqa: E402, I100

__all__ = ['NAMES', 'TRUTH', 'at_truth', 'forced', 'mirror_of_24']

NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl', 'c_br')
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])


def forced(lag: str, chosen: str, seed: int = 3) -> dict:
    """A static curve and ``lag`` (0.3 s) on the reference chain; ``chosen`` forced in.

    Round 1 takes the curve, round 2 is made to take ``chosen`` whatever the data say.
    Returns what :func:`exchanges` needs: the final model, the found ids, the rounds.
    """
    t = np.arange(0.0, 120.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    vv = np.concatenate([np.full(6, v[0]), v[:-6]]) if lag == 'dead_time' else v
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, vv)
    span = float(np.ptp(x))
    x = x + 0.15 * span * ((x - float(np.min(x))) / span) ** 2
    y = first_order_sensor(t, x, 0.3) if lag == 'sensor_lag' else x
    data, ctx, settings, relocate, chain = at_truth(t, v, y, 0.004 * span, seed)
    curve = try_all(get_mechanisms(('static_nonlinearity',), channel='position'), chain,
                    data, ctx, settings, relocate(chain), [])[0]
    mechs = get_mechanisms(tuple(LAGS), channel='position')
    second = try_all(mechs, curve.fit, data, ctx, settings, relocate(curve.fit), [])
    final = next(c for c in second if c.mechanism == chosen).fit
    return {'current': final, 'found': ['static_nonlinearity', chosen],
            'rounds': {chosen: second}, 'mechs': mechs, 'data': data, 'ctx': ctx,
            'settings': settings, 'chain_starts': [], 'relocate': relocate}


def at_truth(t: np.ndarray, v: np.ndarray, y: np.ndarray, sigma: float, seed: int
             ) -> tuple[Data, Context, DiagnoseSettings, Callable, FitResult]:
    """``y`` with noise ``sigma`` (``seed``), split 70/30; the reference chain at its truth.

    Returns the data, the context, small-budget settings, the residual's
    localization for a fit, and the chain evaluated at :data:`TRUTH`.
    """
    y = y + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    n = int(0.7 * t.size)
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma, judged=inside_rows(v, n))
    settings = DiagnoseSettings(fit_budget=300, workers=1)

    def relocate(fit):
        return locate(t, v, y, fit.prediction, sigma, n, None)
    chain = evaluate(ComposedModel('position', [], ctx, chain_spec('position').bounds), data,
                     TRUTH)
    return data, ctx, settings, relocate, chain


def mirror_of_24(delay_samples: int = 2) -> Recording:
    """Blind #24's draw with a dead time in place of its sensor lag (curve and noise kept)."""
    case = blind_family.draw(24)
    t, v = case['t'], case['reference_command']
    delayed = np.concatenate([np.full(delay_samples, v[0]), v[:-delay_samples]])
    x = reference_simulate('position', case['chain_params'], t, delayed)
    span = float(np.ptp(x))
    z = (x - float(np.min(x))) / span
    x = x + case['magnitudes']['static_nonlinearity'] * span * z ** 2
    sigma = 0.01 * case['noise_percent_of_span'] * float(np.ptp(x))
    y = x + np.random.default_rng(2024).normal(0.0, sigma, x.size)
    return Recording(t, case['command'], y, 'position', source='blind #24, delay for lag')
