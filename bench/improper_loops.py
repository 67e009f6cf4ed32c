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

"""Chains drawn under the paper's constraints only: whether identify reaches the noise floor.

The package searches proper loops first (corners in order, ``docs/model.md``);
the paper's constraints admit loops whose corners are out of order, whose
output jumps at some reversals, and an independent simulator drawing its
parameters under the paper's constraints makes them often. This draws random
chains that way (slopes ``m_l, m_r`` 0.6-1.6, ``m_t, m_b`` 5-60 % of the
smaller; the side lines crossing zero output near command 0, ``c_l`` within 1
of it and ``c_r`` 0.1-0.6 command half ranges above, as in the paper's domains;
the paper's ``v_2`` (left line meets bottom) 0.3-0.9 half ranges below the
command's centre and ``v_1`` (right line meets top) 0.3-1.2 above; ``c_t > c_b``;
a backlash; the pressure sensor's lag 0.2-2 s, the
flow sensor's damping 0.3-0.9 and 1-4 rad/s), simulates them with the
independent reference simulator (``test/reference_sim``) under the excitations
of ``bench/generalisation.py`` (1,500 samples, 0.05 s, Gaussian noise 0.3-1.5 %
of the span) and identifies each with the defaults. It prints, per recording,
whether the true loop is proper, the fit's %e_r over the true noise (1.0: the
floor) and over the estimated floor, whether the loop kept is proper, and the
seconds; then the counts. Run from the repository root (1-4 minutes per
recording and worker)::

    python bench/improper_loops.py [--n 12] [--workers 2] [--without-loose]

``--without-loose``: the proper search alone (``IdentifySettings.loose_loops``
off), as before the loose phase. ``--diagnose``: ``hyst-id diagnose`` (the
defaults, one worker) instead of identify, each recording being clean (noise
only, so every claimed block is a false claim): verdict, blocks, final held-out
%e_r over the floor and whether the loop it ends with is proper;
``--without-loose`` then turns the diagnosis's loose baseline off
(``DiagnoseSettings.loose_loops``, :mod:`hyst_id.diagnosis.loose_baseline`).
``--test-record SEEDS``: instead, the recording of
``test/identification/test_loose_loops.py`` with these noise seeds, each
unperturbed and under round-off probes 1 and 2 (``HYST_ID_ROUNDOFF_PROBE``:
another CPU's last bits), and the ratio its tests bound (``rms / sigma``); with
``--diagnose``, of ``test/diagnosis/test_loose_baseline.py`` (the final held-out
%e_r over the floor, and the verdict). ``--far-record SEEDS``: the same with
the far-off chain of that test (``improper_chain.FAR``, whose proper fit ends
near 40 x the floor)::

    python bench/improper_loops.py --test-record 0 1 2 3 4 5 [--diagnose]
    python bench/improper_loops.py --far-record 0 1 2 3
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
import os
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from generalisation import _excitation, EXCITATIONS  # noqa: E402, I100
from reference_sim import simulate as reference_simulate  # noqa: E402, I100

from hyst_id.identification import identify, IdentifySettings  # noqa: E402, I100
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.models.tk import loop_is_proper  # noqa: E402

CHANNELS = ('position', 'pressure', 'flow')
N_SAMPLES, DT_S = 1500, 0.05


def paper_chain(rng: np.random.Generator, v: np.ndarray, channel: str) -> dict:
    """Random chain parameters under the paper's constraints only (corners in any order)."""
    lo, hi = float(v.min()), float(v.max())
    vc, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    while True:
        m_l, m_r = rng.uniform(0.6, 1.6, 2)
        m_t, m_b = rng.uniform(0.05, 0.6, 2) * min(m_l, m_r)
        # the side lines cross zero output near command 0, as in the paper's domains
        c_l = rng.uniform(-1.0, 1.0)
        c_r = c_l + rng.uniform(0.1, 0.6) * half
        # the paper's v_2 (left line meets bottom) and v_1 (right line meets top) in range
        v_2 = vc - rng.uniform(0.3, 0.9) * half
        v_1 = vc + rng.uniform(0.3, 1.2) * half
        c_b = m_l * (v_2 - c_l) - m_b * v_2
        c_t = m_r * (v_1 - c_r) - m_t * v_1
        if c_t > c_b:
            break
    width = rng.uniform(0.02, 0.3) * half * min(m_l, m_r)
    p = {'m_l': m_l, 'm_r': m_r, 'm_t': m_t, 'm_b': m_b, 'c_l': c_l, 'c_r': c_r, 'c_t': c_t,
         'c_b': c_b, 'm_bl': rng.uniform(0.7, 1.5), 'c_bl': -width, 'c_br': width}
    if channel == 'pressure':
        p['tau_s'] = rng.uniform(0.2, 2.0)
    if channel == 'flow':
        p['zeta'], p['omega_n'] = rng.uniform(0.3, 0.9), rng.uniform(1.0, 4.0)
    return p


