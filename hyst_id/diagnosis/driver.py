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

"""Diagnosis: where a recording departs from the paper's chain, which physics is missing.

``diagnose(recording)``

1. splits the record in time (default: the first 70 % trains, the rest is
   held out) and fits the paper's chain of the channel on the training part
   (:mod:`hyst_id.diagnosis.baseline`: identify with its global phase, in the
   chain's and in data-chosen conventions), in a normalised command scale
   unless a chain spec is given;
2. locates the mismatch in the residual (:mod:`hyst_id.diagnosis.locate`);
3. inserts every mechanism of the library (:mod:`hyst_id.diagnosis.mechanisms`)
   at its place in the chain, refits locally from the baseline (in worker
   processes when ``settings.workers`` is not 1: :mod:`hyst_id.diagnosis.trial`)
   and keeps the best one the data support (:mod:`hyst_id.diagnosis.select`;
   time blocks decide when the split judges too little:
   :meth:`~hyst_id.diagnosis.blocked_cv.BlockedCV.decide`)
   and that more than the chain's refit alone explains
   (:mod:`hyst_id.diagnosis.control`); when none is accepted but a chain as
   good on the training part predicts the held-out part better, that chain is
   taken and the round runs again; repeats once more if the residual still
   has structure; claims made against a baseline near its floor then face
   the chain alone searched wider (:mod:`hyst_id.diagnosis.challenge`);
4. returns a :class:`Diagnosis` whose :meth:`~Diagnosis.to_dict` is the
   ``--json`` document and whose :meth:`~Diagnosis.report` is the text report.

When the baseline residual is white, independent of the command and at the
noise floor on held-out data, no mechanism is tested and the verdict is
``none``. When mechanisms were tested, none was accepted and the held-out
error stays above :data:`~hyst_id.diagnosis.verdict.UNKNOWN_FACTOR` x the noise
floor, the verdict is ``unknown``: something is missing and it is not in the
library (:mod:`hyst_id.diagnosis.verdict`). Whenever
that much is left (with or without findings), an empirical block
(:mod:`hyst_id.diagnosis.empirical`) measures what a model could still gain
and which features of the command and time carry it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np
from threadpoolctl import threadpool_limits

from hyst_id.diagnosis.blocked_cv import BlockedCV, split_record
from hyst_id.diagnosis.challenge import chain_fit, challenge, withdrawn_note
from hyst_id.diagnosis.control import drop_superseded, equivalent_chain, null_control
from hyst_id.diagnosis.control import recheck
from hyst_id.diagnosis.empirical import empirical_block
from hyst_id.diagnosis.exchange import drift_exchange, Exchange, exchanged_call, exchanges
from hyst_id.diagnosis.exchange import gain_call
from hyst_id.diagnosis.locate import Localization, locate, noise_std
from hyst_id.diagnosis.loose_baseline import kept_loose_note, loose_baseline
from hyst_id.diagnosis.mechanisms import get_mechanisms
from hyst_id.diagnosis.mechanisms.base import Context, Mechanism
from hyst_id.diagnosis.refit import contest
from hyst_id.diagnosis.result import DiagnoseSettings, Diagnosis, Finding
from hyst_id.diagnosis.select import Comparison, Data, FitResult, round_record
from hyst_id.diagnosis.split_notes import level_note, range_note, require_split, swing_note
from hyst_id.diagnosis.start_cut import other_boundary, start_cut
from hyst_id.diagnosis.ties import alternatives_record, choose, close_calls, hold_calls
from hyst_id.diagnosis.trial import try_all
from hyst_id.diagnosis.verdict import decide_verdict, UNKNOWN_FACTOR
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec, ChainSpec
from hyst_id.io.recording import Recording, roundoff_probe, validate_part, validate_recording
from hyst_id.signals.artefacts import find_artefacts
from hyst_id.signals.noise import floor_percent
from hyst_id.signals.reversals import command_context
from hyst_id.signals.split import inside_rows, split_index

__all__ = ['diagnose', 'finding_from', 'located_where']


def _info(fit: FitResult, ctx: Context, command: np.ndarray) -> dict:
    """What :meth:`Mechanism.describe` needs to turn a block's numbers into units."""
    model = fit.model
    x_chain = fit.p[:model.n_chain]
    th = {m.id: model.theta(fit.p, m.id) for m in model.mechanisms}
    n_basis = sum(1 for lab in fit.labels if lab == 'sensor' or lab.startswith('quantity:'))

    def to_meas(x: np.ndarray) -> np.ndarray:
        basis = [np.asarray(x, dtype=float)]
        for m in model.mechanisms:
            if m.stage == 'quantity':
                basis = m.quantity(th[m.id], basis[0], fit.span) or basis
        return sum(c * b for c, b in zip(fit.coef[:n_basis], basis)) + fit.offset_at_start

    lo, hi = fit.span
    ends = to_meas(np.array([lo, hi]))
    a = ctx.command_scale[0]
    if model.spec.family.id == 'tk':
        pos_per_cmd = float(x_chain[1] * x_chain[8] / a)      # right line times backlash
    else:                                                     # mean slope over the travel
        pos_per_cmd = float(np.ptp(fit.travel_raw) / max(float(np.ptp(command)), 1e-300))
    return {'coef': fit.coef, 'labels': fit.labels, 'span': fit.span, 'x_chain': x_chain,
            'to_meas': to_meas, 'meas_per_pos': float((ends[1] - ends[0]) / (hi - lo)),
            'pos_per_cmd': pos_per_cmd, 'command': command, 'travel_raw': fit.travel_raw,
            'readings_median': ctx.extra.get('readings_median')}   # the doubt's (trial.judge)


