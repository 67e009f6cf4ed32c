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

"""What each effect of the blind family's two-effect recordings costs alone (issue 14, 5).

``bench/blind_family.py`` measures a recording's cost (the baseline's judged
held-out %e_r over the noise floor) with all its effects in. Issue 14's
target is per effect ("named right where the effect costs more than 3 x the
floor"), and in a recording with two effects one of them can cost little: a
second effect that alone stays at the floor cannot be told from the noise
once the first is modelled. This script draws each two-effect recording
again with one of its effects only (``blind_family.draw(index, only=...)``:
the same command, chain, noise and magnitudes, the other effect left out)
and runs the diagnosis's baseline on it (``DiagnoseSettings(max_mechanisms=0)``:
the same split, identification and judged rows as the full diagnosis). As a
check it does the same for ``--check`` one-effect recordings, whose cost the
blind run already has: the two must agree.

Writes ``docs/data/blind_effect_costs.json`` (``{index: {effect: cost}}``),
which ``blind_family.py`` reads for its per-effect figures.

With ``--clean`` it draws every recording with effects again without any and
writes ``docs/data/blind_clean_costs.json`` (``{"cost": {index: cost}, "train":
{index: the training fit over its floor}}``): where the
chain alone misses the held-out part, the split costs it that much without
any effect (:func:`clean_figures`; about 10 minutes).

Usage (repository root, about 15 minutes on 2 cores)::

    python bench/blind_effect_costs.py [--n 180] [--workers 2] [--check 4] [--clean]
    python bench/blind_effect_costs.py --clean --gaass 10 500 [--summarise]
        # the clean draws with identify's GAASS settings in the baseline (about 20
        # minutes), compared with the default run
"""

from __future__ import annotations

import argparse
from concurrent.futures import as_completed, ProcessPoolExecutor
import json
from pathlib import Path
import sys
import time
from typing import Callable

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blind_family import draw, ROOT  # noqa: E402, I100

OUT = ROOT / 'docs' / 'data' / 'blind_effect_costs.json'
CLEAN_OUT = ROOT / 'docs' / 'data' / 'blind_clean_costs.json'
#: A clean draw whose baseline stays within this many x the floor: the split can judge it.
CLEAN_OK = 1.5


def alone_figures(rows: list[dict], effects: tuple[str, ...]) -> str:
    """Issue 14's named-right figure per effect, each effect costed alone; '' without costs.

    One-effect recordings keep the blind run's cost; two-effect ones take
    this script's (``OUT``). Named = among the findings (those blocked
    cross-validation confirmed, as in the blind run's tables).
    """
    try:
        costs = json.loads(OUT.read_text())
    except (OSError, ValueError):
        return ''
    two = [r for r in rows if len(r['effects']) == 2]
    if any(str(r['index']) not in costs for r in two):
        return ''

    def alone(r: dict, e: str) -> float:
        return _alone(r, e, costs)

    pairs = [(r, e) for r in rows for e in r['effects']]
    big = [(r, e) for r, e in pairs if alone(r, e) > 3.0]
    recs = [r for r in rows if any(alone(r, e) > 3.0 for e in r['effects'])]
    right = [r for r in recs if set(r['found']) <= set(r['effects'])
             and all(e in r['found'] for e in r['effects'] if alone(r, e) > 3.0)]
    lines = ['Each effect costed alone (`python bench/blind_effect_costs.py`: the two-effect '
             'recordings drawn again with one effect, the baseline of the diagnosis on each; '
             f'{sum(alone(r, e) <= 3.0 for r in two for e in r["effects"])} of the '
             f'{2 * len(two)} effects of two-effect recordings cost <= 3 x alone):', '',
             '| figure | value |', '|---|---|',
             '| effects that alone cost > 3 x the floor, named | '
             f'{sum(e in r["found"] for r, e in big)}/{len(big)} |',
             '| recordings with an effect that alone costs > 3 x: every such effect named, '
             f'no finding that is not an effect | {len(right)}/{len(recs)} |', '',
             '| effect | alone > 3 x | named there | alone <= 3 x | named there |',
             '|---|---|---|---|---|']
    for e in effects:
        hi = [r for r, f in big if f == e]
        lo = [r for r, f in pairs if f == e and alone(r, f) <= 3.0]
        lines.append(f'| {e} | {len(hi)} | {sum(e in r["found"] for r in hi)} | {len(lo)} | '
                     f'{sum(e in r["found"] for r in lo)} |')
    return '\n'.join(lines)


def _alone(r: dict, effect: str, costs: dict) -> float:
    """What ``effect`` of blind row ``r`` costs alone: the row's cost, or this script's."""
    return r['cost'] if len(r['effects']) == 1 else costs[str(r['index'])][effect]


