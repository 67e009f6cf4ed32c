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

"""A drifting plant under three compensators: fixed H⁻¹, sliding re-identification, tracking.

The plant is the independent reference simulator's position chain
(``test/reference_sim``: the paper's H and B) whose reading drifts after the
identification run: its gain falls linearly by ``--gain-drop`` (30 %) and its
offset rises by ``--offset-rise`` (0.6) over the ``--duration`` (360 s) of
closed-loop operation (``--profile ramp``), or all at once a third of the
way in (``--profile step``: a supply switched, a part replaced), noise 0.01.
The first 60 s are an open-loop Eq. 24 run from which the starting set is
identified (``identify``, 2 seeds). Then, closed sample by sample at 10 Hz
with a desired value of minor loops:

(a) **fixed**: the starting set's inverse throughout (the paper);
(b) **sliding**: every 30 s the newest 60 s of closed-loop data are refitted
    (:func:`hyst_id.live.sliding.reidentify_window`, 10 s held out, the
    identifier node's swap rule, gate and default fresh fit: one seed of 100
    generations, no global phase) and a better set swapped in at once (the
    node swaps when its worker is done, seconds later);
(c) **tracking**: the compensator's gain/offset tracker (forgetting 20 s).

Prints the rms of reading − desired per minute for each, the swaps with
their reasons, and writes a plot of the error over time.

Usage: ``PYTHONPATH=.:test python bench/drift_compensation.py [--plot FILE.png]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

import numpy as np

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / 'test')]

from hyst_id.compensation import CommandLimits, Compensator, InverseModel  # noqa: E402, I100
from hyst_id.compensation.tracking import (AdaptiveCompensator,  # noqa: E402
                                           GainOffsetTracker, SensorPredictor)
from hyst_id.identification import identify, IdentifySettings  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.live.sliding import reidentify_window, tail_window  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402
from reference_sim import backlash, hysteresis  # noqa: E402, I100, I201

P = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)
B = (1.0, -0.25, 0.25)
DT_S = 0.1
IDENT_S = 60.0
NOISE = 0.01


class DriftingPlant:
    """The reference chain with the reading's gain and offset drifting after ``t_drift_s``."""

    def __init__(self, duration_s: float, gain_drop: float, offset_rise: float, seed: int,
                 profile: str = 'ramp'):
        self.cmds: list[float] = []
        self.profile = profile
        self.t_drift_s, self.duration_s = IDENT_S, duration_s
        self.gain_drop, self.offset_rise = gain_drop, offset_rise
        self.rng = np.random.default_rng(seed)

    def drift(self, t_s: float) -> tuple[float, float]:
        """Gain and offset of the reading at ``t_s``."""
        frac = min(max((t_s - self.t_drift_s) / self.duration_s, 0.0), 1.0)
        if self.profile == 'step':          # the whole change at a third of the run
            frac = float(frac >= 1.0 / 3.0)
        return 1.0 - self.gain_drop * frac, self.offset_rise * frac

    def step(self, v: float, t_s: float) -> float:
        """Reading after command ``v`` at ``t_s`` (the whole history through the reference)."""
        self.cmds.append(v)
        u = hysteresis(np.array(self.cmds), *P)
        y = backlash(u, *B)[-1]
        g, o = self.drift(t_s)
        return float(g * y + o + self.rng.normal(0.0, NOISE))


def desired_at(t_s: np.ndarray) -> np.ndarray:
    """Minor loops of changing size around the middle of the travel."""
    envelope = 0.6 + 0.4 * np.sin(2 * np.pi * t_s / 47.0)
    return 9.3 + 1.4 * np.sin(2 * np.pi * t_s / 12.0) * envelope


def run(kind: str, args: argparse.Namespace, first) -> tuple[np.ndarray, np.ndarray, list]:
    """Closed-loop run ``kind`` in ('fixed', 'sliding', 'tracking'): times, errors, events."""
    plant = DriftingPlant(args.duration, args.gain_drop, args.offset_rise, args.seed,
                          args.profile)
    t_id = np.arange(0.0, IDENT_S, DT_S)
    v_id = eq24(t_id)
    for tk, vk in zip(t_id, v_id):
        plant.step(float(vk), float(tk))
    current = first
    comp = Compensator(InverseModel.from_vector(current.x, current.output_sign),
                       CommandLimits(4.0, 20.0), v0=float(v_id[-1]))
    adaptive = None
    if kind == 'tracking':
        adaptive = AdaptiveCompensator(comp, GainOffsetTracker(forget_time_s=20.0),
                                       SensorPredictor('none'))
    t = IDENT_S + np.arange(0.0, args.duration, DT_S)
    want = desired_at(t)
    ts, vs, ys, events = [], [], [], []
    next_fit = IDENT_S + 60.0
    for k, tk in enumerate(t):
        v = adaptive.step(float(want[k]), float(tk)) if adaptive else comp.step(float(want[k]))
        y = plant.step(v, float(tk))
        if adaptive:
            adaptive.observe(y, float(tk), 0.0 if k == 0 else DT_S)
        ts.append(tk)
        vs.append(v)
        ys.append(y)
        if kind == 'sliding' and tk >= next_fit:
            next_fit += 30.0
            rec = tail_window(Recording(np.array(ts), np.array(vs), np.array(ys), 'position'),
                              60.0)
            t0 = time.perf_counter()
            d = reidentify_window(current, rec, fresh_settings=IdentifySettings(
                seeds=(0,), maxiter=100, workers=1, restarts=0, global_evals=0))
            events.append((float(tk), d.swap, d.reason, time.perf_counter() - t0))
            if d.swap:
                current = d.candidate
                comp.set_model(InverseModel.from_vector(current.x, current.output_sign))
    return t, np.array(ys) - want, events


