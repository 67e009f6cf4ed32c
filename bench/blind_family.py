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

"""Blind diagnosis on a random family from the independent reference simulator (issue 14, 5).

Each recording (2,000 samples) is the paper's chain drawn as in
``bench/generalisation.py`` (random loop, backlash, excitation, rate, noise,
units) from ``test/reference_sim``, with 0, 1 or 2 effects written here in
plain numpy at their physical places, at magnitudes drawn log-uniformly from
barely visible to strong:

* on the command: ``dead_time`` (1-10 samples);
* on the travel: ``saturation`` (an end stop cutting 2-25 % of the travel's top),
  ``static_nonlinearity`` (a quadratic term, 1-20 % of the span),
  ``actuator_dynamics`` (zeta 0.1-0.5, omega_n dt 0.05-0.5);
* on the travel from #150 on (:data:`FRICTION_FROM`): ``friction``, a force band leading
  the motion (1-20 % of the span, Dahl's state by Euler steps with a presliding travel
  of 0.5-10 % of it), alone or with the first effect drawn; #0-149 are as before;
* after the channel's sensor: ``sensor_lag`` (tau 0.5-20 samples), ``creep``
  (a 2-20 % share relaxing with tau 2-20 % of the record), ``gain_drift`` (0.5-15 %
  over the record), ``offset_drift`` (0.2-10 % of the span over the record).

Every recording is diagnosed blind with the default settings; the effect's cost
is the baseline's held-out %e_r over the noise floor, both on the judged rows
(``extra.judged_holdout``). Prints per recording and the issue's figures:
named right where the effect costs more than 3 x the floor, claims on clean
recordings, the median final held-out over the floor, seconds per recording;
writes ``docs/diagnosis_blind.md`` and ``docs/diagnosis_blind.json``.

Run from the repository root (about 55 minutes for 150 recordings on 2 cores)::

    python bench/blind_family.py [--n 150] [--workers 2] [--no-write]
    python bench/blind_family.py --indices 5 17 23 --diagnose-workers 2
        # one at a time, each diagnosis in two processes: the time per recording on 2 cores
    python bench/blind_family.py --indices 38 42 64      # some recordings again, no write
    python bench/blind_family.py --from-json     # the tables again, from the last run
    git show REV:docs/diagnosis_blind.json > old.json
    python bench/blind_family.py --compare old.json  # what moved since REV's run
    python bench/blind_family.py --stop-after-min 45   # a part of the run, resumed later

A full run keeps every finished recording in ``docs/diagnosis_blind.partial.jsonl``
with a hash of the code that decides its row (``hyst_id``, the reference simulator,
the family's draw); a later full run on the same code skips those and goes on, so a
slow machine can run the family in parts (``--stop-after-min``: no new recording is
started after that many minutes). Rows of other code are dropped. When all are done the
tables are written and the partial file removed. The seconds per recording then come
from several sessions, each measured the same way.
"""

from __future__ import annotations

import argparse
from collections import Counter
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
import functools
import hashlib
import inspect
import json
from pathlib import Path
import sys
import time
from typing import Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from excitations import moves_and_holds  # noqa: E402, I100
from friction_reference import euler_dahl  # noqa: E402, I100
from generalisation import _draw_params, _excitation, EXCITATIONS  # noqa: E402, I100
from reference_sim import first_order_sensor, second_order_sensor  # noqa: E402, I100
from reference_sim import simulate as reference_simulate  # noqa: E402, I100

N_SAMPLES = 2000
EFFECTS = ('dead_time', 'saturation', 'static_nonlinearity', 'actuator_dynamics',
           'sensor_lag', 'creep', 'gain_drift', 'offset_drift')
#: Recordings from this index on carry ``friction`` (joined the library after the first
#: 150 were drawn; those stay as they were), alone or with the first effect drawn.
FRICTION_FROM = 150