def clean_figures(rows: list[dict], right: Callable[[dict], bool]) -> str:
    """The named-right figure where the chain alone predicts the clean draw; '' without costs.

    A recording's cost is the baseline's judged held-out miss with its effects
    in; when the same recording drawn without any effect (``--clean``) is
    missed as well, the split costs the chain that much by itself (the
    held-out part reaches output levels or loop states the training part
    never shows, as on some of the reference family's drawn loops), and what
    the effects cost cannot be read from it.
    """
    try:
        doc = json.loads(CLEAN_OUT.read_text())
        clean, train = doc['cost'], doc['train']
    except (OSError, ValueError, KeyError, TypeError):
        return ''
    big = [r for r in rows if r['effects'] and r['cost'] > 3.0]
    if any(str(r['index']) not in clean for r in big):
        return ''
    apart = [r for r in big if clean[str(r['index'])] > CLEAN_OK]
    kept = [r for r in big if clean[str(r['index'])] <= CLEAN_OK]
    with_effects = [r for r in rows if r['effects']]
    missed = [r['index'] for r in with_effects if clean[str(r['index'])] > 3.0]
    shares = {i: _beyond_training_levels(i) for i in missed}
    beyond = {i: m for i, (m, _) in shares.items() if m > 0.05}
    inside = sum(shares[i][1] <= 0.05 for i in beyond)
    unfit = [i for i in missed if train[str(i)] > CLEAN_OK]
    return '\n'.join([
        'Where the chain alone predicts the clean draw (`python bench/blind_effect_costs.py '
        '--clean`: every recording with effects drawn again without any, the baseline on '
        f'each; {len(missed)} of the {len(with_effects)} clean draws are missed by more '
        f'than 3 x the floor, {len(beyond)} of them with more than 5 % of the held-out '
        "measurement beyond the training part's levels ("
        + ', '.join(f'#{i} {100 * m:.0f} %' for i, m in beyond.items())
        + f'; in {inside} of them 95 % or more of the held-out commands lie inside the '
        'training range): there the split asks the chain '
        f'to extrapolate; {len(missed) - len(unfit)} of the {len(missed)} fit their training '
        f'part within {CLEAN_OK} x its floor, the baseline stops above it on '
        + (', '.join(f'#{i} ({train[str(i)]:.2f} x)' for i in unfit) or 'none') + '):', '',
        '| figure | value |', '|---|---|',
        f'| effects cost > 3 x and the clean draw within {CLEAN_OK} x: every effect named, '
        f'nothing else | {sum(right(r) for r in kept)}/{len(kept)} |',
        f'| effects cost > 3 x but the clean draw is missed by more than {CLEAN_OK} x '
        f"(the cost is partly the split's) | {len(apart)}: "
        + ', '.join(f"#{r['index']} ({r['cost']:.1f} x, clean {clean[str(r['index'])]:.1f} x)"
                    for r in apart) + ' |'] + _both_refinements(rows, clean))


def _both_refinements(rows: list[dict], clean: dict) -> list[str]:
    """Rows of effects costed alone, on recordings whose clean draw the chain predicts."""
    try:
        costs = json.loads(OUT.read_text())
        pairs = [(r, e) for r in rows if clean.get(str(r['index']), 1e9) <= CLEAN_OK
                 for e in r['effects'] if _alone(r, e, costs) > 3.0]
    except (OSError, ValueError, KeyError):
        return []
    recs = {r['index']: r for r, _ in pairs}.values()
    right = [r for r in recs if set(r['found']) <= set(r['effects'])
             and all(e in r['found'] for e in r['effects'] if _alone(r, e, costs) > 3.0)]
    return [f'| effects that alone cost > 3 x, on recordings whose clean draw is within '
            f'{CLEAN_OK} x: named | {sum(e in r["found"] for r, e in pairs)}/{len(pairs)} |',
            '| those recordings: every such effect named, no finding that is not an effect | '
            f'{len(right)}/{len(recs)} |']


def _beyond_training_levels(index: int, train_fraction: float = 0.7) -> tuple[float, float]:
    """Shares of the clean draw's held-out measurement (1 % margin) and command beyond training."""
    case = draw(index, only=frozenset())
    n = int(round(train_fraction * case['measurement'].size))

    def beyond(x, margin: float) -> float:
        lo, hi = float(x[:n].min()), float(x[:n].max())
        pad = margin * (hi - lo)
        return float(((x[n:] > hi + pad) | (x[n:] < lo - pad)).mean())

    return beyond(case['measurement'], 0.01), beyond(case['command'], 0.0)


def _gaass_out(gaass: list[int]) -> Path:
    return CLEAN_OUT.with_name(f'{CLEAN_OUT.stem}_s{gaass[0]}g{gaass[1]}.json')


def gaass_comparison(path: Path) -> str:
    """What other GAASS settings in the baseline change on the clean draws (``--gaass``)."""
    old, new = json.loads(CLEAN_OUT.read_text()), json.loads(path.read_text())
    keys = sorted(set(old['cost']) & set(new['cost']), key=int)
    lines = [f'{len(keys)} clean draws, default baseline -> {path.name}:']
    for name, part in (('held-out cost', 'cost'), ('training fit', 'train')):
        a = [old[part][k] for k in keys]
        b = [new[part][k] for k in keys]
        for limit in (1.5, 3.0):
            lines.append(f'  {name} > {limit} x: {sum(x > limit for x in a)} -> '
                         f'{sum(x > limit for x in b)}')
    worse = [k for k in keys if old['cost'][k] <= 1.5 < new['cost'][k]]
    better = [k for k in keys if new['cost'][k] <= 1.5 < old['cost'][k]]
    lines.append('  within 1.5 x now, not before: ' + (', '.join(
        f"#{k} ({old['cost'][k]:.1f} -> {new['cost'][k]:.2f})" for k in better) or 'none'))
    lines.append('  within 1.5 x before, not now: ' + (', '.join(
        f"#{k} ({old['cost'][k]:.2f} -> {new['cost'][k]:.1f})" for k in worse) or 'none'))
    return '\n'.join(lines)