def located_where(loc: Localization, own: dict) -> dict:
    """The ``where`` of a finding: located windows, regimes, trend, spectrum, correlation."""
    bad = sorted((w for w in loc.windows if w['flagged']), key=lambda w: -w['rms_ratio'])
    regimes = {k: [{'range': b['label'], 'rms_ratio': b['rms_ratio'], 'mean': b['mean']}
                   for b in bins if b['flagged']] for k, bins in loc.regimes.items()}
    out = {'time_windows_s': [[w['t_start_s'], w['t_end_s']] for w in bad[:6]],
           'regimes': {k: v for k, v in regimes.items() if v},
           'trend_per_s': loc.trend['slope_per_s'] if loc.trend['significant'] else 0.0,
           'frequencies': {'f0_hz': loc.spectrum['f0_hz'],
                           'below_f0_fraction': loc.spectrum['low_fraction'],
                           'harmonic_fraction': loc.spectrum['harmonic_fraction']},
           'correlation': {'white': loc.white, 'ljung_box_p': loc.ljung_box['p'],
                           'command': {'r': loc.ccf_command['peak_r'],
                                       'lag_s': loc.ccf_command['peak_lag_s'],
                                       'bound': loc.ccf_command['bound']},
                           'command_rate': {'r': loc.ccf_rate['peak_r'],
                                            'lag_s': loc.ccf_rate['peak_lag_s'],
                                            'bound': loc.ccf_rate['bound']}}}
    out['evidence'] = own
    return out


def finding_from(comp: Comparison, before: FitResult, mech: Mechanism, loc: Localization,
                 ctx: Context, command: np.ndarray) -> Finding:
    """Turn an accepted comparison into a :class:`Finding` with words and units."""
    fit = comp.fit
    theta = fit.model.theta(fit.p, mech.id) if mech.id in fit.model.slices else np.zeros(0)
    info = _info(fit, ctx, command)
    info.update(er_before=before.er_holdout_percent, er_after=fit.er_holdout_percent)
    values = mech.describe(theta, fit.coef, info, ctx)
    where = located_where(loc, comp.where)
    return Finding(mechanism=mech.id, title=mech.title, placement=mech.placement,
                   explanation=mech.explain(values, where, ctx), where=where, params=values,
                   er_train_before_percent=before.er_train_percent,
                   er_train_after_percent=fit.er_train_percent,
                   er_holdout_before_percent=before.er_holdout_percent,
                   er_holdout_after_percent=fit.er_holdout_percent,
                   delta_bic=comp.delta_bic, holdout_z=comp.holdout_z,
                   compensation={'kind': mech.compensation,
                                 'how': mech.compensation_note(values, ctx),
                                 'correction': {}})      # from the final fit, at the end