def _logu(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def draw_excitation(rng: np.random.Generator, t: np.ndarray) -> tuple[str, np.ndarray]:
    """The family's excitation: one of ``EXCITATIONS`` or moves and holds, and its command."""
    kind = (*EXCITATIONS, 'moves and holds')[int(rng.integers(0, len(EXCITATIONS) + 1))]
    if kind == 'moves and holds':
        return kind, moves_and_holds(rng, t, dwell_s=t[-1] / 25, move_s=t[-1] / 200,
                                     n_levels=25, lo=6.5, hi=11.5)
    return kind, _excitation(kind, t, rng)


def draw(index: int, only: frozenset | None = None, initial: str = 'rising',
         noise: Callable[[np.random.Generator, int, float, float], np.ndarray] | None = None
         ) -> dict:
    """Recording ``index``: command, measurement, the effects and their magnitudes.

    ``only``: apply only these of its effects (the others are drawn, so that
    everything else is the same, but left out): what one effect alone costs.
    ``initial``: the boundary the reference chain starts on (the family's is
    ``'rising'``; ``bench/start_shares.py`` draws it ``'falling'`` too).
    ``noise``: ``noise(rng, n, sigma, dt_s)`` gives the measurement noise of standard
    deviation ``sigma`` instead of white Gaussian noise
    (``bench/coloured_noise_family.py``).
    """
    rng = np.random.default_rng([index, 14])
    channel = ('position', 'pressure')[index % 2]
    n_eff = int(rng.choice([0, 1, 2], p=[0.25, 0.5, 0.25]))
    effects = rng.choice(EFFECTS, size=n_eff, replace=False).tolist()
    if index >= FRICTION_FROM:
        effects = ['friction'] + effects[:1]
    effects = sorted(effects)
    on = {e for e in effects if only is None or e in only}
    dt = float(rng.choice([0.01, 0.02, 0.05, 0.1]))
    t = np.arange(N_SAMPLES) * dt
    kind, v = draw_excitation(rng, t)
    p = _draw_params(channel, v, rng, t[-1])
    mags: dict[str, float] = {}
    vv = v
    if 'dead_time' in effects:
        d = int(round(_logu(rng, 1.0, 10.0)))
        mags['dead_time'] = d * dt
    if 'dead_time' in on:
        vv = np.concatenate([np.full(d, v[0]), v[:-d]])
    x = reference_simulate('position', p, t, vv, initial=initial)
    span = float(np.ptp(x))
    if 'saturation' in effects:
        cut = _logu(rng, 0.02, 0.25)
        mags['saturation'] = cut
    if 'saturation' in on:
        x = np.minimum(x, float(np.max(x)) - cut * span)
    if 'static_nonlinearity' in effects:
        c = _logu(rng, 0.01, 0.2)
        mags['static_nonlinearity'] = c
    if 'static_nonlinearity' in on:
        z = (x - float(np.min(x))) / span
        x = x + c * span * z ** 2
    if 'friction' in effects:         # a force with the motion: 1-20 % of the span
        frng = np.random.default_rng([index, 14, 1])
        force, length = _logu(frng, 0.01, 0.2), _logu(frng, 0.005, 0.1)
        mags['friction'] = force
    if 'friction' in on:
        x = x + force * span * euler_dahl(x, length * span)
    if 'actuator_dynamics' in effects:
        zeta, wdt = rng.uniform(0.1, 0.5), _logu(rng, 0.05, 0.5)
        mags['actuator_dynamics'] = wdt
    if 'actuator_dynamics' in on:
        x = second_order_sensor(t, x, zeta, wdt / dt)
    y = first_order_sensor(t, x, p['tau_s']) if channel == 'pressure' else x
    span = float(np.ptp(y))
    if 'sensor_lag' in effects:
        tau = _logu(rng, 0.5, 20.0) * dt
        mags['sensor_lag'] = tau
    if 'sensor_lag' in on:
        y = first_order_sensor(t, y, tau)
    if 'creep' in effects:
        share, tau_c = _logu(rng, 0.02, 0.2), rng.uniform(0.02, 0.2) * t[-1]
        mags['creep'] = share
    if 'creep' in on:
        y = (1.0 - share) * y + share * first_order_sensor(t, y, tau_c)
    if 'gain_drift' in effects:       # the sensitivity, about the sensor's zero
        g = _logu(rng, 0.005, 0.15)
        mags['gain_drift'] = g
    if 'gain_drift' in on:
        y = y * (1.0 + g * t / t[-1])
    if 'offset_drift' in effects:
        r = _logu(rng, 0.002, 0.1)
        mags['offset_drift'] = r
    if 'offset_drift' in on:
        y = y + r * span * t / t[-1]
    sigma = rng.uniform(0.002, 0.01) * span
    y = y + (rng.normal(0.0, sigma, y.size) if noise is None else noise(rng, y.size, sigma, dt))
    a, b = float(np.exp(rng.uniform(np.log(0.5), np.log(5.0)))), float(rng.uniform(-5, 5))
    k = float(np.exp(rng.uniform(np.log(0.1), np.log(100.0))))
    zero = rng.uniform(-10, 10) * k       # the reading of y = 0 (gain_drift's pivot)
    return {'index': index, 'channel': channel, 'excitation': kind, 'dt_s': dt,
            'effects': sorted(on),
            'magnitudes': {e: m for e, m in mags.items() if e in on}, 't': t, 'command': a * v + b,
            'measurement': k * y + zero, 'sensor_zero': zero,
            'noise_percent_of_span': 100.0 * sigma / span,
            # the reference chain's parameters, for the command before its affine map
            'chain_params': p, 'reference_command': v}


def run(index: int, workers: int = 1, more_starts: bool = False,
        joint_generations: int = 0) -> dict:
    """Draw and diagnose one recording (``workers`` processes); what the tables need.

    ``more_starts``: the baseline's identify builds more chains from the data
    (``DiagnoseSettings.more_starts``; off, as by default, in the documented run).
    ``joint_generations``: the joint search (``DiagnoseSettings.joint_generations``;
    off by default, 300 in the rerun of ``docs/data/blind_joint_search.json``).
    """
    from hyst_id.diagnosis import diagnose, DiagnoseSettings
    from hyst_id.diagnosis.blocked_cv import confirmed
    from hyst_id.io.recording import Recording
    case = draw(index)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index}')
    t0 = time.time()
    d = diagnose(rec, settings=DiagnoseSettings(workers=workers, more_starts=more_starts,
                                                joint_generations=joint_generations))
    j = d.extra['judged_holdout']
    out = {k: case[k] for k in ('index', 'channel', 'excitation', 'dt_s', 'effects',
                                'magnitudes', 'noise_percent_of_span')}
    held = [f for f in d.findings if confirmed(f.blocked_cv)]
    out.update(verdict=d.verdict, found=[f.mechanism for f in held],
               # fitted, but not held up by blocked cross-validation: stated, not claimed
               unconfirmed=[f.mechanism for f in d.findings if f not in held],
               # per finding, the tied candidates and close calls its report names
               calls=[[a['mechanism'] for a in f.alternatives
                       if a.get('kind', 'tied') in ('tied', 'close', 'signature', 'hold', 'split')]
                      for f in held],
               # the final residual's time x level t (exchange.gain_call's signature)
               level_t=d.final_localization.trend['level_t'],
               # blocked cross-validation: time blocks better / worse, per finding
               blocked=[[f.blocked_cv['better'], f.blocked_cv['worse']] for f in held],
               cost=j['baseline_er_percent'] / j['noise_floor_percent'],
               final=j['final_er_percent'] / j['noise_floor_percent'],
               seconds=time.time() - t0)
    return out


