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

"""The joint search's figures (``hyst_id/diagnosis/joint.py``) on a blind-family recording.

The recording is diagnosed without the joint search; its final model, less
the blocks given by ``--without`` (each taken out, the rest polished), is
the start; the search is then run from it in several random streams and
generation counts. Printed: the start's and each search's %e_r over the
training and held-out noise floors, and the searched blocks' values. Run from
the repository root (about two minutes for the default, blind #175 less its
``gain_drift``)::

    python bench/joint_search.py [--index 175] [--without gain_drift]
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from blind_family import draw  # noqa: E402, I100

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.diagnosis.control import without  # noqa: E402
from hyst_id.diagnosis.joint import joint_search  # noqa: E402
from hyst_id.diagnosis.locate import noise_std  # noqa: E402
from hyst_id.diagnosis.select import Data  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.signals.noise import floor_percent  # noqa: E402
from hyst_id.signals.split import inside_rows, split_index  # noqa: E402


def main() -> None:
    """Print the start and each search."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--index', type=int, default=175)
    ap.add_argument('--without', nargs='*', default=['gain_drift'])
    ap.add_argument('--runs', nargs='*', default=['0:200', '0:300', '1:300', '2:300', '3:300'],
                    help='SEED:GENERATIONS of each search')
    args = ap.parse_args()
    d = draw(args.index)
    rec = Recording(d['t'], d['command'], d['measurement'], d['channel'],
                    source=f'blind #{args.index}')
    # no start cut, so that the model's record is the whole recording
    settings = replace(DiagnoseSettings(workers=1), joint_generations=0, start_state=False)
    print(f'blind #{args.index}: {d["channel"]}, {d["excitation"]}, effects {d["effects"]}; '
          'diagnosing without the joint search ...', flush=True)
    got = diagnose(rec, settings=settings)
    fit = got.final
    # the diagnosis's own command units and split (hyst_id/diagnosis/driver.py)
    n = split_index(rec.t_s, settings.train_fraction)
    a, b = fit.model.ctx.command_scale
    v = (rec.command - b) / a
    y = rec.measurement
    sigma = noise_std(y) or 1e-12 * float(np.max(np.abs(y)))     # as the diagnosis's
    data = Data(t_s=rec.t_s, v=v, y=y, n_train=n, noise_std=sigma, judged=inside_rows(v, n))
    for mid in args.without:
        if mid in fit.model.slices:
            less = without(fit, mid, data, max_nfev=2 * settings.fit_budget)
            if less is None:
                sys.exit(f'the final model without {mid} is not feasible: nothing to search')
            fit = less
    f_tr, f_ho = floor_percent(y[:n], sigma), floor_percent(y[n:], sigma)

    def line(name, f, seconds=None):
        vals = {m.id: np.round(f.model.theta(f.p, m.id), 5).tolist()
                for m in f.model.mechanisms}
        took = '' if seconds is None else f', {seconds:.1f} s'
        print(f'  {name:<22} training {f.er_train_percent / f_tr:6.3f} x, held-out '
              f'{f.er_holdout_percent / f_ho:6.3f} x the floor; blocks {vals}{took}')

    print(f'start: the final model {got.final.ids}, less {args.without}:')
    line('start', fit)
    for run in args.runs:
        seed, gens = (int(x) for x in run.split(':'))
        t0 = time.perf_counter()
        f = joint_search(fit, data, generations=gens, polish_nfev=2 * settings.fit_budget,
                         seed=seed)
        line(f'seed {seed}, {gens} gen.', f, time.perf_counter() - t0)


if __name__ == '__main__':
    main()