def draw(index: int) -> dict:
    """Recording ``index``: channel, excitation, truth, command, measurement, noise std."""
    rng = np.random.default_rng([index, 63])
    channel = CHANNELS[index % 3]
    t = np.arange(N_SAMPLES) * DT_S
    kind = EXCITATIONS[int(rng.integers(0, len(EXCITATIONS)))]
    v = _excitation(kind, t, rng)
    p = paper_chain(rng, v, channel)
    x = reference_simulate(channel, p, t, v)
    sigma = rng.uniform(0.003, 0.015) * float(np.ptp(x))
    h_names = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')
    proper = bool(loop_is_proper(*(p[k] for k in h_names)))
    return {'index': index, 'channel': channel, 'excitation': kind, 'params': p,
            'proper': proper, 't': t, 'command': v,
            'measurement': x + rng.normal(0.0, sigma, x.size), 'sigma': sigma}


def one(job: tuple[int, bool]) -> dict:
    """Identify recording ``index`` (``loose``: the defaults; else the proper search alone)."""
    index, loose = job
    case = draw(index)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    t0 = time.monotonic()
    settings = IdentifySettings(workers=1)
    ident = identify(rec, settings=settings if loose else replace(settings, loose_loops=False))
    y = rec.measurement
    rms = ident.er_percent / 100.0 * float(np.sqrt(np.mean(y ** 2)))
    return {'index': index, 'channel': case['channel'], 'excitation': case['excitation'],
            'true_proper': case['proper'], 'kept_proper': ident.proper,
            'over_noise': rms / case['sigma'],
            'over_floor': ident.er_percent / ident.noise_floor_percent,
            'seconds': time.monotonic() - t0}


def diagnose_one(job: tuple[int, bool]) -> dict:
    """Diagnose recording ``index`` (clean: noise only) with or without the loose baseline."""
    from hyst_id.diagnosis import diagnose, DiagnoseSettings
    index, loose = job
    case = draw(index)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    t0 = time.monotonic()
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, loose_loops=loose))
    return {'index': index, 'channel': case['channel'], 'true_proper': case['proper'],
            'verdict': d.verdict, 'blocks': [f.mechanism for f in d.findings],
            'final': d.final.er_holdout_percent / d.noise_floor_percent,
            'kept_proper': d.to_dict()['proper_loop'], 'seconds': time.monotonic() - t0}


def print_diagnoses(rows: list[dict]) -> None:
    """The diagnosis table and its counts (every block claimed is a false claim)."""
    print('  #  channel   true loop  verdict          blocks                    final x floor'
          '  kept loop  seconds')
    for r in rows:
        print(f'#{r["index"]:3d} {r["channel"]:9s} '
              f'{"proper" if r["true_proper"] else "improper":9s}  {r["verdict"]:15s}  '
              f'{"+".join(r["blocks"]) or "-":24s}  {r["final"]:13.2f}  '
              f'{"proper" if r["kept_proper"] else "improper":9s}  {r["seconds"]:7.0f}')
    for label, mine in by_truth(rows):
        finals = sorted(r['final'] for r in mine)
        print(f'{label} truths: {len(mine)}; false claims '
              f'{sum(bool(r["blocks"]) for r in mine)}; verdict none '
              f'{sum(r["verdict"] == "none" for r in mine)}; final within 1.2 x the floor '
              f'{sum(x <= 1.2 for x in finals)}, median {np.median(finals):.2f}, worst '
              f'{finals[-1]:.2f}; kept improper {sum(not r["kept_proper"] for r in mine)}; '
              f'{sum(r["seconds"] for r in mine):.0f} s in all')


def by_truth(rows: list[dict]) -> list[tuple[str, list[dict]]]:
    """The rows of proper and of improper truths, each with its label (empty groups left out)."""
    groups = [(label, [r for r in rows if r['true_proper'] == truth])
              for label, truth in (('proper', True), ('improper', False))]
    return [(label, mine) for label, mine in groups if mine]