def diagnose(recording: Recording, *, spec: ChainSpec | None = None,
             settings: DiagnoseSettings | None = None,
             progress: Callable[[str], None] | None = None) -> Diagnosis:
    """Diagnose what a recording has that the paper's chain of its channel lacks.

    Parameters
    ----------
    recording : Recording
        Command and one measured channel (validated here).
    spec : ChainSpec, optional
        Chain spec with search domains in the recording's own command units.
        Default: the paper's domains on a normalised command (the command's
        training range mapped to 7-11, the range of the paper's Eq. 24).
    settings : DiagnoseSettings, optional
        Split, baseline GAASS settings, mechanisms, criteria.
    progress : callable, optional
        Called with a short message at each step.

    Returns
    -------
    Diagnosis
    """
    settings = settings or DiagnoseSettings()
    say = progress or (lambda msg: None)
    with threadpool_limits(limits=1):   # small dense problems: one BLAS thread is fastest
        return _diagnose(recording, spec, settings, say)


def _diagnose(recording: Recording, spec: ChainSpec | None, settings: DiagnoseSettings,
              say: Callable[[str], None]) -> Diagnosis:
    given_spec = spec
    rec = roundoff_probe(validate_recording(recording))
    mechs = get_mechanisms(settings.mechanisms, channel=rec.channel)
    t, v_orig, y = rec.t_s, rec.command, rec.measurement
    n_train = split_index(t, settings.train_fraction)
    require_split(n_train, t.size)
    if spec is None:
        lo, hi = float(np.min(v_orig[:n_train])), float(np.max(v_orig[:n_train]))
        half = 0.5 * (hi - lo) if hi > lo else 1.0
        scale = (half / 2.0, 0.5 * (lo + hi) - 9.0 * half / 2.0)
        spec = chain_spec(rec.channel)
    else:
        if spec.channel != rec.channel:
            raise ConfigError(f'chain spec is for {spec.channel!r}, recording is {rec.channel!r}')
        scale = (1.0, 0.0)
    v = (v_orig - scale[1]) / scale[0]
    rec_train = Recording(t[:n_train], v[:n_train], y[:n_train], rec.channel, source=rec.source)
    validate_part(rec_train, f'its training part (the first {settings.train_fraction:.0%} of '
                  'its duration; train_fraction sets it)')
    ctx = Context(channel=rec.channel, t_s=t, n_train=n_train, command_scale=scale,
                  command_unit=rec.command_unit, measurement_unit=rec.measurement_unit,
                  measurement_name=rec.measurement_name,
                  extra={**command_context(t[:n_train], v[:n_train]),
                         'readings_median': float(np.median(y[:n_train]))})
    sigma = noise_std(y) or 1e-12 * float(np.max(np.abs(y)))    # noise-free: no 0 floor
    data = Data(t_s=t, v=v, y=y, n_train=n_train, noise_std=sigma,
                judged=inside_rows(v, n_train))
    say(f'baseline: identify (GAASS x {len(settings.seeds)} seeds, global phase) twice on the '
        f'first {n_train} samples')
    baseline, chain_starts = chain_fit(rec_train, spec, settings, data, ctx)
    baseline, loose_note = loose_baseline(rec_train, spec, settings, data, ctx, baseline)
    if loose_note:
        say('baseline: only a loop whose corners are out of order fits; diagnosing over such')
        spec = replace(spec, proper=False)
    spec, mechs, start_note = other_boundary(baseline.model.initial, spec, mechs)
    floor_h = floor_percent(y[n_train:], sigma)
    floor_t = floor_percent(y[:n_train], sigma)

    def relocate(fit: FitResult) -> Localization:     # where ``fit`` departs from y
        return locate(t, v_orig, y, fit.prediction, sigma, n_train, ctx.period_s)
    loc0 = relocate(baseline)
    say(f'baseline: %e_r train {baseline.er_train_percent:.4g}, held-out '
        f'{baseline.er_holdout_percent:.4g} (noise floor {floor_h:.3g})')
    cut = (start_cut(rec, v, spec, settings, baseline.er_train_percent, floor_t)
           if settings.start_state else None)
    if cut is not None:     # a start inside the play: the record from its first reversal
        say(f'the record started inside the play: diagnosing it from sample {cut.index} on')
        d = _diagnose(recording.window(cut.index, recording.n_samples), given_spec,
                      replace(settings, start_state=False), say)
        d.notes.insert(0, cut.note)
        d.extra['start_cut'] = {'samples_left_out': cut.index, 'first_t_s': float(t[cut.index]),
                                'baseline_over_floor': cut.before_ratio,
                                'probe_over_floor': cut.probe_ratio}
        return d
    current, loc, findings, rounds, round_comps = baseline, loc0, [], [], {}
    blocked = BlockedCV(data)
    rechosen, chain_notes = False, []
    for round_no in range(settings.max_mechanisms):
        if not loc.structured and current.er_holdout_percent <= 1.5 * floor_h:
            break
        if round_no > 0 and current.er_holdout_percent <= 1.2 * floor_h:
            break   # what structure is left is within the noise on held-out data
        done = set(current.ids)
        family = current.model.spec.family.id
        cands = [m for m in mechs if m.id not in done
                 and (m.families is None or family in m.families)
                 and getattr(m, 'swap_family', '') != family]
        rsay = (lambda text, k=round_no + 1: say(f'round {k}: {text}'))
        comps = try_all(cands, current, data, ctx, settings, loc, chain_starts, rsay)
        winner, alternatives = _choose(comps, data, settings.criteria, blocked, rsay)
        null = None if winner is None else null_control(
            winner, current, data, max_nfev=2 * settings.fit_budget)
        if null is not None and recheck(comps, null, data, settings.criteria):
            rsay(f"{winner.mechanism} was the chain refit's doing")
            current = null
            loc = relocate(current)
            winner, alternatives = _choose(comps, data, settings.criteria, blocked, rsay)
        rounds.append(round_record(round_no + 1, comps, winner, data))
        if winner is None and not rechosen:
            other = equivalent_chain(comps, current, data, settings.criteria,
                                     max_nfev=2 * settings.fit_budget)
            if other is not None:
                say(f'round {round_no + 1}: no block, but an equally good chain predicts '
                    'the held-out part better')
                chain_notes.append(_rechosen_note(current, other, data))
                current, rechosen = other, True
                loc = relocate(current)
                continue
        if winner is None:
            break
        mech = next(m for m in mechs if m.id == winner.mechanism)
        named = {a['mechanism'] for a in alternatives}
        calls = hold_calls(winner, comps, data, settings.criteria, ctx.dt_s)
        alternatives += [a for a in calls if a['mechanism'] not in named]
        first, trained = winner, winner.fit.er_train_percent
        by = 'time blocks' if blocked.split_short else 'judged split'
        winner, contested = contest(winner, comps, data, ctx, spec, settings,
                                    floor_train_percent=floor_t,
                                    beats=blocked.beats if blocked.split_short else None,
                                    say=rsay)
        if winner is not first:
            mech = next(m for m in mechs if m.id == winner.mechanism)
            # the round's ties and close calls were measured against the former leader
            alternatives = [{'mechanism': first.mechanism, 'kind': 'contested', 'by': by,
                             'er_holdout_after_percent': first.fit.er_holdout_percent,
                             'er_judged_after_percent': contested[0]['er_judged_after_percent']}
                            ] + [a for a in alternatives if a['kind'] == 'split'
                                 and a['mechanism'] != winner.mechanism]
            rsay(f'{winner.mechanism} takes the round from {first.mechanism} once both chains '
                 'are re-identified')
            chain_notes.append(_contest_note(round_no + 1, first, winner, contested, by))
        elif winner.fit.er_train_percent != trained:
            say(f're-identified the chain with {winner.mechanism}: training %e_r '
                f'{trained:.4g} -> {winner.fit.er_train_percent:.4g}')
        findings.append(finding_from(winner, current, mech, loc, ctx, v_orig))
        findings[-1].alternatives = alternatives
        round_comps[winner.mechanism] = comps
        findings[-1].blocked_cv = blocked.confirm(current, winner.fit)
        current = winner.fit
        loc = relocate(current)
    notes = (list(rec.notes)
             + [start_note] * bool(start_note)
             + range_note(v_orig, n_train, data.judged_rows.size) + chain_notes)
    if len(findings) > 1:
        current, dropped = drop_superseded(current, [f.mechanism for f in findings], data,
                                           settings.criteria, max_nfev=2 * settings.fit_budget)
        for mid in dropped:
            say(f'{mid} withdrawn: the other blocks explain what it did')
            notes.append(f'{mid} was accepted in its round and withdrawn at the end: with the '
                         'other blocks in, the model without it does as well on held-out data '
                         '(it stood in for what a later block explains)')
        if dropped:
            findings = [f for f in findings if f.mechanism not in dropped]
            loc = relocate(current)
    made = exchanges(current, [f.mechanism for f in findings], round_comps, mechs, data, ctx,
                     settings, chain_starts, relocate, say)
    for x in made:
        findings, current, loc = _exchanged(x, findings, mechs, data, ctx, v_orig, blocked,
                                            relocate)
    x = drift_exchange(current, [f.mechanism for f in findings], mechs, data, ctx, settings,
                       chain_starts, loc, relocate, say)
    if x is not None:
        findings, current, loc = _exchanged(x, findings, mechs, data, ctx, v_orig, blocked,
                                            relocate)
    withdrawn: list[str] = []   # claims that the wider chain alone does as well as
    if findings:
        wider = challenge(current, baseline, rec_train, spec, settings, data, ctx, say,
                          split_short=blocked.split_short)
        if wider is not None:
            ids = [f.mechanism for f in findings]
            say(f"{' and '.join(ids)} withdrawn: the chain alone, searched wider, does as well")
            notes.append(withdrawn_note(ids, *wider, data))
            findings, current, withdrawn = [], wider[0], ids
            loc = relocate(current)
    _refresh_values(findings, mechs, current, ctx, v_orig)      # the values the set holds
    _final_corrections(findings, mechs, current, ctx, v_orig)
    final_loc = loc if current is not baseline else loc0
    gain_call(findings, final_loc, {m.id for m in mechs})
    notes += swing_note(t, v_orig, [f.mechanism for f in findings]
                        + [a['mechanism'] for f in findings for a in f.alternatives])
    empirical = None
    if current.er_holdout_percent > UNKNOWN_FACTOR * floor_h:
        say('empirical block: what a model could still gain')
        empirical = empirical_block(t, v_orig, y, current.prediction, n_train, ctx.period_s)
        notes += [] if range_note(v_orig, n_train) else level_note(y, n_train)
    extra = {} if current is baseline else {'blocked_cv': blocked.confirm(baseline, current)}
    if withdrawn:
        extra['withdrawn'] = withdrawn
    verdict, decided = decide_verdict(findings, bool(rounds), baseline, current,
                                      Recording(t, v, y, rec.channel, source=rec.source),
                                      n_train, spec, settings, sigma, floor_h, say)
    extra.update(decided)
    proper_loop, kept = kept_loose_note(current, loose_note)
    notes = [kept] * bool(kept) + notes
    return Diagnosis(channel=rec.channel, source=rec.source, mode='model',
                     verdict=verdict, empirical=empirical, t_s=t,
                     command=v_orig, measurement=y, n_train=n_train, baseline=baseline,
                     final=current, findings=findings, localization=loc0,
                     final_localization=final_loc, noise_std=sigma,
                     noise_floor_percent=floor_h, noise_floor_train_percent=floor_t,
                     rounds=rounds, baseline_params=_chain_dict(rec.channel, baseline.p),
                     measurement_unit=rec.measurement_unit, command_unit=rec.command_unit,
                     measurement_name=rec.measurement_name, command_name=rec.command_name,
                     notes=notes, extra={**extra, 'command_scale': list(scale),
                                         'artefacts': [a.to_dict() for a in find_artefacts(
                                             t, v_orig, y, rec.measurement_unit)],
                                         'hold': current.model.hold
                                         if current.model.dynamic else '',
                                         'initial': current.model.initial,
                                         'proper_loop': proper_loop,
                                         'judged_holdout': _judged(data, baseline, current)})