def _right(r: dict) -> bool:
    return sorted(r['found']) == r['effects'] if r['effects'] else r['verdict'] == 'none'


def _right_or_called(r: dict) -> bool:
    """Right, or each effect is a finding or one of the judgement calls the report names.

    Nothing else may be claimed: each finding must be an effect or carry one as a
    stated alternative. Rows from runs before ``calls`` was recorded count as
    :func:`_right`.
    """
    if _right(r) or not r['effects'] or 'calls' not in r:
        return _right(r)
    options = [{f, *c} for f, c in zip(r['found'], r['calls'])]
    return (len(options) == len(r['effects'])
            and all(o & set(r['effects']) for o in options)
            and set(r['effects']) <= set().union(*options))


def summary(rows: list[dict], how: str = 'one worker each') -> str:
    """The issue's figures and the confusion of effects against findings, as markdown."""
    clean = [r for r in rows if not r['effects']]
    eff = [r for r in rows if r['effects']]
    big = [r for r in eff if r['cost'] > 3.0]
    first = [r for r in big if r['found'] and r['found'][0] in r['effects']]
    claims = [r for r in clean if r['found']]
    lines = ['| figure | value | target |', '|---|---|---|',
             f'| recordings | {len(rows)} ({len(clean)} clean, '
             f'{sum(len(r["effects"]) == 1 for r in rows)} with one effect, '
             f'{sum(len(r["effects"]) == 2 for r in rows)} with two) | >= 150 |',
             f'| every effect named, nothing else, where the effects cost > 3 x the floor | '
             f'{sum(map(_right, big))}/{len(big)} | >= 90 % |',
             '| every effect named or among the judgement calls the report states, nothing '
             f'else (same recordings) | {sum(map(_right_or_called, big))}/{len(big)} | |',
             f'| first finding is one of the effects (same recordings) | '
             f'{len(first)}/{len(big)} | |',
             f'| physical claims on clean recordings | {len(claims)}/{len(clean)} '
             f'({", ".join(sorted({r["verdict"] for r in claims})) or "-"}) | 0 |',
             '| median final held-out / floor (judged rows), recordings with effects | '
             f'{np.median([r["final"] for r in eff]) if eff else float("nan"):.2f} | <= 1.2 |',
             f'| seconds per recording, median / max (2,000 samples, {how}) | '
             f'{np.median([r["seconds"] for r in rows]):.0f} / '
             f'{max(r["seconds"] for r in rows):.0f} | <= 60 |', '']
    one = [r for r in big if len(r['effects']) == 1]
    two = [r for r in big if len(r['effects']) == 2]
    right_one = sum(r['verdict'] == r['effects'][0] for r in one)
    lines += [f'Above 3 x: one effect, verdict right {right_one}'
              f'/{len(one)}, all findings right {sum(map(_right, one))}/{len(one)}; two effects, '
              f'both named {sum(map(_right, two))}/{len(two)}, at least one '
              f'{sum(any(f in r["effects"] for f in r["found"]) for r in two)}/{len(two)}. '
              f'Clean baselines above 1.5 x the floor: '
              f'{sum(r["cost"] > 1.5 for r in clean)}/{len(clean)}; clean claims where the '
              f'baseline stopped above 1.4 x: '
              f'{sum(r["cost"] > 1.4 for r in claims)}/{len(claims)} '
              f'(position {sum(r["channel"] == "position" for r in claims)}, pressure '
              f'{sum(r["channel"] == "pressure" for r in claims)}).', '']
    lines += ['Per effect (recordings that contain it; named = among the findings):', '',
              '| effect | recordings | cost > 3 x | named there | named at cost <= 3 x |',
              '|---|---|---|---|---|']
    for e in (*EFFECTS, 'friction'):
        has = [r for r in eff if e in r['effects']]
        hi = [r for r in has if r['cost'] > 3.0]
        lo = [r for r in has if r['cost'] <= 3.0]
        lines.append(f'| {e} | {len(has)} | {len(hi)} | {sum(e in r["found"] for r in hi)} | '
                     f'{sum(e in r["found"] for r in lo)}/{len(lo)} |')
    from blind_effect_costs import alone_figures, clean_figures    # its costs, when written
    alone = alone_figures(rows, (*EFFECTS, 'friction'))
    lines += ['', alone] if alone else []
    clean_split = clean_figures(rows, _right)
    lines += ['', clean_split] if clean_split else []
    lines += ['', blocked_tally(rows)]
    wrong = [r for r in big if not _right(r)]
    lines += ['', 'Misses where the effects cost > 3 x the floor:', '']
    lines += [f'- #{r["index"]} {r["channel"]}, {r["excitation"]}, {1 / r["dt_s"]:g} Hz: '
              f'{"+".join(r["effects"])} ({r["cost"]:.1f} x) -> '
              f'{"+".join(r["found"]) or r["verdict"]} (final {r["final"]:.2f} x)'
              + (f'; judgement calls stated: {_calls(r)}' if any(r.get('calls', [])) else '')
              for r in wrong] or ['- none']
    return '\n'.join(lines)


