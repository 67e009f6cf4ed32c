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

"""The smooth family's evidence: simulated curved loops, real loops, compensation.

Four tables (docs/model.md, "The smooth family"):

1. **Simulated smooth loops.** Prandtl-Ishlinskii loops (the plain reference
   ``test/smooth_reference.py``) and Bouc-Wen loops (the piezo form
   ``u = v - kappa z``, a plain Euler integration here, 20 sub-steps a sample;
   a shape the smooth family can only approximate), each behind ``reference_sim``'s backlash and
   first-order sensor, 0.5 % noise: ``identify`` with the smooth family,
   best %e_r / the *true* noise floor.
2. **Real loops, predicting what the fit did not see.** The shared B(H)
   loops: fit on every loop but the largest, predict the largest; the
   shared pneumatic-cylinder recordings: fit on the first 70 %, predict the
   rest. Both families, held-out %e_r side by side, and their ratio.
3. **Compensation of a simulated curved-loop actuator.** A PI actuator with
   backlash is identified from a noisy run (smooth family), its inverse runs
   in-line (:class:`hyst_id.compensation.Compensator`) on a new desired
   trajectory; %eps_c (Eq. 26) of the actuator's output against the desired,
   compensated and uncompensated (command = desired), over seeds, from 5 s on
   (the inverse starts on its rising boundary, the actuator wherever the
   identification run left it).

The compensator's time per sample is ``bench/compensator_latency.py``.

Usage (from the repository root; about 10 minutes on 2 cores)::

    python bench/smooth_family.py
    python bench/smooth_family.py --only real
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from real_recordings import load_all  # noqa: E402, I100
from reference_sim import backlash, first_order_sensor  # noqa: E402
from smooth_reference import plain_play_sum, random_params, smooth_recording  # noqa: E402

__all__ = ['bouc_wen', 'main']

#: Samples (5 s) left out of %eps_c while the inverse's state meets the actuator's.
SETTLE = 250


def bouc_wen(v: np.ndarray, a: float, beta: float, gamma: float, n: float,
             kappa: float, substeps: int = 20) -> np.ndarray:
    """Bouc-Wen actuator loop ``u = v - kappa z``, explicit Euler.

    ``dz = a dv - beta |dv| |z|^(n-1) z - gamma dv |z|^n`` with ``substeps``
    steps per sample and ``z(0) = 0``.

    The piezo form (the Bouc-Wen variable *subtracted*, Low and Guo): the output
    lags the command and the loop runs counter-clockwise; ``u = v + kappa z``
    would be the clockwise force-displacement loop of structural mechanics.
    """
    z, out = 0.0, np.empty(v.size)
    out[0] = v[0]
    for j in range(1, v.size):
        dv = (v[j] - v[j - 1]) / substeps
        for _ in range(substeps):
            az = abs(z)
            z += a * dv - beta * abs(dv) * az ** (n - 1.0) * z - gamma * dv * az ** n
        out[j] = v[j] - kappa * z
    return out


def _bouc_wen_recording(seed: int):
    from hyst_id.io.recording import Recording
    rng = np.random.default_rng([21, seed])
    t = np.arange(3000) * 0.02
    amp = rng.uniform(1.0, 5.0)
    v = amp * np.sin(2 * np.pi * t / 12.0) * (0.4 + 0.6 * np.exp(-t / 25.0))
    v += 0.15 * amp * np.sin(2 * np.pi * t / 2.7)
    n = rng.choice([1.0, 1.5, 2.0])
    beta = rng.uniform(0.5, 2.0) / amp ** n
    gamma = rng.uniform(-0.5, 0.9) * beta
    steepest = 2.0 * beta / (beta + gamma) if gamma < beta else 1.0     # max dz/dv
    u = bouc_wen(v, 1.0, beta, gamma, n, rng.uniform(0.2, 0.8) / steepest)
    band = rng.uniform(0.0, 0.1) * np.ptp(u)
    y0 = first_order_sensor(t, backlash(u, 1.0, -0.5 * band, 0.5 * band), 0.3)
    sigma = 0.005 * np.ptp(y0)
    y = 25.0 * y0 - 4.0 + 25.0 * rng.normal(0.0, sigma, t.size)
    floor = float(np.sqrt(t.size * (25.0 * sigma) ** 2 / (y @ y)) * 100.0)
    return Recording(t, v, y, 'pressure', 'V', 'kPa', f'Bouc-Wen #{seed} (n {n:g})'), floor


def simulated(n_each: int, seeds: int) -> list[str]:
    """Table 1: identify (smooth family) on simulated PI and Bouc-Wen loops."""
    from hyst_id.identification import identify, IdentifySettings
    from hyst_id.identification.domains import domains_from_data
    rows = ['| recording | true floor % | %e_r | ratio |', '|---|---|---|---|']
    ratios = {'PI': [], 'Bouc-Wen': []}
    for kind, make in (('PI', smooth_recording), ('Bouc-Wen', _bouc_wen_recording)):
        for seed in range(n_each):
            rec, floor = make(100 + seed if kind == 'PI' else seed)
            ident = identify(rec, spec=domains_from_data(rec, family='smooth'),
                             settings=IdentifySettings(seeds=tuple(range(seeds))))
            ratios[kind].append(ident.er_percent / floor)
            rows.append(f'| {rec.source} | {floor:.3f} | {ident.er_percent:.3f} | '
                        f'{ident.er_percent / floor:.3f} |')
            print(rows[-1], flush=True)
    rows.append('')
    for kind, r in ratios.items():
        r = np.array(r)
        rows.append(f'{kind}: within 1.1 x the true floor in {np.mean(r <= 1.1):.0%} of '
                    f'{r.size}, median {np.median(r):.3f}, worst {r.max():.2f}')
    return rows


def _largest_loop_start(rec) -> int:
    """Index where the last (largest) B(H) loop starts: the largest |command| jump."""
    return int(np.argmax(np.abs(np.diff(rec.command)))) + 1


def real(seeds: int) -> list[str]:
    """Table 2: both families on the shared real recordings, held-out %e_r."""
    from hyst_id.identification import identify, IdentifySettings
    from hyst_id.identification.domains import domains_from_data
    from hyst_id.identification.model_choice import holdout_error
    from hyst_id.io.recording import validate_recording
    rows = ['| recording | fit on | tk % fit | tk % held out | smooth % fit | '
            'smooth % held out | tk / smooth held out |', '|---|---|---|---|---|---|---|']
    for rec in load_all(ROOT.parent / 'shared' / 'data'):
        bh = 'magnetic' in rec.source
        n_train = _largest_loop_start(rec) if bh else int(0.7 * rec.n_samples)
        train = validate_recording(rec.window(0, n_train))
        err = {}
        for fam in ('tk', 'smooth'):
            ident = identify(train, spec=domains_from_data(train, family=fam),
                             settings=IdentifySettings(seeds=tuple(range(seeds))))
            err[fam] = holdout_error(ident, rec, n_train)
        what = 'smaller loops' if bh else 'first 70 %'
        rows.append(f'| {rec.source} | {what} | {err["tk"][0]:.3f} | {err["tk"][1]:.3f} | '
                    f'{err["smooth"][0]:.3f} | {err["smooth"][1]:.3f} | '
                    f'{err["tk"][1] / err["smooth"][1]:.2f} |')
        print(rows[-1], flush=True)
    return rows


def _actuator(p: np.ndarray, band: float, v: np.ndarray) -> np.ndarray:
    return backlash(plain_play_sum(p, v), 1.0, -0.5 * band, 0.5 * band)


def compensation(n_seeds: int, seeds: int) -> list[str]:
    """Table 3: %eps_c compensated vs uncompensated on simulated PI actuators."""
    from hyst_id.compensation import CommandLimits, Compensator, InverseModel
    from hyst_id.identification import identify, IdentifySettings
    from hyst_id.identification.domains import domains_from_data
    from hyst_id.io.recording import Recording
    rows = ['| actuator | %e_r of the fit | %eps_c uncompensated | %eps_c compensated | '
            'ratio |', '|---|---|---|---|---|']
    ratios = []
    for seed in range(n_seeds):
        rng = np.random.default_rng([31, seed])
        p = random_params(rng)
        # unit overall gain around 10 (command units = output units, as the paper's rig)
        total = p[:7].sum()
        p[:7] /= total
        p[7] *= rng.uniform(0.3, 1.0)                     # r_max
        p[8] = rng.uniform(3.0, 20.0)                     # v_s
        p[9], p[10] = 10.0, 10.0                          # v_c, c_o
        band = rng.uniform(0.0, 0.3)
        t = np.arange(4000) * 0.02
        v = 10.0 + 3.0 * np.sin(2 * np.pi * t / 15.0) * (0.3 + 0.7 * np.exp(-t / 30.0))
        v += 0.6 * np.sin(2 * np.pi * t / 3.1)
        y = _actuator(p, band, v)
        y = y + rng.normal(0.0, 0.003 * np.ptp(y), t.size)
        rec = Recording(t, v, y, 'position', 'mA', 'mA', f'PI actuator #{seed}')
        ident = identify(rec, spec=domains_from_data(rec, family='smooth'),
                         settings=IdentifySettings(seeds=tuple(range(seeds))))
        model = InverseModel.from_mapping({**ident.params, 'family': 'smooth',
                                           'output_sign': ident.output_sign})
        td = np.arange(3000) * 0.02
        desired = 10.0 + 2.0 * np.sin(2 * np.pi * td / 10.0) + 0.5 * np.sin(2 * np.pi * td / 2.3)
        comp = Compensator(model, CommandLimits(-1e6, 1e6), v0=float(desired[0]))
        v_comp = comp.run(desired)
        err = {}
        for name, cmd in (('unc', desired), ('comp', v_comp)):
            out = _actuator(p, band, np.concatenate([v, cmd]))[v.size:]   # state after the run
            e, d = (out - desired)[SETTLE:], desired[SETTLE:]
            err[name] = float(np.sqrt(np.sum(e ** 2) / np.sum(d ** 2)) * 100.0)
        ratios.append(err['comp'] / err['unc'])
        rows.append(f'| {rec.source} | {ident.er_percent:.3f} | {err["unc"]:.3f} | '
                    f'{err["comp"]:.4f} | {ratios[-1]:.3f} |')
        print(rows[-1], flush=True)
    r = np.array(ratios)
    rows += ['', f'compensated / uncompensated %eps_c: median {np.median(r):.3f}, worst '
             f'{r.max():.3f} (target <= 0.2: {"met" if r.max() <= 0.2 else "NOT met"} on all)']
    return rows


def main(argv: list[str] | None = None) -> int:
    """Run the tables asked for and print them."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--only', choices=('simulated', 'real', 'compensation'), default=None)
    ap.add_argument('--n', type=int, default=6, help='recordings per simulated kind')
    ap.add_argument('--seeds', type=int, default=10, help='identify seeds')
    args = ap.parse_args(argv)
    tables = {'simulated': lambda: simulated(args.n, args.seeds),
              'real': lambda: real(args.seeds),
              'compensation': lambda: compensation(args.n, args.seeds)}
    out = []
    for name, fn in tables.items():
        if args.only in (None, name):
            out += [f'## {name}', ''] + fn() + ['']
    print()
    print('\n'.join(out))
    return 0


if __name__ == '__main__':
    sys.exit(main())