def _exchanged(x: Exchange, findings: list[Finding], mechs: list[Mechanism], data: Data,
               ctx: Context, v_orig: np.ndarray, blocked: BlockedCV,
               relocate: Callable[[FitResult], Localization]
               ) -> tuple[list[Finding], FitResult, Localization]:
    """The findings, the model and its localization once ``x`` is made."""
    mech = next(m for m in mechs if m.id == x.comparison.mechanism)
    findings = list(findings)
    old, findings[x.index] = findings[x.index], finding_from(
        x.comparison, x.before, mech, relocate(x.before), ctx, v_orig)
    findings[x.index].alternatives = [exchanged_call(x, data)] + [
        a for a in old.alternatives if a['mechanism'] != mech.id
        and a['mechanism'] not in x.stale]
    findings[x.index].blocked_cv = blocked.confirm(x.before, x.comparison.fit)
    return findings, x.comparison.fit, relocate(x.comparison.fit)


def _rechosen_note(before: FitResult, after: FitResult, data: Data) -> str:
    n = data.n_train
    return (f'the chain was chosen again: no block was accepted, but a chain that fits the '
            f'training part as well (%e_r {after.er_train_percent:.4g} against '
            f'{before.er_train_percent:.4g}, BIC {after.bic(n) - before.bic(n):+.1f}) '
            f'predicts the held-out part better (judged %e_r '
            f'{data.judged_er_percent(after):.4g} against {data.judged_er_percent(before):.4g}); '
            'the training part alone does not pin the chain down, and the held-out part '
            'chose between equally good fits')