def test_record(job: tuple[int, str, bool, bool]) -> tuple[int, str, float, bool, float, str]:
    """The test's recording with noise ``seed`` under probe ``probe``: its bounded ratio.

    Identify's RMS error over the true noise, or (``diagnose``) the diagnosis's
    final held-out %e_r over its floor; whether the loop kept is proper; the
    seconds; the diagnosis's verdict and blocks ('' for identify). ``far``: the
    far-off chain's recording (``improper_chain.far_recording``) instead.
    """
    seed, probe, diagnose_it, far = job
    from improper_chain import far_recording, improper_recording
    os.environ['HYST_ID_ROUNDOFF_PROBE'] = probe
    rec, sigma = (far_recording if far else improper_recording)(seed)
    t0 = time.monotonic()
    if diagnose_it:
        from hyst_id.diagnosis import diagnose, DiagnoseSettings
        d = diagnose(rec, settings=DiagnoseSettings(workers=1))
        return (seed, probe or '-', d.final.er_holdout_percent / d.noise_floor_percent,
                d.to_dict()['proper_loop'], time.monotonic() - t0,
                '+'.join([d.verdict] + [f.mechanism for f in d.findings]))
    ident = identify(rec, settings=IdentifySettings(workers=1))
    rms = ident.er_percent / 100.0 * float(np.sqrt(np.mean(rec.measurement ** 2)))
    return seed, probe or '-', rms / sigma, ident.proper, time.monotonic() - t0, ''


def main(argv: list[str] | None = None) -> int:
    """Identify the drawn recordings and print the table and the counts."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=12)
    ap.add_argument('--indices', type=int, nargs='*', help='these recordings instead')
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--without-loose', action='store_true')
    ap.add_argument('--diagnose', action='store_true', help='diagnose instead of identify')
    ap.add_argument('--test-record', type=int, nargs='+', metavar='SEED',
                    help="the tests' recording with these noise seeds, under probes too")
    ap.add_argument('--far-record', type=int, nargs='+', metavar='SEED',
                    help="the same with the tests' far-off chain (improper_chain.FAR)")
    args = ap.parse_args(argv)
    if args.test_record or args.far_record:
        far = not args.test_record
        seeds = args.far_record if far else args.test_record
        with ProcessPoolExecutor(args.workers) as pool:
            got = list(pool.map(test_record, [(s, pr, args.diagnose, far) for s in seeds
                                              for pr in ('', '1', '2')]))
        what = 'final / floor' if args.diagnose else 'rms / sigma'
        print(f'seed  probe  {what:>13s}  kept loop  seconds  verdict')
        for seed, probe, ratio, proper, sec, verdict in got:
            print(f'{seed:4d}  {probe:5s}  {ratio:13.3f}  {"proper" if proper else "improper":9s}'
                  f'  {sec:7.0f}  {verdict}')
        print(f'{what}: {min(g[2] for g in got):.3f} - {max(g[2] for g in got):.3f} over '
              f'{len(got)} runs; kept improper in {sum(not g[3] for g in got)}'
              + (f'; verdict none in {sum(g[5] == "none" for g in got)}' if args.diagnose
                 else ''))
        return 0
    indices = args.indices if args.indices else list(range(args.n))
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(diagnose_one if args.diagnose else one,
                             [(i, not args.without_loose) for i in indices]))
    if args.diagnose:
        print_diagnoses(rows)
        return 0
    print('  #  channel   excitation      true loop  kept loop  x true noise  x est. floor'
          '  seconds')
    for r in rows:
        print(f'#{r["index"]:3d} {r["channel"]:9s} {r["excitation"]:15s} '
              f'{"proper" if r["true_proper"] else "improper":9s}  '
              f'{"proper" if r["kept_proper"] else "improper":9s}  {r["over_noise"]:12.3f}  '
              f'{r["over_floor"]:12.3f}  {r["seconds"]:7.0f}')
    for label, mine in by_truth(rows):
        ratios = sorted(r['over_noise'] for r in mine)
        print(f'{label} truths: {len(mine)}; within 1.1 x the true noise '
              f'{sum(x <= 1.1 for x in ratios)}, within 1.5 x {sum(x <= 1.5 for x in ratios)}; '
              f'median {np.median(ratios):.3f}, worst {ratios[-1]:.3f}; kept improper '
              f'{sum(not r["kept_proper"] for r in mine)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
