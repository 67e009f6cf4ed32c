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

"""The rig simulator: batch (:func:`simulate_rig`) and streaming (:class:`RigSimulator`).

Sample convention (the same as the identification chain's): ``command[j]``
is applied over ``(t[j-1], t[j]]`` and the sensors are read at ``t[j]``.
Sample 0 is the steady state at ``command[0]`` (actuator on the rising
branch, pressures and sensors at equilibrium). With every effect off the
position channel is exactly ``B(H(v))`` plus sensor noise and A/D.

Each sample interval is split into ``ceil(dt / max_substep_s)`` equal
substeps; per substep the actuator is updated, the pneumatics advance with
backward Euler (:func:`hyst_id.rig.physics.pneumatic_step`) and the sensor
dynamics advance exactly (zero-order hold). Noise, drift and A/D act once
per sample. Batch and streaming run the same numba kernel and draw the same
random numbers (six standard normals per sample), so they agree exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math

from numba import njit
import numpy as np

from hyst_id.errors import ConfigError, RecordingError
from hyst_id.io.recording import CHANNELS, Recording
from hyst_id.models.backlash import backlash_step
from hyst_id.models.sensors import first_order_coefficient, second_order_coefficients
from hyst_id.models.tk import hysteresis_step, initial_output
from hyst_id.rig.effects import (
    CHARACTERISTIC_KINDS,
    DELAY_CAPACITY,
    delay_lookup,
    delay_push,
    end_stop,
    rate_filter_step,
    stick_slip_step,
    valve_area_fraction,
)
from hyst_id.rig.params import RigParams
from hyst_id.rig.params_file import as_rig_params
from hyst_id.rig.physics import FLOW_MODELS, pneumatic_step, steady_state, vessel_mass

__all__ = ['RigRun', 'RigSample', 'RigSimulator', 'simulate_rig', 'TRUTH_FIELDS', 'UNITS']

_P_FIELDS = (
    'gamma r_gas t0 p_amb v_s n_poly p_s0 reg_on p_set k_reg w_reg_max w_comp v1 a_m b_m '
    'a_v_max a_v_leak b_v pos_closed pos_open flow_model '
    'm_l m_r m_t m_b c_l c_r c_t c_b m_bl c_bl c_br '
    'pos_noise pos_bits pos_lo pos_hi pr_tau pr_noise pr_bits pr_lo pr_hi pr_gauge '
    'fl_zeta fl_omega fl_noise fl_bits fl_lo fl_hi max_sub '
    'dt_on dt_delay lag_on lag_pos lag_pr lag_fl ss_on ss_static ss_dynamic es_on es_lo es_hi '
    'dr_on dr_pos dr_pr dr_fl dr_pos_walk dr_pr_walk dr_fl_walk rh_on rh_k rh_tau '
    'vc_on vc_kind vc_r vc_n').split()
_P_DTYPE = np.dtype([(n, 'f8') for n in _P_FIELDS])
_S_DTYPE = np.dtype([(n, 'f8') for n in (
    't v_act u_h y_b x_pos rate p_s p1 w_in w_m w_v pr_x fl_x fl_xd lag_pos lag_pr lag_fl '
    'off_pos off_pr off_fl cum_in cum_m cum_v p_ref dl_head dl_count n_fail init').split()])

#: Internal (noise-free) signals recorded per sample, with units.
TRUTH_FIELDS = {
    'actuator_command_ma': 'mA', 'hysteresis_out': 'mA-eq', 'backlash_out': 'mA-eq',
    'position_true': 'mA-eq', 'opening': '1', 'valve_area_m2': 'm^2',
    'supply_pressure_pa': 'Pa', 'p1_pa': 'Pa', 'mass_flow_g_s': 'g/s',
    'manual_flow_g_s': 'g/s', 'supply_inflow_g_s': 'g/s', 'vessel_mass_kg': 'kg',
    'pipe_mass_kg': 'kg', 'cum_supply_in_kg': 'kg', 'cum_manual_kg': 'kg',
    'cum_valve_kg': 'kg', 'position_clean': 'mA-eq', 'pressure_clean_pa': 'Pa',
    'flow_clean_g_s': 'g/s',
}
_OUT_DTYPE = np.dtype([(n, 'f8') for n in ('position', 'pressure_pa', 'flow_g_s', *TRUTH_FIELDS)])

#: Units of the measured channels (position in the actuator's mA-equivalent units).
UNITS = {'command': 'mA', 'position': 'mA-eq', 'pressure': 'Pa', 'flow': 'g/s'}


def _pack(params: RigParams) -> np.ndarray:
    g, s, cv, a, e = (params.gas, params.supply, params.control_valve, params.actuator,
                      params.effects)
    ps, pr, fl = params.position_sensor, params.pressure_sensor, params.flow_sensor
    values = {
        'gamma': g.gamma, 'r_gas': g.r_j_kg_k, 't0': g.temperature_k,
        'p_amb': g.ambient_pressure_pa,
        'v_s': s.volume_m3, 'n_poly': s.polytropic_n, 'p_s0': s.initial_pressure_pa,
        'reg_on': float(s.regulation), 'p_set': s.regulator_setpoint_pa,
        'k_reg': s.regulator_gain_kg_s_pa,
        'w_reg_max': s.regulator_max_flow_g_s * 1e-3, 'w_comp': s.compressor_flow_g_s * 1e-3,
        'v1': params.pipe.volume_m3, 'a_m': params.manual_valve.area_m2,
        'b_m': params.manual_valve.critical_ratio, 'a_v_max': cv.max_area_m2,
        'a_v_leak': cv.leak_area_m2, 'b_v': cv.critical_ratio, 'pos_closed': cv.position_closed,
        'pos_open': cv.position_open,
        'flow_model': float(FLOW_MODELS.index(params.integration.flow_model)),
        'pos_noise': ps.noise_std, 'pos_bits': ps.adc_bits, 'pos_lo': ps.range_min,
        'pos_hi': ps.range_max,
        'pr_tau': pr.tau_s, 'pr_noise': pr.noise_std_pa, 'pr_bits': pr.adc_bits,
        'pr_lo': pr.range_min_pa,
        'pr_hi': pr.range_max_pa, 'pr_gauge': float(pr.reference == 'gauge'),
        'fl_zeta': fl.zeta, 'fl_omega': fl.omega_n_rad_s, 'fl_noise': fl.noise_std_g_s,
        'fl_bits': fl.adc_bits, 'fl_lo': fl.range_min_g_s, 'fl_hi': fl.range_max_g_s,
        'max_sub': params.integration.max_substep_s,
        'dt_on': e.dead_time.enabled, 'dt_delay': e.dead_time.delay_s,
        'lag_on': e.sensor_lag.enabled, 'lag_pos': e.sensor_lag.position_tau_s,
        'lag_pr': e.sensor_lag.pressure_tau_s, 'lag_fl': e.sensor_lag.flow_tau_s,
        'ss_on': e.stick_slip.enabled, 'ss_static': e.stick_slip.static_band,
        'ss_dynamic': e.stick_slip.dynamic_band, 'es_on': e.end_stops.enabled,
        'es_lo': e.end_stops.min_position, 'es_hi': e.end_stops.max_position,
        'dr_on': e.offset_drift.enabled, 'dr_pos': e.offset_drift.position_per_s,
        'dr_pr': e.offset_drift.pressure_pa_per_s, 'dr_fl': e.offset_drift.flow_g_s_per_s,
        'dr_pos_walk': e.offset_drift.position_walk_per_sqrt_s,
        'dr_pr_walk': e.offset_drift.pressure_walk_pa_per_sqrt_s,
        'dr_fl_walk': e.offset_drift.flow_walk_g_s_per_sqrt_s,
        'rh_on': e.rate_hysteresis.enabled, 'rh_k': e.rate_hysteresis.width_per_rate_s,
        'rh_tau': e.rate_hysteresis.filter_tau_s, 'vc_on': e.valve_characteristic.enabled,
        'vc_kind': CHARACTERISTIC_KINDS.index(e.valve_characteristic.kind),
        'vc_r': e.valve_characteristic.rangeability, 'vc_n': e.valve_characteristic.exponent,
    }
    values.update({k: getattr(a, k) for k in ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t',
                                              'c_b', 'm_bl', 'c_bl', 'c_br')})
    rec = np.zeros(1, dtype=_P_DTYPE)
    for k, v in values.items():
        rec[0][k] = float(v)
    return rec


@njit(cache=True)
def _gas(p):
    return (p.b_m, p.b_v, int(p.flow_model), p.gamma, p.r_gas, p.t0, p.p_amb, p.v_s, p.n_poly,
            p.p_s0, p.v1, p.reg_on > 0.5, p.p_set, p.k_reg, p.w_reg_max, p.w_comp)


@njit(cache=True)
def _area(p, position):
    x = min(max((position - p.pos_closed) / (p.pos_open - p.pos_closed), 0.0), 1.0)
    f = x
    if p.vc_on > 0.5:
        f = valve_area_fraction(x, int(p.vc_kind), p.vc_r, p.vc_n)
    return x, p.a_v_leak + (p.a_v_max - p.a_v_leak) * f


@njit(cache=True)
def _quantise(y, noise_std, z, bits, lo, hi):
    y = y + noise_std * z
    if bits > 0.5:
        lsb = (hi - lo) / 2.0 ** bits
        code = min(max(math.floor((y - lo) / lsb + 0.5), 0.0), 2.0 ** bits - 1.0)
        return lo + code * lsb
    return min(max(y, lo), hi)


@njit(cache=True)
def _initialise(p, s, buf, v0):
    u = initial_output(v0, p.m_r, p.m_t, p.m_b, p.c_r, p.c_t, p.c_b)
    y = p.m_bl * (u - p.c_br)
    pos = end_stop(y, p.es_lo, p.es_hi) if p.es_on > 0.5 else y
    a_v = _area(p, pos)[1]
    g = _gas(p)
    p_s, p1 = steady_state(p.p_s0, p.a_m, a_v, g)
    s.t, s.v_act, s.u_h, s.y_b, s.x_pos, s.rate = 0.0, v0, u, y, y, 0.0
    s.p_s, s.p1, s.p_ref = p_s, p1, p_s
    g = (g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g[8], p_s, g[10], g[11], g[12],
         g[13], g[14], g[15])
    _, _, s.w_in, s.w_m, s.w_v, _ = pneumatic_step(p_s, p1, 0.0, p.a_m, a_v, g)
    s.pr_x, s.fl_x, s.fl_xd = p1, s.w_v * 1e3, 0.0
    s.lag_pos, s.lag_pr, s.lag_fl = pos, p1, s.w_v * 1e3
    s.off_pos, s.off_pr, s.off_fl = 0.0, 0.0, 0.0
    s.cum_in, s.cum_m, s.cum_v, s.n_fail = 0.0, 0.0, 0.0, 0.0
    s.dl_head, s.dl_count = 0.0, 0.0
    head, count = delay_push(buf, 0, 0, -1e300, v0)
    s.dl_head, s.dl_count = float(head), float(count)
    s.init = 1.0


@njit(cache=True)
def _interval(p, s, buf, v, dt):
    """Advance the rig over one sample interval with command ``v``; 0 or an error code."""
    g = _gas(p)
    g = (g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g[8], s.p_ref, g[10], g[11], g[12],
         g[13], g[14], g[15])
    head, count = int(s.dl_head), int(s.dl_count)
    if p.dt_on > 0.5:
        head, count = delay_push(buf, head, count, s.t, v)
        if count < 0:
            return 1
    n_sub = max(1, int(math.ceil(dt / p.max_sub - 1e-9)))
    h = dt / n_sub
    a_pr = first_order_coefficient(h, p.pr_tau)
    q11, q12, q21, q22 = second_order_coefficients(h, p.fl_zeta, p.fl_omega)
    lag = p.lag_on > 0.5
    a_lp = first_order_coefficient(h, p.lag_pos) if lag else 0.0
    a_lr = first_order_coefficient(h, p.lag_pr) if lag else 0.0
    a_lf = first_order_coefficient(h, p.lag_fl) if lag else 0.0
    c_l, c_r = p.c_l, p.c_r
    for k in range(n_sub):
        v_a = v
        if p.dt_on > 0.5:
            v_a, head, count = delay_lookup(buf, head, count, s.t + (k + 0.5) * h - p.dt_delay)
        if p.rh_on > 0.5:
            s.rate = rate_filter_step(s.rate, abs(v_a - s.v_act), h, p.rh_tau)
            c_l, c_r = p.c_l - p.rh_k * s.rate, p.c_r + p.rh_k * s.rate
        s.u_h = hysteresis_step(v_a, s.v_act, s.u_h, p.m_l, p.m_r, p.m_t, p.m_b, c_l, c_r,
                                p.c_t, p.c_b)
        s.v_act = v_a
        s.y_b = backlash_step(s.u_h, s.y_b, p.m_bl, p.c_bl, p.c_br)
        s.x_pos = stick_slip_step(s.y_b, s.x_pos, p.ss_static, p.ss_dynamic) \
            if p.ss_on > 0.5 else s.y_b
        pos = end_stop(s.x_pos, p.es_lo, p.es_hi) if p.es_on > 0.5 else s.x_pos
        a_v = _area(p, pos)[1]
        s.p_s, s.p1, s.w_in, s.w_m, s.w_v, ok = pneumatic_step(s.p_s, s.p1, h, p.a_m, a_v, g)
        if not ok:
            s.n_fail += 1.0
        s.cum_in += h * s.w_in
        s.cum_m += h * s.w_m
        s.cum_v += h * s.w_v
        s.pr_x = a_pr * s.pr_x + (1.0 - a_pr) * s.p1
        w = s.w_v * 1e3
        e = s.fl_x - w
        s.fl_x = w + q11 * e + q12 * s.fl_xd
        s.fl_xd = q21 * e + q22 * s.fl_xd
        if lag:
            s.lag_pos = a_lp * s.lag_pos + (1.0 - a_lp) * pos
            s.lag_pr = a_lr * s.lag_pr + (1.0 - a_lr) * s.pr_x
            s.lag_fl = a_lf * s.lag_fl + (1.0 - a_lf) * s.fl_x
    s.t += dt
    s.dl_head, s.dl_count = float(head), float(count)
    return 0


@njit(cache=True)
def _advance(pr, st, buf, cmd, dt, z, out):
    """Run ``cmd`` through the rig from state ``st`` (in place); 0 or an error code."""
    p = pr[0]
    s = st[0]
    for j in range(cmd.shape[0]):
        if s.init < 0.5:
            _initialise(p, s, buf, cmd[j])
        else:
            code = _interval(p, s, buf, cmd[j], dt[j])
            if code > 0:
                return code
            if p.dr_on > 0.5:
                sq = math.sqrt(dt[j])
                s.off_pos += p.dr_pos * dt[j] + p.dr_pos_walk * sq * z[j, 3]
                s.off_pr += p.dr_pr * dt[j] + p.dr_pr_walk * sq * z[j, 4]
                s.off_fl += p.dr_fl * dt[j] + p.dr_fl_walk * sq * z[j, 5]
        pos = end_stop(s.x_pos, p.es_lo, p.es_hi) if p.es_on > 0.5 else s.x_pos
        opening, a_v = _area(p, pos)
        lag = p.lag_on > 0.5
        pos_c = (s.lag_pos if lag else pos) + s.off_pos
        pr_c = (s.lag_pr if lag else s.pr_x) - (p.p_amb if p.pr_gauge > 0.5 else 0.0) + s.off_pr
        fl_c = (s.lag_fl if lag else s.fl_x) + s.off_fl
        o = out[j]
        o.position = _quantise(pos_c, p.pos_noise, z[j, 0], p.pos_bits, p.pos_lo, p.pos_hi)
        o.pressure_pa = _quantise(pr_c, p.pr_noise, z[j, 1], p.pr_bits, p.pr_lo, p.pr_hi)
        o.flow_g_s = _quantise(fl_c, p.fl_noise, z[j, 2], p.fl_bits, p.fl_lo, p.fl_hi)
        o.actuator_command_ma, o.hysteresis_out, o.backlash_out = s.v_act, s.u_h, s.y_b
        o.position_true, o.opening, o.valve_area_m2 = pos, opening, a_v
        o.supply_pressure_pa, o.p1_pa = s.p_s, s.p1
        o.mass_flow_g_s, o.manual_flow_g_s = s.w_v * 1e3, s.w_m * 1e3
        o.supply_inflow_g_s = s.w_in * 1e3
        o.vessel_mass_kg = vessel_mass(s.p_s, p.v_s, p.n_poly, s.p_ref, p.t0, p.r_gas)[0]
        o.pipe_mass_kg = s.p1 * p.v1 / (p.r_gas * p.t0)
        o.cum_supply_in_kg, o.cum_manual_kg, o.cum_valve_kg = s.cum_in, s.cum_m, s.cum_v
        o.position_clean, o.pressure_clean_pa, o.flow_clean_g_s = pos_c, pr_c, fl_c
    return 0


def _as_dict(rows: np.ndarray) -> dict[str, np.ndarray]:
    return {name: np.array(rows[name]) for name in rows.dtype.names}


@dataclass(frozen=True)
class RigSample:
    """One sample of the streaming simulator.

    Attributes
    ----------
    t_s : float
        Sample time, seconds.
    command_ma : float
        Command applied over the interval that ended now.
    position, pressure_pa, flow_g_s : float
        Sensor readings (noise, drift, A/D): position units, Pa, g/s.
    truth : dict
        Noise-free internal signals, as :data:`TRUTH_FIELDS`.
    """

    t_s: float
    command_ma: float
    position: float
    pressure_pa: float
    flow_g_s: float
    truth: dict = field(default_factory=dict)


@dataclass(frozen=True)
class RigRun:
    """A batch run: commands, sensor readings and the rig's internal signals.

    Attributes
    ----------
    t_s, command_ma : numpy.ndarray
        Sample times (s) and commands (mA).
    position, pressure_pa, flow_g_s : numpy.ndarray
        Sensor readings.
    truth : dict of numpy.ndarray
        Noise-free internal signals (:data:`TRUTH_FIELDS`): hysteresis
        output, true position, supply pressure, ``p1``, true mass flow,
        noise-free sensor values...
    params : RigParams
        Parameters of the run.
    seed : int or None
        Noise seed.
    solver_failures : int
        Substeps whose Newton iteration hit its limit (0 expected).
    """

    t_s: np.ndarray
    command_ma: np.ndarray
    position: np.ndarray
    pressure_pa: np.ndarray
    flow_g_s: np.ndarray
    truth: dict
    params: RigParams
    seed: int | None = None
    solver_failures: int = 0

    def measurement(self, channel: str) -> np.ndarray:
        """Return the readings of ``channel`` (``position``, ``pressure`` or ``flow``)."""
        if channel not in CHANNELS:
            raise ConfigError(f'unknown channel {channel!r}; expected one of {CHANNELS}')
        return {'position': self.position, 'pressure': self.pressure_pa,
                'flow': self.flow_g_s}[channel]

    def unit(self, channel: str) -> str:
        """Return the unit of a channel's readings."""
        if channel == 'pressure' and self.params.pressure_sensor.reference == 'gauge':
            return 'Pa (gauge)'
        return UNITS[channel]

    def recording(self, channel: str) -> Recording:
        """Return the run as a :class:`~hyst_id.io.recording.Recording` of one channel."""
        return Recording(t_s=self.t_s.copy(), command=self.command_ma.copy(),
                         measurement=self.measurement(channel).copy(), channel=channel,
                         command_unit=UNITS['command'], measurement_unit=self.unit(channel),
                         source=f'rig simulator (seed {self.seed})')