def blocked_tally(rows: list[dict]) -> str:
    """Blocked cross-validation of the findings, split by whether each is an effect of its record.

    Rows from runs before blocked cross-validation (no ``unconfirmed``) are left out.
    """
    rows = [r for r in rows if 'unconfirmed' in r]
    if not rows:
        return 'Blocked cross-validation: not in these rows (a run before it).'
    true = [(b, w) for r in rows for f, (b, w) in zip(r['found'], r['blocked'])
            if f in r['effects']]
    other = [(b, w) for r in rows for f, (b, w) in zip(r['found'], r['blocked'])
             if f not in r['effects']]
    true_out = sum(f in r['effects'] for r in rows for f in r['unconfirmed'])
    other_out = sum(f not in r['effects'] for r in rows for f in r['unconfirmed'])
    worse = ', '.join(f'{k}: {n}' for k, n in sorted(Counter(w for _, w in true).items()))
    return (f'Blocked cross-validation ({len(rows)} recordings): findings that are an effect '
            f'of their recording confirmed {len(true)}/{len(true) + true_out} (worse in '
            f'how many time blocks -> findings: {worse or "-"}); findings that are not an '
            f'effect not confirmed {other_out}/{len(other) + other_out} (stated, not claimed; '
            f'the verdict is the first confirmed finding, or `unknown`).')