def alone_cost(index: int, effect: str, gaass: tuple[int, int] | None = None
               ) -> tuple[int, str, float, float, float]:
    """The judged baseline held-out %e_r over the floor of ``index`` with ``effect`` only.

    ``effect`` ``''``: none of its effects (the recording's clean draw). Also
    returns the baseline's training %e_r over the training part's floor and the
    seconds it took. ``gaass``: (seeds, generations) of the baseline's GAASS
    instead of the diagnosis's defaults.
    """
    from hyst_id.diagnosis import diagnose, DiagnoseSettings
    from hyst_id.io.recording import Recording
    case = draw(index, only=frozenset({effect} - {''}))
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index}, {effect or "no effect"} only')
    more = {} if gaass is None else {'seeds': tuple(range(gaass[0])), 'generations': gaass[1]}
    t0 = time.time()
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, max_mechanisms=0, **more))
    j = d.extra['judged_holdout']
    return (index, effect, j['baseline_er_percent'] / j['noise_floor_percent'],
            d.baseline.er_train_percent / d.noise_floor_train_percent, time.time() - t0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=180)
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--check', type=int, default=4,
                    help='one-effect recordings costed again, against the blind run')
    ap.add_argument('--gaass', type=int, nargs=2, metavar=('SEEDS', 'GENERATIONS'),
                    help="with --clean: the baseline's GAASS with these settings (identify's: "
                         '10 500), compared with the default run, written apart')
    ap.add_argument('--summarise', action='store_true',
                    help='with --gaass: only compare its written run with the default one')
    ap.add_argument('--clean', action='store_true',
                    help='instead: every recording with effects drawn again without any '
                         '(what the split costs the chain alone); checks on clean recordings')
    args = ap.parse_args()
    if args.gaass and args.summarise:
        print(gaass_comparison(_gaass_out(args.gaass)))
        return 0
    blind = {r['index']: r for r in json.loads(
        (ROOT / 'docs' / 'diagnosis_blind.json').read_text())}
    cases = [draw(i) for i in range(args.n)]
    if args.clean:
        tasks = [(c['index'], '') for c in cases if c['effects']]
        checks = [(c['index'], '') for c in cases      # other GAASS: nothing to check
                  if not c['effects'] and c['index'] in blind and not args.gaass][:args.check]
    else:
        tasks = [(c['index'], e) for c in cases if len(c['effects']) == 2
                 for e in c['effects']]
        checks = [(c['index'], c['effects'][0]) for c in cases
                  if len(c['effects']) == 1 and c['index'] in blind][:args.check]
    costs: dict[str, dict[str, float]] = {}
    train_fit: dict[str, float] = {}         # --clean: the training fit over its floor
    disagree, t0, times = 0, time.time(), []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        futures = [pool.submit(alone_cost, i, e, tuple(args.gaass) if args.gaass else None)
                   for i, e in tasks + checks]
        for k, fut in enumerate(as_completed(futures), 1):
            i, e, cost, train, seconds = fut.result()
            times.append(seconds)
            if (i, e) in checks:
                print(f'check #{i} {e}: alone {cost:.3f} x, blind run {blind[i]["cost"]:.3f} x',
                      flush=True)
                disagree += abs(cost - blind[i]['cost']) > 1e-6 * blind[i]['cost']
                continue
            costs.setdefault(str(i), {})[e] = cost
            train_fit[str(i)] = train
            print(f'[{k}/{len(futures)} {time.time() - t0:.0f} s] #{i} {e or "no effect"} '
                  f'alone: {cost:.2f} x (with its effects: {blind[i]["cost"]:.2f} x)',
                  flush=True)
    if disagree:
        print(f'{disagree} check(s) disagree with the blind run: the procedure is not the '
              "blind run's (another code or machine?); nothing written")
        return 1
    print(f'baseline seconds per recording (one process each): median '
          f'{sorted(times)[len(times) // 2]:.1f}, max {max(times):.1f}')
    out = CLEAN_OUT if args.clean else OUT
    if args.gaass:
        out = _gaass_out(args.gaass)
    if args.clean:
        doc = {'cost': {k: costs[k][''] for k in sorted(costs, key=int)},
               'train': {k: train_fit[k] for k in sorted(train_fit, key=int)}}
    else:
        doc = {k: costs[k] for k in sorted(costs, key=int)}
    out.write_text(json.dumps(doc, indent=1) + '\n')
    print(f'wrote {out.relative_to(ROOT)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