def _check_inputs(t_s: np.ndarray, command_ma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = np.ascontiguousarray(t_s, dtype=np.float64)
    v = np.ascontiguousarray(command_ma, dtype=np.float64)
    if t.ndim != 1 or v.shape != t.shape or t.size == 0:
        raise RecordingError(f't_s and command_ma must be equal-length 1-D arrays, '
                             f'got {t.shape} and {v.shape}')
    if not (np.isfinite(t).all() and np.isfinite(v).all()):
        raise RecordingError('t_s and command_ma must be finite')
    if t.size > 1 and not (np.diff(t) > 0).all():
        raise RecordingError('t_s must be strictly increasing')
    return t, v


class RigSimulator:
    """Streaming rig for a real-time node: state is kept between :meth:`step` calls.

    Parameters
    ----------
    params : RigParams, mapping, path or None
        Rig parameters (see :func:`~hyst_id.rig.params_file.as_rig_params`);
        ``None`` for the defaults.
    seed : int, optional
        Noise seed (a ``numpy.random.Generator`` is accepted too).
    t0_s : float
        Time stamp of the first sample.

    Notes
    -----
    The first :meth:`step` initialises the rig at steady state for its
    command and returns sample 0 (its ``dt_s`` is ignored); every later
    call applies the command over the next ``dt_s`` seconds.
    """

    def __init__(self, params: RigParams | None = None, seed=None, t0_s: float = 0.0) -> None:
        self.params = as_rig_params(params)
        self.seed = seed
        self._rng = np.random.default_rng(seed)
        self._p = _pack(self.params)
        self._s = np.zeros(1, dtype=_S_DTYPE)
        self._buf = np.zeros((DELAY_CAPACITY, 2))
        self._t0_s = float(t0_s)

    @property
    def started(self) -> bool:
        """Whether the first sample has been produced."""
        return bool(self._s[0]['init'] > 0.5)

    @property
    def t_s(self) -> float:
        """Time of the last sample."""
        return self._t0_s + float(self._s[0]['t'])

    @property
    def solver_failures(self) -> int:
        """Substeps whose Newton iteration hit its limit so far."""
        return int(self._s[0]['n_fail'])

    def run(self, command_ma: np.ndarray, dt_s: np.ndarray) -> np.ndarray:
        """Advance over several samples; structured array of readings and truth."""
        v = np.ascontiguousarray(command_ma, dtype=np.float64).ravel()
        dt = np.ascontiguousarray(np.broadcast_to(dt_s, v.shape), dtype=np.float64)
        if not (np.isfinite(v).all() and np.isfinite(dt).all()):
            raise RecordingError('command and dt must be finite')
        later = dt[1:] if not self.started else dt
        if (later <= 0).any():
            raise RecordingError(f'dt_s must be > 0, got {float(later.min())}')
        z = self._rng.standard_normal((v.size, 6))
        out = np.zeros(v.size, dtype=_OUT_DTYPE)
        code = _advance(self._p, self._s, self._buf, v, dt, z, out)
        if code == 1:
            raise ConfigError(f'effects.dead_time.delay_s too long for the sample rate: more '
                              f'than {DELAY_CAPACITY} commands in flight')
        return out

    def step(self, command_ma: float, dt_s: float) -> RigSample:
        """Apply ``command_ma`` for ``dt_s`` seconds and read the sensors."""
        row = self.run(np.array([command_ma], dtype=float), np.array([dt_s], dtype=float))[0]
        truth = {k: float(row[k]) for k in TRUTH_FIELDS}
        return RigSample(t_s=self.t_s, command_ma=float(command_ma),
                         position=float(row['position']),
                         pressure_pa=float(row['pressure_pa']), flow_g_s=float(row['flow_g_s']),
                         truth=truth)


#: Most integration substeps one run may take: a bound that refuses a typo
#: (``max_substep_s=1e-12``) rather than integrating for hours. The integrator took 49 s per
#: 10^8 substeps on the development machine (a 2000 s run at 10 ms, 4 x 10^5 substeps, in
#: 0.19 s); a 10^4 s run at the default 5 ms substep takes 2 x 10^6.
MAX_SUBSTEPS = 10 ** 8


def simulate_rig(params: RigParams | None, t_s: np.ndarray, command_ma: np.ndarray,
                 seed=None) -> RigRun:
    """Simulate the rig for a command sampled at ``t_s`` (non-uniform allowed).

    Parameters
    ----------
    params : RigParams, mapping, path or None
        Rig parameters; ``None`` for the defaults (``params/pipeline.yaml``).
    t_s : numpy.ndarray
        Strictly increasing sample times, seconds.
    command_ma : numpy.ndarray
        Command per sample, mA, applied over the interval ending at that sample.
    seed : int, optional
        Noise seed; the same seed gives the same run.

    Returns
    -------
    RigRun
    """
    t, v = _check_inputs(t_s, command_ma)
    sim = RigSimulator(params, seed=seed, t0_s=float(t[0]))
    dt = np.concatenate([[0.0], np.diff(t)])
    max_sub = sim.params.integration.max_substep_s
    work = float(np.sum(np.ceil(dt / max_sub)))
    if work > MAX_SUBSTEPS:
        raise ConfigError(f'the run needs {work:.3g} integration substeps (samples over '
                          f'{t[-1] - t[0]:.6g} s, integration.max_substep_s {max_sub:g} s); at '
                          f'most {MAX_SUBSTEPS:.0e}: a shorter run or a longer substep')
    out = sim.run(v, dt)
    truth = _as_dict(out)
    return RigRun(t_s=t, command_ma=v, position=truth.pop('position'),
                  pressure_pa=truth.pop('pressure_pa'), flow_g_s=truth.pop('flow_g_s'),
                  truth=truth, params=sim.params, seed=seed,
                  solver_failures=sim.solver_failures)