def _calls(r: dict) -> str:
    return '; '.join(f'{f} or {"/".join(c)}' for f, c in zip(r['found'], r['calls']) if c)


def moved(old: list[dict], new: list[dict]) -> str:
    """The recordings whose findings or final held-out / floor moved, a line each."""
    before = {r['index']: r for r in old}
    lines = []
    for r in new:
        o = before.get(r['index'])
        if o is None:
            continue
        was, now = '+'.join(o['found']) or o['verdict'], '+'.join(r['found']) or r['verdict']
        if was != now or abs(o['final'] - r['final']) > 0.05:
            lines.append(f'#{r["index"]} {"+".join(r["effects"]) or "clean"} (cost '
                         f'{r["cost"]:.1f} x): {was} {o["final"]:.2f} x -> {now} '
                         f'{r["final"]:.2f} x')
    return '\n'.join(lines) or 'nothing moved'


def time_ratio(old: list[dict], new: list[dict], indices: list[int] | None = None) -> str:
    """Seconds per recording on the recordings both runs have (or ``indices``), a line.

    The median with its ratio, then the sum and the slowest recording of each run. The same
    recordings and code paths on two machines: the ratio is the machines', as long as
    nothing moved (see :func:`moved`).
    """
    before = {r['index']: r['seconds'] for r in old}
    pairs = [(before[r['index']], r['seconds']) for r in new if r['index'] in before
             and (indices is None or r['index'] in indices)]
    if not pairs:
        return 'no recording in both runs'
    was, now = np.median([p[0] for p in pairs]), np.median([p[1] for p in pairs])
    sums = [sum(p[k] for p in pairs) for k in (0, 1)]
    slowest = [max(pairs, key=lambda p: p[k])[k] for k in (0, 1)]
    return (f'seconds per recording on the same {len(pairs)} recordings, median: '
            f'{was:.0f} -> {now:.0f} ({now / was:.1f} x); sum {sums[0]:.0f} -> {sums[1]:.0f}; '
            f'max {slowest[0]:.0f} -> {slowest[1]:.0f}')


def _rows_json(rows: list[dict]) -> str:
    """The rows as written to a JSON file (without the code hash of the run in parts)."""
    return json.dumps([{key: v for key, v in r.items() if key != 'code'} for r in rows],
                      indent=1)