def plot_rolling_rms(path: Path, series: dict, swaps: list, xlabel: str, ylabel: str,
                     title: str, marks: tuple = ()) -> None:
    """Plot each ``(t, error)`` of ``series`` as its rms over the trailing 10 s.

    ``swaps`` (times of sliding swaps) are dotted lines, ``marks`` solid ones.
    """
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 3.5))
    w = int(10.0 / DT_S)            # trailing 10 s: what an operator sees at t
    for kind, (t, err) in series.items():
        c = np.concatenate([[0.0], np.cumsum(np.asarray(err) ** 2)])
        ax.plot(np.asarray(t)[w - 1:], np.sqrt((c[w:] - c[:-w]) / w), label=kind)
    for tk in swaps:
        ax.axvline(tk, color='tab:orange', lw=0.6, ls=':')
    for tk in marks:
        ax.axvline(tk, color='k', lw=0.6)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--duration', type=float, default=360.0, help='closed-loop seconds')
    ap.add_argument('--gain-drop', type=float, default=0.3)
    ap.add_argument('--offset-rise', type=float, default=0.6)
    ap.add_argument('--seed', type=int, default=0, help='plant noise seed')
    ap.add_argument('--profile', choices=('ramp', 'step'), default='ramp',
                    help='ramp: the change grows over the run; step: all of it at a third')
    ap.add_argument('--plot', type=Path, default=None, help='write the error plot here')
    args = ap.parse_args()
    t_id = np.arange(0.0, IDENT_S, DT_S)
    plant = DriftingPlant(args.duration, args.gain_drop, args.offset_rise, args.seed)
    y_id = np.array([plant.step(float(v), float(tk)) for tk, v in zip(t_id, eq24(t_id))])
    first = identify(Recording(t_id, eq24(t_id), y_id, 'position'),
                     settings=IdentifySettings(seeds=(0, 1), maxiter=100, workers=1))
    print(f'# starting set from {IDENT_S:g} s open loop: %e_r {first.er_percent:.3f} '
          f'(noise floor {first.noise_floor_percent:.3f})')
    results = {kind: run(kind, args, first) for kind in ('fixed', 'sliding', 'tracking')}
    minutes = int(args.duration // 60)
    how = (f'over {args.duration:g} s' if args.profile == 'ramp' else
           f'in one step at t = {IDENT_S + args.duration / 3:g} s')
    print(f'\n# rms of reading - desired per minute (gain falls {args.gain_drop:.0%}, offset '
          f'rises {args.offset_rise:g} {how}; noise {NOISE:g})')
    print('| minute | ' + ' | '.join(results) + ' |')
    print('|---|' + '---|' * len(results))
    for m in range(minutes):
        cells = []
        for t, err, _ in results.values():
            sel = (t >= IDENT_S + 60 * m) & (t < IDENT_S + 60 * (m + 1))
            cells.append(f'{np.sqrt(np.mean(err[sel] ** 2)):.3f}')
        print(f'| {m + 1} | ' + ' | '.join(cells) + ' |')
    print('\n# sliding re-identification decisions')
    for tk, swap, reason, secs in results['sliding'][2]:
        print(f'- t={tk:.0f} s ({secs:.1f} s): {"SWAP" if swap else "kept"}: {reason}')
    if args.plot:
        plot_rolling_rms(args.plot, {k: (t, err) for k, (t, err, _) in results.items()},
                         [tk for tk, swap, _, _ in results['sliding'][2] if swap],
                         'time [s]', 'rms(reading - desired), last 10 s',
                         f'plant change ({args.profile}): fixed H⁻¹, sliding '
                         're-identification, tracking')
        print(f'\nwrote {args.plot}')


if __name__ == '__main__':
    main()
