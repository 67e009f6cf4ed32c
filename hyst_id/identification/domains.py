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

"""Search domains derived from the recording, for any actuator and any units.

The paper's domains (:data:`hyst_id.identification.chains.PAPER_DOMAINS`, preset ``paper``)
fit its rig: a command around 9 mA and a position in the same scale. This
module derives domains from the data instead (preset ``auto``), so a piezo
stage in V and µm or a valve in % and degrees is identified without rescaling
the data or guessing bounds.

The virtual output scale
------------------------
With the affine calibration profiled (the default), the chain's output scale
and offset are free: ``k`` and ``b`` absorb them (see :mod:`hyst_id.identification.gauge`).
The search therefore runs in a *virtual* output scale chosen here: the
hysteresis output spans as much as the command does, centred on zero. The
measurement's units drop out; only the command's range matters. Slopes are
then dimensionless multiples of the loop's mean slope (output span over
command span) and every bound follows from the command range ``[v_lo, v_hi]``
(span ``V``):

========================  ==================================================
parameter                 domain (virtual scale, output span = ``V``)
========================  ==================================================
``m_l``, ``m_r``          ``[0, slope_max]`` (10: ten times the mean slope,
                          or twice the steepest slope in the data)
``m_t``, ``m_b``          ``[0, flat_slope_max]`` (2)
``c_l``, ``c_r``          every crossing ``v - u / m`` of a line with slope
                          ``m >= slope_min`` through the output box
                          ``|u| <= U`` at a command in the visited range
                          widened by ``command_margin``
``c_t``, ``c_b``          every intercept ``u - m v`` of such a line with
                          ``m <= flat_slope_max``
``m_bl``                  ``[0.5, 2]`` (a pure gauge when profiled)
``c_bl``, ``c_br``        ``[-V/2, V/2]``: dead band up to the output span
``tau_s``                 ``[0, 4 T_half]``
``zeta``                  ``[0, 0.99]`` (dimensionless, as the paper)
``omega_n``               ``[0.1, 20] x pi / T_half``, at most ``pi / dt``
========================  ==================================================

The box need not contain every representative of a loop, only one: the
scale gauge lets a loop whose lines are steeper than ``slope_max`` mean
slopes use a smaller virtual output span, and the offset gauge moves the
crossings with the backlash centre.

``U = (1/2 + output_margin) V`` is the half-height of the output box:
the data's half span plus room for a backlash half width and for a top or
bottom line that lies above or below the data (never reached). ``T_half``
is the mean time between command reversals (record length over reversal
count) and ``dt`` the median sampling interval.

With a fixed calibration the output is in the measurement's units mapped
back through it, so the box is centred on the mapped data and every slope
bound is multiplied by the ratio of output span to command span.

Sign of the measurement
-----------------------
The hysteresis model's loop runs counter-clockwise (rising on the lower
branch). A sensor whose reading falls as the actuator moves forward gives a
clockwise loop, fitted with a negative profiled gain ``k``; identification
reports it as ``output_sign = -1`` (the canonical parameters then describe
the negated measurement). :func:`measurement_sign` predicts that sign from
the data alone (:func:`loop_orientation`, the signed loop area) and is kept
in ``ChainSpec.extra``; :func:`reversal_response` tells a friction-type
loop (a transition right after each reversal), which no sign makes
representable.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec, ChainSpec, PAPER_DOMAINS
from hyst_id.identification.loop import (
    loop_orientation,
    loop_width,
    measurement_sign,
    steepest_slope,
)
from hyst_id.io.numbers import level
from hyst_id.io.recording import Recording
from hyst_id.models.family import HysteresisFamily, LoopBox
from hyst_id.models.registry import get_family
from hyst_id.signals.reversals import half_period_s

__all__ = [
    'AUTO',
    'PAPER',
    'PRESETS',
    'DomainSettings',
    'domains_from_data',
    'format_domains',
    'loop_box',
    'preset_spec',
]

#: Name of the data-derived domains (``--domains auto``).
AUTO = 'auto'
#: Name of the paper's domains (``--domains paper``), used by the paper's experiment.
PAPER = 'paper'
#: Fixed presets by name: parameter name -> (low, high).
PRESETS: dict[str, Mapping[str, tuple[float, float]]] = {PAPER: PAPER_DOMAINS}


@dataclass(frozen=True)
class DomainSettings:
    """How wide the data-derived domains are (multiples of the data's scales).

    Attributes
    ----------
    slope_max : float
        Largest left/right slope, in mean loop slopes (output span over
        command span), unless the data shows steeper stretches.
    steep_factor : float
        The largest left/right slope is at least this times the steepest
        slope the data shows (:func:`steepest_slope`).
    flat_slope_max : float
        Largest top/bottom slope, in mean loop slopes.
    slope_min : float
        Smallest left/right slope the crossing domains make room for, in mean
        loop slopes.
    command_margin : float
        Widening of the visited command range on each side, in command spans.
    output_margin : float
        Room above and below the data in the output box, in output spans.
    backlash_slope : tuple of float
        Domain of ``m_bl``.
    tau_max_half_periods : float
        Largest first-order time constant, in half periods of the excitation
        (4: a transmitter slower than a fast dither on the command is common;
        with 1 a 0.95 s sensor under a multisine of 0.34 s half period fell
        outside the box, ``bench/generalisation.py`` #4).
    omega_n_range_rad : tuple of float
        Range of ``omega_n`` in units of ``pi / T_half``.
    zeta : tuple of float
        Domain of ``zeta``.
    """

    slope_max: float = 10.0
    steep_factor: float = 2.0
    flat_slope_max: float = 2.0
    slope_min: float = 0.5
    command_margin: float = 0.25
    output_margin: float = 0.25
    backlash_slope: tuple[float, float] = (0.5, 2.0)
    tau_max_half_periods: float = 4.0
    omega_n_range_rad: tuple[float, float] = (0.1, 20.0)
    zeta: tuple[float, float] = (0.0, 0.99)


def loop_box(rec: Recording, settings: DomainSettings | None = None,
             calibration: tuple[float, float] | None = None) -> LoopBox:
    """Where a loop fitted to ``rec`` lives: command range, output box, slopes, width.

    With the calibration profiled (the default) the output box is the
    virtual scale (output span = command span, centred on zero); with a
    fixed one, the measurement mapped back through it.

    Raises
    ------
    ConfigError
        The command or the measurement does not move, or the calibration
        gain is zero.
    """
    s = settings or DomainSettings()
    v = np.asarray(rec.command, dtype=np.float64)
    y = np.asarray(rec.measurement, dtype=np.float64)
    v_lo, v_hi = float(np.min(v)), float(np.max(v))
    span_v = v_hi - v_lo
    y_lo, y_hi = (float(q) for q in np.percentile(y, [0.5, 99.5]))
    if not span_v > 0.0:
        raise ConfigError('cannot derive search domains: the command does not move')
    if not y_hi > y_lo:
        raise ConfigError('cannot derive search domains: 99 % of the measurement samples '
                          f'hold one value ({y_lo:.6g}); the rest are outliers, not a response')
    if calibration is None:
        u_mid, span_u = 0.0, span_v                      # virtual scale
    else:
        k, b = calibration
        if k == 0.0:
            raise ConfigError('calibration gain k must not be zero')
        s_lo, s_hi = sorted(((y_lo - b) / k, (y_hi - b) / k))
        u_mid, span_u = 0.5 * (s_lo + s_hi), s_hi - s_lo
    half_u = (0.5 + s.output_margin) * span_u
    return LoopBox(v_lo=v_lo - s.command_margin * span_v, v_hi=v_hi + s.command_margin * span_v,
                   v_min=v_lo, v_max=v_hi, u_lo=u_mid - half_u, u_hi=u_mid + half_u,
                   slope=span_u / span_v,
                   steep=max(s.slope_max, s.steep_factor * steepest_slope(rec)),
                   slope_min=s.slope_min, flat_max=s.flat_slope_max,
                   loop_width=loop_width(rec.t_s, v, y))


def domains_from_data(rec: Recording, *, settings: DomainSettings | None = None,
                      calibration: tuple[float, float] | None = None,
                      overrides: Mapping[str, tuple[float, float]] | None = None,
                      family: str | HysteresisFamily | None = None) -> ChainSpec:
    """Chain spec for ``rec.channel`` with search domains derived from the data.

    Parameters
    ----------
    rec : Recording
        The recording to identify (validated or not; only its ranges,
        timing and reversals are read).
    settings : DomainSettings, optional
        Widths of the domains; defaults suit any loop of the recorded span.
    calibration : tuple of float, optional
        Fixed ``(k, b)``; default profiled, whose virtual output scale makes
        the domains independent of the measurement's units.
    overrides : mapping, optional
        Domains given by the user (params YAML or CLI); they win.
    family : str or HysteresisFamily, optional
        H's family (default ``tk``); it derives its own domains from the
        loop box (:func:`loop_box`).

    Returns
    -------
    ChainSpec
        ``domain_source`` is ``'auto'`` (``'auto+given'`` with overrides);
        ``extra`` holds the scales used, the loop box and the measurement's sign.

    Raises
    ------
    ConfigError
        The command or the measurement does not move, or the calibration
        gain is zero.
    """
    s = settings or DomainSettings()
    fam = get_family(family)
    box = loop_box(rec, s, calibration)
    t = np.asarray(rec.t_s, dtype=np.float64)
    span_u = box.span_u / (1.0 + 2.0 * s.output_margin)
    dt_s = float(np.median(np.diff(t)))
    half_period = half_period_s(rec.t_s, rec.command)
    omega_exc = np.pi / half_period
    domains = {
        **fam.domains(box),
        'm_bl': tuple(s.backlash_slope),
        'c_bl': (-0.5 * span_u, 0.5 * span_u), 'c_br': (-0.5 * span_u, 0.5 * span_u),
        'tau_s': (0.0, max(s.tau_max_half_periods * half_period, 10.0 * dt_s)),
        'zeta': tuple(s.zeta),
        'omega_n': (s.omega_n_range_rad[0] * omega_exc,
                    max(min(s.omega_n_range_rad[1] * omega_exc, np.pi / dt_s),
                        2.0 * s.omega_n_range_rad[0] * omega_exc)),
    }
    spec = chain_spec(rec.channel, calibration=calibration, family=fam)
    spec = spec.with_bounds({n: domains[n] for n in spec.names}, source=AUTO)
    source = AUTO
    if overrides:
        spec = spec.with_bounds(overrides, source=AUTO + '+given')
        source = spec.domain_source
    y = np.asarray(rec.measurement, dtype=np.float64)
    y_lo, y_hi = (float(q) for q in np.percentile(y, [0.5, 99.5]))
    extra = {
        'command_range': (box.v_min, box.v_max), 'measurement_range': (y_lo, y_hi),
        'virtual_output_per_measurement': span_u / (y_hi - y_lo),
        'mean_slope': box.slope, 'steepest_slope_allowed': box.steep,
        'output_box': (box.u_lo, box.u_hi), 'loop_box': box,
        'half_period_s': half_period, 'dt_s': dt_s,
        'measurement_sign': measurement_sign(rec),
        'orientation': loop_orientation(rec.command, y),
    }
    return ChainSpec(channel=spec.channel, bounds=spec.bounds, calibration=spec.calibration,
                     domain_source=source, extra=extra, family=fam)


def preset_spec(name: str, channel: str,
                calibration: tuple[float, float] | None = None) -> ChainSpec:
    """Chain spec with a named preset's domains (``paper``).

    Parameters
    ----------
    name : str
        A key of :data:`PRESETS`.
    channel : str
        The chain's channel.
    calibration : tuple of float, optional
        Fixed ``(k, b)``; default profiled.
    """
    if name not in PRESETS:
        raise ConfigError(f'unknown domain preset {name!r}; expected one of '
                          f'{(AUTO, *PRESETS)} or a YAML file')
    preset = PRESETS[name]
    spec = chain_spec(channel, calibration=calibration)
    return spec.with_bounds({n: preset[n] for n in spec.names}, source=name)


def format_domains(spec: ChainSpec) -> str:
    """One line listing each parameter's domain, for logs and reports."""
    return ', '.join(f'{n} [{level(lo, hi - lo)}, {level(hi, hi - lo)}]'
                     for n, (lo, hi) in zip(spec.names, spec.bounds))
