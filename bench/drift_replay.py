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

"""A recorded run of a drifting plant, replayed: what each compensator's set would leave.

Issue 17's recording-driven evidence. A bag is recorded from the independent
reference simulator's position chain (``test/reference_sim``: the paper's H
and B, noise 0.01) driven open loop: 60 s of Eq. 24, then ``--duration``
(360 s) of minor loops of changing size while the reading's gain falls by
``--gain-drop`` (30 %) and its offset rises by ``--offset-rise`` (0.6), as a
ramp or in one step (``--profile``; the plant of ``bench/drift_compensation.py``).
The bag (MCAP, ``hyst_id.io.bag``) is then read back as any recording is and
replayed sample by sample, in time order, through the package's adaptive
code, with no simulator truth:

(a) **fixed**: the set identified on the first 60 s (``identify``, 2 seeds);
(b) **sliding**: every 30 s the newest 60 s refitted and swapped in when the
    identifier node's rule and gate allow (:func:`hyst_id.live.sliding.reidentify_window`,
    the node's code);
(c) **tracking**: the compensator's gain/offset tracker
    (:class:`hyst_id.compensation.tracking.GainOffsetTracker`, forgetting 20 s) fed
    each recorded reading and the fixed set's prediction for the recorded command.

A compensator running a set leaves the reading off the desired value by what
that set mispredicts (it inverts the set: ``P(S^-1(y_d)) = y_d + (P - S)``), so
the error printed per minute is the rms of the recorded reading minus the
prediction, for the recorded commands, of the model in force at each sample
(tracking: its correction as applied at that sample, before the sample
updates it). This is the open-loop counterpart of ``bench/drift_compensation.py``,
whose closed loop needs the simulator; here only the recording is used.

Usage: ``PYTHONPATH=.:test python bench/drift_replay.py [--profile ramp|step]
[--bag DIR] [--plot FILE.png]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import tempfile

import numpy as np

sys.path[:0] = [str(Path(__file__).resolve().parent),
                str(Path(__file__).resolve().parents[1] / 'test')]

from drift_compensation import (  # noqa: E402, I100
    desired_at,
    DriftingPlant,
    DT_S,
    IDENT_S,
    plot_rolling_rms,
)

from hyst_id.compensation.tracking import GainOffsetTracker  # noqa: E402, I100, I202
from hyst_id.identification import identify, IdentifySettings  # noqa: E402
from hyst_id.io.bag import write_recording_bag  # noqa: E402
from hyst_id.io.readers import read_recording  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.live.sliding import reidentify_window, tail_window  # noqa: E402
from hyst_id.signals.excitation import eq24  # noqa: E402


def record(args: argparse.Namespace, path: Path) -> Path:
    """Run the drifting plant open loop and write the bag; return its directory."""
    plant = DriftingPlant(args.duration, args.gain_drop, args.offset_rise, args.seed,
                          args.profile)
    t = np.arange(0.0, IDENT_S + args.duration, DT_S)
    v = np.where(t < IDENT_S, eq24(t), desired_at(t))
    y = np.array([plant.step(float(vk), float(tk)) for tk, vk in zip(t, v)])
    return write_recording_bag(path, Recording(t, v, y, 'position', 'mA', ''))


def predictions(ident, rec: Recording) -> np.ndarray:
    """The set's prediction of the whole recording (state carried from its start)."""
    return ident.spec().simulate(ident.x, rec.t_s, rec.command)


def replay(rec: Recording) -> dict:
    """Errors per sample of (a) fixed, (b) sliding, (c) tracking, and the sliding decisions."""
    t, y = rec.t_s, rec.measurement
    n_id = int(np.searchsorted(t, IDENT_S))
    first = identify(rec.window(0, n_id), settings=IdentifySettings(
        seeds=(0, 1), maxiter=100, workers=1))
    fixed = predictions(first, rec)
    # (b): the set in force at each sample; a swap at t applies to the samples after it
    in_force = fixed.copy()
    current, events, next_fit = first, [], t[0] + 2 * IDENT_S
    for k in range(n_id, t.size):
        if t[k] < next_fit:
            continue
        next_fit += 30.0
        window = tail_window(rec.window(0, k + 1), 60.0)
        d = reidentify_window(current, window, fresh_settings=IdentifySettings(
            seeds=(0,), maxiter=100, workers=1, restarts=0, global_evals=0))
        events.append((float(t[k]), d.swap, d.reason))
        if d.swap:
            current = d.candidate
            in_force[k + 1:] = predictions(current, rec)[k + 1:]
    # (c): the tracker's a-priori correction of the fixed set's prediction
    tracker = GainOffsetTracker(forget_time_s=20.0)
    tracked = fixed.copy()
    for k in range(n_id, t.size):
        if tracker.applied and tracker.centre is not None:
            tracked[k] = tracker.gain * (fixed[k] - tracker.centre) + tracker.centre \
                + tracker.offset_at(float(t[k]))
        tracker.update(float(t[k]), float(fixed[k]), float(y[k]))
    return {'first': first, 'events': events,
            'errors': {'fixed': y - fixed, 'sliding': y - in_force, 'tracking': y - tracked}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--duration', type=float, default=360.0, help='seconds after the first 60')
    ap.add_argument('--gain-drop', type=float, default=0.3)
    ap.add_argument('--offset-rise', type=float, default=0.6)
    ap.add_argument('--seed', type=int, default=0, help='plant noise seed')
    ap.add_argument('--profile', choices=('ramp', 'step'), default='ramp')
    ap.add_argument('--bag', type=Path, default=None, help='write the bag here (kept)')
    ap.add_argument('--plot', type=Path, default=None, help='write the error plot here')
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        bag = record(args, args.bag or Path(tmp) / 'drifting_plant')
        rec = read_recording(bag, 'position')
        out = replay(rec)
    print(f'# bag {bag if args.bag else "(temporary)"}: {rec.n_samples} samples, '
          f'{rec.duration_s:.0f} s; starting set from the first {IDENT_S:g} s: %e_r '
          f'{out["first"].er_percent:.3f} (noise floor {out["first"].noise_floor_percent:.3f})')
    how = (f'as a ramp over {args.duration:g} s' if args.profile == 'ramp' else
           f'in one step at t = {IDENT_S + args.duration / 3:g} s')
    print(f'\n# rms of reading - model in force per minute after the first {IDENT_S:g} s '
          f'(gain falls {args.gain_drop:.0%}, offset rises {args.offset_rise:g} {how}; '
          'noise 0.01)')
    errors = out['errors']
    print('| minute | ' + ' | '.join(errors) + ' |')
    print('|---|' + '---|' * len(errors))
    for m in range(int(args.duration // 60)):
        sel = (rec.t_s >= IDENT_S + 60 * m) & (rec.t_s < IDENT_S + 60 * (m + 1))
        print(f'| {m + 1} | ' + ' | '.join(f'{np.sqrt(np.mean(e[sel] ** 2)):.3f}'
                                           for e in errors.values()) + ' |')
    print('\n# sliding re-identification decisions')
    for tk, swap, reason in out['events']:
        print(f'- t={tk:.0f} s: {"SWAP" if swap else "kept"}: {reason}')
    if args.plot:
        plot_rolling_rms(args.plot, {k: (rec.t_s, e) for k, e in errors.items()},
                         [tk for tk, swap, _ in out['events'] if swap], 'recording time [s]',
                         'rms(reading - model), last 10 s',
                         f'replayed bag of a drifting plant ({args.profile})', (IDENT_S,))
        print(f'\nwrote {args.plot}')


if __name__ == '__main__':
    main()