def _contest_note(round_no: int, first: Comparison, chosen: Comparison,
                  contested: list[dict], by: str = 'judged split') -> str:
    figures = ', '.join(f"{c['mechanism']} {c['er_judged_after_percent']:.4g}" for c in contested)
    how = ('predicts the judged held-out part clearly better' if by == 'judged split' else
           'predicts every judged time block better (the split judged too little to decide)')
    return (f'round {round_no}: {first.mechanism} led on fits made around the current chain, '
            f"but with each block's chain re-identified {chosen.mechanism} {how} (judged "
            f'%e_r after re-identification: {figures}); the current chain was biased by the '
            'missing effect')


def _choose(comps: list[Comparison], data: Data, criteria, blocked: BlockedCV,
            say: Callable[[str], None]) -> tuple[Comparison | None, list[dict]]:
    """:func:`choose`, then, on a short split, :meth:`BlockedCV.decide` among its rivals.

    Returns the round's winner (None when nothing is accepted) and its
    alternatives record: the tied candidates and close calls, or, when the
    time blocks overruled the split, the split's own choice (kind ``split``;
    the others were tied or close to that choice on the short split, which
    said too little to rank them against the winner).
    """
    winner, tied = choose(comps, data, criteria)
    if winner is None:
        return None, []
    close = close_calls(comps, winner, tied, data, criteria)
    chosen, cv = blocked.decide(winner, tied + close)
    if chosen is winner:
        return winner, alternatives_record(tied, close, data)
    say(f'{chosen.mechanism} predicts every time block better than {winner.mechanism}, the '
        "short judged split's choice")
    return chosen, [split_record(winner, chosen, data, cv)]