def write_csv(folder: Path, indices: list[int]) -> int:
    """Write recordings as CSV with their truth beside them (nothing is diagnosed)."""
    folder.mkdir(parents=True, exist_ok=True)
    for i in indices:
        case = draw(i)
        path = folder / f'blind_{i}.csv'
        np.savetxt(path, np.c_[case['t'], case['command'], case['measurement']],
                   delimiter=',', header='t,command,measurement', comments='')
        truth = {k: case[k] for k in ('index', 'channel', 'excitation', 'dt_s', 'effects',
                                      'magnitudes', 'noise_percent_of_span')}
        (folder / f'blind_{i}.truth.json').write_text(json.dumps(truth, indent=1))
        print(f'{path}: hyst-id diagnose {path} --channel {case["channel"]}')
    return 0


PARTIAL = ROOT / 'docs' / 'diagnosis_blind.partial.jsonl'


def code_hash() -> str:
    """Hash of what decides a row: ``hyst_id``, the reference simulator, the draw."""
    h = hashlib.sha256()
    files = sorted([*(ROOT / 'hyst_id').rglob('*.py'),
                    *(ROOT / 'test' / 'reference_sim').rglob('*.py'),
                    ROOT / 'test' / 'excitations.py', ROOT / 'test' / 'friction_reference.py',
                    ROOT / 'bench' / 'generalisation.py'])
    for f in files:
        h.update(str(f.relative_to(ROOT)).encode() + b'\0' + f.read_bytes())
    for fn in (draw, run):
        h.update(inspect.getsource(fn).encode())
    return h.hexdigest()[:16]


def finished_rows(code: str, partial: Path = PARTIAL) -> list[dict]:
    """Rows of an earlier part of the run on the same code (others are dropped)."""
    if not partial.exists():
        return []
    rows = [json.loads(line) for line in partial.read_text().splitlines() if line.strip()]
    kept = [r for r in rows if r.get('code') == code]
    if len(kept) < len(rows):
        print(f'{len(rows) - len(kept)} rows of other code dropped from {partial.name}')
    return kept


def rows_so_far(partial: Path = PARTIAL) -> list[dict]:
    """The rows a run in parts on this code has finished (any ``--diagnose-workers``)."""
    if not partial.exists():
        return []
    code = code_hash()
    rows = [json.loads(line) for line in partial.read_text().splitlines() if line.strip()]
    return [r for r in rows if r.get('code') == code or r.get('code', '').startswith(code + '-k')]


def run_parts(indices: list[int], workers: int, stop_after_s: float, keep: bool, *,
              partial: Path = PARTIAL, one=None, code: str | None = None,
              inline: bool = False) -> list[dict]:
    """Diagnose ``indices`` in ``workers`` processes; append each row to ``partial``.

    ``one`` (default :func:`run`) makes a row from an index; ``code`` (default
    :func:`code_hash`) marks the rows this code makes. ``inline``: one
    recording after the other in this process (``workers`` unused; for
    ``--diagnose-workers``, whose diagnoses start their own processes).
    """
    one = run if one is None else one
    code = code_hash() if code is None else code
    rows = [r for r in finished_rows(code, partial) if r['index'] in indices] if keep else []
    done = {r['index'] for r in rows}
    todo = [i for i in indices if i not in done]
    if done:
        print(f'{len(done)} recordings from earlier parts on this code ({code}); '
              f'{len(todo)} to go')
    t0 = time.time()

    def record(r: dict) -> None:
        rows.append(r)
        if keep:
            with partial.open('a') as f:
                f.write(json.dumps(dict(r, code=code)) + '\n')
        _say(r, len(rows), len(indices), t0)

    if inline:
        for i in todo:
            if time.time() - t0 >= stop_after_s:
                break
            record(one(i))
        return sorted(rows, key=lambda r: r['index'])
    with ProcessPoolExecutor(workers) as pool:
        running: set = set()
        while todo or running:
            while todo and len(running) < workers and time.time() - t0 < stop_after_s:
                running.add(pool.submit(one, todo.pop(0)))
            if not running:
                break
            finished, running = wait(running, return_when=FIRST_COMPLETED)
            for fut in finished:
                record(fut.result())
    return sorted(rows, key=lambda r: r['index'])


