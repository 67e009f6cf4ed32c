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

"""The baseline fit: the paper's chain of a channel on the training part.

GAASS with a few seeds (refined by least squares, :func:`hyst_id.identification.identify`)
finds a basin; a handful of starts built from the data themselves
(:func:`structured_starts`: the loop width measured where the output
crosses its median, split between H and the backlash) are polished too,
because on some records every GAASS seed ends in the same wrong basin (a
backlash dead band standing in for the hysteron's flat inner lines). The
best of them all is the baseline; the data-built starts also seed the
mechanism fits, so that a chain distorted by a missing mechanism does not
trap them.
"""

from __future__ import annotations

import numpy as np

from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.starts import data_starts, SPLITS
from hyst_id.io.recording import Recording

__all__ = ['baseline_starts', 'structured_starts']


def structured_starts(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
                      sensor: np.ndarray, splits: tuple = SPLITS) -> list[np.ndarray]:
    """Chain starts built from the data (:func:`hyst_id.identification.starts.data_starts`).

    One loop per split (unit mean side slopes), the given sensor parameters.
    """
    return data_starts(spec, t_s, v, y, sensors=[np.asarray(sensor, dtype=float)],
                       splits=splits, per_split=1)


def baseline_starts(rec_train: Recording, spec: ChainSpec, settings
                    ) -> tuple[np.ndarray, list[np.ndarray]]:
    """GAASS result (few seeds, refined) and the data-built starts.

    The chain's conventions stay the spec's (``conventions='given'``): the
    diagnosis's composed model starts on the rising boundary and holds the
    sensor input before its sample, and its baseline must be fitted in them.
    Without identify's global phase (``global_evals=0``): it runs when a fit
    stays above 1.1 x the noise floor, which a record with missing physics
    always does, and it cost a quarter of a diagnosis without changing its
    verdicts (stick-slip records, seeds 5 and 6: the same findings and
    held-out errors).
    """
    ident_settings = IdentifySettings(pop_size=settings.pop_size, maxiter=settings.generations,
                                      seeds=tuple(settings.seeds), workers=settings.workers,
                                      refine=True, refine_top=2, restarts=1,
                                      refine_max_nfev=1500, conventions='given',
                                      global_evals=0)
    ident = identify(rec_train, spec=spec, settings=ident_settings)
    x_ga = np.array(min(ident.runs, key=lambda r: r.fun).x_raw, dtype=float)
    return x_ga, structured_starts(spec, rec_train.t_s, rec_train.command,
                                   rec_train.measurement, x_ga[spec.sensor_slice])