def _refresh_values(findings: list[Finding], mechs: list[Mechanism], final: FitResult,
                    ctx: Context, command: np.ndarray) -> None:
    """Each finding's values and words from ``final``: the refitted chain the set holds."""
    info = _info(final, ctx, command)
    by_id = {m.id: m for m in mechs}
    for f in findings:
        m = by_id.get(f.mechanism)
        if m is None or m.id not in final.model.slices:
            continue
        own = dict(info, er_before=f.er_holdout_before_percent,   # its round's, as reported
                   er_after=f.er_holdout_after_percent)
        theta = final.model.theta(final.p, m.id)
        f.params = m.describe(theta, final.coef, own, ctx)
        f.at_edges = m.at_edges(theta, ctx)
        f.explanation = m.explain(f.params, f.where, ctx)
        f.compensation['how'] = m.compensation_note(f.params, ctx)


def _final_corrections(findings: list[Finding], mechs: list[Mechanism], final: FitResult,
                       ctx: Context, command: np.ndarray) -> None:
    """Each finding's in-line correction from the *final* fit (what the compensator runs).

    A block accepted in an early round is refitted with every later one, so its
    values (and the calibration a gain centre or a curve refers to) are taken
    from the final model, with which they are exported.
    """
    model = final.model
    if model is None:
        return
    info = _info(final, ctx, command)
    by_id = {m.id: m for m in mechs}
    for f in findings:
        m = by_id.get(f.mechanism)
        if m is None:
            continue
        f.compensation['correction'] = (
            m.correction(model.theta(final.p, m.id), final.coef, info, ctx)
            if m.id in model.slices else {})


def _judged(data: Data, baseline: FitResult, final: FitResult) -> dict:
    """The held-out samples blocks were judged on, and the errors there."""
    rows = data.judged_rows
    return {'n_samples': int(rows.size), 'n_holdout': data.n_holdout,
            'rule': 'held-out samples before the command first leaves the training range '
                    '(all of them when that is under a tenth)',
            'noise_floor_percent': data.floor_holdout_percent,
            'baseline_er_percent': data.judged_er_percent(baseline),
            'final_er_percent': data.judged_er_percent(final)}


def _chain_dict(channel: str, p: np.ndarray) -> dict:
    names = chain_spec(channel).names
    return {n: float(x) for n, x in zip(names, p[:len(names)])}