def _say(r: dict, k: int, n: int, t0: float) -> None:
    print(f'[{k}/{n} {time.time() - t0:.0f} s] #{r["index"]} '
          f'{r["channel"]} {r["excitation"]} {1 / r["dt_s"]:g} Hz '
          f'{"+".join(r["effects"]) or "clean"} (cost {r["cost"]:.1f} x) -> '
          f'{"+".join(r["found"]) or r["verdict"]} (final {r["final"]:.2f} x, '
          f'{r["seconds"]:.0f} s)'
          + (f'; calls: {_calls(r)}' if _calls(r) else '')
          + (f'; final level t {r["level_t"]:.1f}' if 'level_t' in r else '')
          + (f'; blocked CV better/worse {_blocked(r)}' if r.get('blocked') else '')
          + (f'; not confirmed: {"+".join(r["unconfirmed"])}' if r.get('unconfirmed') else ''),
          flush=True)


def _blocked(r: dict) -> str:
    return ', '.join(f'{f} {b}/{w}' for f, (b, w) in zip(r['found'], r['blocked']))


def main() -> int:
    """Run the family, print and write the tables."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=150)
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--no-write', action='store_true')
    ap.add_argument('--diagnose-workers', type=int, default=1, metavar='K',
                    help='one recording at a time, its diagnosis in K processes '
                         '(the per-recording time on K cores; --workers is then unused)')
    ap.add_argument('--indices', type=int, nargs='+', metavar='I',
                    help='only these recordings (implies --no-write; with --compare, the '
                         'recordings its time line covers)')
    ap.add_argument('--compare', metavar='OLD_JSON',
                    help='only list the recordings whose findings or final (by more than '
                         '0.05 x) differ between OLD_JSON and docs/diagnosis_blind.json '
                         '(or the rows of a run in parts on this code, while there are any; '
                         'or --against), and their times')
    ap.add_argument('--rows-out', metavar='JSON',
                    help='with --indices: also write the rows of this run to JSON (for '
                         '--compare ... --against JSON: two runs of the same recordings)')
    ap.add_argument('--against', metavar='NEW_JSON',
                    help='with --compare: compare with NEW_JSON instead of the documented run')
    ap.add_argument('--from-json', action='store_true',
                    help='only reprint the tables from docs/diagnosis_blind.json (with '
                    '--diagnose-workers K: of a run one at a time in K processes)')
    ap.add_argument('--merge', metavar='ROWS_JSON', nargs='+',
                    help='with --from-json: the rows of ROWS_JSON (a rerun of some '
                         'recordings, --rows-out) in place of the documented ones; of '
                         'several files, a later one wins')
    ap.add_argument('--write-md', action='store_true',
                    help='with --from-json: write them to docs/diagnosis_blind.md too (after '
                    'bench/blind_effect_costs.py added its figures)')
    ap.add_argument('--so-far', action='store_true',
                    help='only print the tables of the rows a run in parts on this code has '
                         'finished (docs/diagnosis_blind.partial.jsonl)')
    ap.add_argument('--csv', metavar='DIR',
                    help='only write the recordings (--indices, else --n) as DIR/blind_<i>.csv '
                         '(t,command,measurement: for hyst-id diagnose/identify with the '
                         "recording's --channel) and what was put in as "
                         'DIR/blind_<i>.truth.json')
    ap.add_argument('--more-starts', action='store_true',
                    help="with --indices: the baseline's identify builds more chains from the "
                         'data (DiagnoseSettings.more_starts; docs/diagnosis.md, section 1)')
    ap.add_argument('--joint-generations', type=int, default=0, metavar='N',
                    help="with --indices: the joint search of each round's leading blocks "
                         '(DiagnoseSettings.joint_generations; docs/diagnosis.md, section 4)')
    ap.add_argument('--stop-after-min', type=float, default=float('inf'), metavar='M',
                    help='start no new recording after M minutes (a full run resumes from '
                         'docs/diagnosis_blind.partial.jsonl next time)')
    args = ap.parse_args()
    for given in (args.compare, args.against, *(args.merge or [])):
        if given and not Path(given).is_file():
            print(f'blind_family: no such rows file: {given}', file=sys.stderr)
            return 2
    if args.csv:
        return write_csv(Path(args.csv), args.indices or list(range(args.n)))
    if args.compare:
        if args.against:
            print(f'comparing with {args.against}')
            now = json.loads(Path(args.against).read_text())
        elif now := rows_so_far():
            print(f'comparing the {len(now)} rows of the run in parts on this code '
                  f'({PARTIAL.name})')
        else:
            now = json.loads((ROOT / 'docs' / 'diagnosis_blind.json').read_text())
        before = json.loads(Path(args.compare).read_text())
        print(moved(before, now))
        print(time_ratio(before, now, args.indices))
        return 0
    if args.from_json:
        k = args.diagnose_workers
        rows = json.loads((ROOT / 'docs' / 'diagnosis_blind.json').read_text())
        if args.merge:
            again = {}
            for name in args.merge:
                more = {r['index']: r for r in json.loads(Path(name).read_text())}
                print(f'{len(more)} rows from {name}')
                again.update(more)
            rows = [again.get(r['index'], r) for r in rows]
            print(f'the documented rows with {len(again)} of those in their place')
        text = summary(rows, 'one worker each' if k <= 1 else f'one at a time in {k} processes')
        print(text)
        if args.write_md and args.merge:
            print('--write-md writes the documented run only (not with --merge)')
            return 2
        if args.write_md:
            _write_md(text, len(rows), k)
        return 0
    if args.so_far:
        rows = rows_so_far()
        print(f'{len(rows)} recordings of the family finished on this code '
              f'({PARTIAL.name}); the tables of those alone:')
        ks = {r['code'].rpartition('-k')[2] for r in rows if '-k' in r['code']}
        how = f'one at a time in {ks.pop()} processes' if len(ks) == 1 else 'one worker each'
        print(summary(rows, how) if rows else 'none')
        return 0
    if (args.more_starts or args.joint_generations) and not args.indices:
        print('--more-starts and --joint-generations only with --indices (the documented '
              'run uses the defaults)')
        return 2
    if args.against:
        print('--against only with --compare')
        return 2
    if args.rows_out and not args.indices:
        print('--rows-out only with --indices (a full run writes docs/diagnosis_blind.json)')
        return 2
    indices = args.indices or list(range(args.n))
    k = args.diagnose_workers
    one = functools.partial(run, more_starts=args.more_starts,
                            joint_generations=args.joint_generations)
    how = 'one worker each' if k <= 1 else f'one at a time in {k} processes'
    full = not (args.no_write or args.indices)
    if k <= 1:
        rows = run_parts(indices, args.workers, 60.0 * args.stop_after_min, keep=full, one=one)
    else:           # the rows of such a run are marked apart: their seconds mean another thing
        rows = run_parts(indices, 1, 60.0 * args.stop_after_min, keep=full,
                         one=functools.partial(one, workers=k), code=f'{code_hash()}-k{k}',
                         inline=True)
    if len(rows) < len(indices):
        print(f'stopped after {len(rows)}/{len(indices)} recordings; run again to go on')
        return 0
    text = summary(rows, how)
    print(text)
    if args.rows_out:
        Path(args.rows_out).write_text(_rows_json(rows))
    if args.indices:      # against the documented run, on the same recordings
        documented = json.loads((ROOT / 'docs' / 'diagnosis_blind.json').read_text())
        print('against docs/diagnosis_blind.json:\n' + moved(documented, rows) + '\n'
              + time_ratio(documented, rows, args.indices))
    if full:
        (ROOT / 'docs' / 'diagnosis_blind.json').write_text(_rows_json(rows))
        _write_md(text, args.n, k)
        PARTIAL.unlink(missing_ok=True)
    return 0


def _write_md(text: str, n: int, k: int) -> None:
    (ROOT / 'docs' / 'diagnosis_blind.md').write_text(
        '# Blind diagnosis on the reference family (issue 14)\n\nWritten by '
        f'`python bench/blind_family.py --n {n}' + (f' --diagnose-workers {k}' if k > 1 else '')
        + '` (the tables again from its rows: `--from-json --diagnose-workers 2 --write-md`); '
        'see the docstring of the script for the family.\n\n' + text + '\n')


if __name__ == '__main__':
    sys.exit(main())
