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

"""Pneumatics of the rig: compressible orifice flow, vessel blow-down, pipe volume.

Two restrictions in series (see ``docs/rig.md``)::

    vessels p_s --[manual valve A_m, b_m]--> pipe V_1, p_1 --[control valve A_v(x), b_v]--> p_a

Mass flow through a restriction of effective area ``A`` from ``p_u`` to
``p_d`` (``r = p_d/p_u``), upstream temperature ``T_u``::

    W = A p_u psi* / sqrt(R T_u) * phi(r)
    psi* = sqrt(gamma) (2/(gamma+1))^((gamma+1)/(2(gamma-1)))

``psi*`` makes ``A`` the area of an ideal isentropic nozzle at choking.
``phi = 1`` when choked (``r <= b``); above ``b`` it is ISO 6358's ellipse
``sqrt(1 - ((r - b)/(1 - b))^2)`` (``iso6358``) or the isentropic
Saint-Venant law normalised at its own critical ratio (``saint_venant``);
above ``r = 0.999`` a linear (laminar) tail to ``phi(1) = 0`` keeps the slope
finite. ``phi`` is continuous everywhere (C1 at ``b``). Reverse flow uses
the same law with the ends swapped.

Vessels (polytropic blow-down ``p ~ rho^n``, ``n = 1`` isothermal) and the
pipe (isothermal at ambient temperature) are integrated as masses with
backward Euler: unconditionally stable, and mass is conserved exactly
(to the Newton tolerance), since every flow leaves one volume and enters
the next within the same step.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

__all__ = [
    'PSI_PA',
    'US_GALLON_M3',
    'STANDARD_ATMOSPHERE_PA',
    'FLOW_MODELS',
    'LAMINAR_RATIO',
    'choked_coefficient',
    'isentropic_critical_ratio',
    'flow_factor',
    'mass_flow',
    'vessel_mass',
    'regulator_flow',
    'pneumatic_step',
    'steady_p1',
    'steady_state',
    'orifice_mass_flow_kg_s',
    'manual_valve_area_m2',
]

PSI_PA = 6894.757293168361
US_GALLON_M3 = 0.003785411784
STANDARD_ATMOSPHERE_PA = 101325.0
FLOW_MODELS = ('iso6358', 'saint_venant')
LAMINAR_RATIO = 0.999


@njit(cache=True, inline='always')
def choked_coefficient(gamma: float) -> float:
    """``psi*`` of an ideal nozzle: ``W = A p_u psi*/sqrt(R T_u)`` when choked."""
    return math.sqrt(gamma) * (2.0 / (gamma + 1.0)) ** ((gamma + 1.0) / (2.0 * (gamma - 1.0)))


@njit(cache=True, inline='always')
def isentropic_critical_ratio(gamma: float) -> float:
    """Critical pressure ratio ``(2/(gamma+1))^(gamma/(gamma-1))`` (0.528 for air)."""
    return (2.0 / (gamma + 1.0)) ** (gamma / (gamma - 1.0))


@njit(cache=True)
def _phi_subsonic(r, b, model, gamma):
    if model == 1:
        g = r ** (2.0 / gamma) - r ** ((gamma + 1.0) / gamma)
        gc = b ** (2.0 / gamma) - b ** ((gamma + 1.0) / gamma)
        phi = math.sqrt(max(g, 0.0) / gc)
        dg = ((2.0 / gamma) * r ** (2.0 / gamma - 1.0)
              - ((gamma + 1.0) / gamma) * r ** (1.0 / gamma))
        return phi, (dg / (2.0 * phi * gc) if phi > 0.0 else 0.0)
    x = (r - b) / (1.0 - b)
    phi = math.sqrt(max(1.0 - x * x, 0.0))
    return phi, (-x / ((1.0 - b) * phi) if phi > 0.0 else 0.0)


@njit(cache=True)
def flow_factor(r: float, b: float, model: int, gamma: float) -> tuple[float, float]:
    """Flow factor ``phi(r)`` and ``dphi/dr`` for ``0 <= r <= 1``.

    Parameters
    ----------
    r : float
        Pressure ratio ``p_d/p_u``.
    b : float
        Critical pressure ratio (``iso6358``; ``saint_venant`` uses its own).
    model : int
        0 ``iso6358``, 1 ``saint_venant``.
    gamma : float
        Ratio of specific heats.
    """
    if model == 1:
        b = isentropic_critical_ratio(gamma)
    if r <= b:
        return 1.0, 0.0
    if r < LAMINAR_RATIO:
        return _phi_subsonic(r, b, model, gamma)
    phi_l = _phi_subsonic(LAMINAR_RATIO, b, model, gamma)[0]
    slope = phi_l / (1.0 - LAMINAR_RATIO)
    return max(slope * (1.0 - r), 0.0), -slope


@njit(cache=True)
def mass_flow(area_m2: float, p_a_pa: float, p_b_pa: float, t_a_k: float, t_b_k: float,
              b: float, model: int, gamma: float, r_gas: float) -> tuple[float, float, float]:
    """Mass flow from end ``a`` to end ``b`` (kg/s, negative when reversed).

    Returns
    -------
    tuple of float
        ``(W, dW/dp_a, dW/dp_b)``.
    """
    if area_m2 <= 0.0 or (p_a_pa <= 0.0 and p_b_pa <= 0.0):
        return 0.0, 0.0, 0.0
    forward = p_a_pa >= p_b_pa
    p_u, p_d, t_u = (p_a_pa, p_b_pa, t_a_k) if forward else (p_b_pa, p_a_pa, t_b_k)
    k = area_m2 * choked_coefficient(gamma) / math.sqrt(r_gas * t_u)
    r = p_d / p_u
    phi, dphi = flow_factor(r, b, model, gamma)
    w = k * p_u * phi
    dw_du = k * (phi - r * dphi)
    dw_dd = k * dphi
    if forward:
        return w, dw_du, dw_dd
    return -w, -dw_dd, -dw_du


@njit(cache=True, inline='always')
def vessel_mass(p_pa: float, volume_m3: float, n_poly: float, p_ref_pa: float,
                t_ref_k: float, r_gas: float) -> tuple[float, float, float]:
    """Mass, ``dm/dp`` and temperature of a polytropic volume at pressure ``p_pa``.

    ``T = T_ref (p/p_ref)^((n-1)/n)``, so ``m = p V/(R T)`` and ``dm/dp = m/(n p)``.
    """
    t_k = t_ref_k * (p_pa / p_ref_pa) ** ((n_poly - 1.0) / n_poly)
    m = p_pa * volume_m3 / (r_gas * t_k)
    return m, m / (n_poly * p_pa), t_k


@njit(cache=True, inline='always')
def regulator_flow(p_s_pa: float, setpoint_pa: float, gain_kg_s_pa: float,
                   max_kg_s: float) -> tuple[float, float]:
    """Compressor/regulator inflow ``clip(K (p_set - p_s), 0, W_max)`` and its slope."""
    w = gain_kg_s_pa * (setpoint_pa - p_s_pa)
    if w <= 0.0:
        return 0.0, 0.0
    if w >= max_kg_s:
        return max_kg_s, 0.0
    return w, -gain_kg_s_pa


@njit(cache=True)
def _flows(p_s, p1, a_m, a_v, g):
    """Flows and slopes at ``(p_s, p1)``; ``g`` packs the constant parameters."""
    (b_m, b_v, model, gamma, r_gas, t0, p_amb, v_s, n_poly, p_ref, v1,
     reg_on, p_set, k_reg, w_reg_max, w_comp) = g
    m_s, dms, t_s = vessel_mass(p_s, v_s, n_poly, p_ref, t0, r_gas)
    wm, wm_s, wm_1 = mass_flow(a_m, p_s, p1, t_s, t0, b_m, model, gamma, r_gas)
    wv, wv_1, _ = mass_flow(a_v, p1, p_amb, t0, t0, b_v, model, gamma, r_gas)
    if reg_on:
        wr, wr_s = regulator_flow(p_s, p_set, k_reg, w_reg_max)
    else:
        wr, wr_s = w_comp, 0.0
    return m_s, dms, wm, wm_s, wm_1, wv, wv_1, wr, wr_s


@njit(cache=True)
def pneumatic_step(p_s: float, p1: float, h_s: float, a_m: float, a_v: float,
                   g: tuple) -> tuple[float, float, float, float, float, bool]:
    """Advance vessel and pipe pressures by ``h_s`` with backward Euler (Newton).

    Parameters
    ----------
    p_s, p1 : float
        Vessel and pipe pressures now, Pa (absolute).
    h_s : float
        Step, seconds.
    a_m, a_v : float
        Effective areas of the manual and the control valve, m^2.
    g : tuple
        ``(b_m, b_v, model, gamma, R, T0, p_amb, V_s, n, p_ref, V_1, regulation,
        p_set, K_reg, W_reg_max, W_compressor)``.

    Returns
    -------
    tuple
        ``(p_s, p1, W_supply_in, W_manual, W_valve, converged)``, flows in kg/s
        evaluated at the new pressures (so mass is conserved step by step).
    """
    r_gas, t0, v1 = g[4], g[5], g[10]
    c1 = v1 / (r_gas * t0)
    m_s0 = _flows(p_s, p1, a_m, a_v, g)[0]
    m_10 = c1 * p1
    x_s, x_1 = p_s, p1
    converged = False
    for _ in range(60):
        m_s, dms, wm, wm_s, wm_1, wv, wv_1, wr, wr_s = _flows(x_s, x_1, a_m, a_v, g)
        r_s = m_s - m_s0 - h_s * (wr - wm)
        r_1 = c1 * x_1 - m_10 - h_s * (wm - wv)
        j11 = dms - h_s * (wr_s - wm_s)
        j12 = h_s * wm_1
        j21 = -h_s * wm_s
        j22 = c1 - h_s * (wm_1 - wv_1)
        det = j11 * j22 - j12 * j21
        d_s = (r_s * j22 - j12 * r_1) / det
        d_1 = (j11 * r_1 - j21 * r_s) / det
        lam = 1.0
        while x_s - lam * d_s <= 0.0 or x_1 - lam * d_1 <= 0.0:
            lam *= 0.5
        x_s -= lam * d_s
        x_1 -= lam * d_1
        if abs(d_s) <= 1e-10 * x_s and abs(d_1) <= 1e-10 * x_1:
            converged = True
            break
    m_s, dms, wm, wm_s, wm_1, wv, wv_1, wr, wr_s = _flows(x_s, x_1, a_m, a_v, g)
    return x_s, x_1, wr, wm, wv, converged


@njit(cache=True)
def steady_p1(p_s: float, a_m: float, a_v: float, g: tuple) -> float:
    """Pipe pressure where the manual-valve inflow equals the control-valve outflow."""
    lo, hi = g[6], max(p_s, g[6])
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        f = _flows(p_s, mid, a_m, a_v, g)
        if f[2] - f[5] > 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return 0.5 * (lo + hi)


@njit(cache=True)
def steady_state(p_s_initial: float, a_m: float, a_v: float, g: tuple) -> tuple[float, float]:
    """Equilibrium ``(p_s, p1)``: with regulation the supply too, else ``p_s`` given."""
    if not g[11]:
        return p_s_initial, steady_p1(p_s_initial, a_m, a_v, g)
    lo, hi = g[6], g[12]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        p1 = steady_p1(mid, a_m, a_v, g)
        f = _flows(mid, p1, a_m, a_v, g)
        if f[7] - f[5] > 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    p_s = 0.5 * (lo + hi)
    return p_s, steady_p1(p_s, a_m, a_v, g)


def orifice_mass_flow_kg_s(area_m2, p_up_pa, p_down_pa, *, temperature_k: float = 293.15,
                           critical_ratio: float = 0.528, model: str = 'iso6358',
                           gamma: float = 1.4, r_j_kg_k: float = 287.05) -> np.ndarray:
    """Mass flow through a restriction (vectorised over the pressures), kg/s.

    Parameters
    ----------
    area_m2 : float or array_like
        Effective area.
    p_up_pa, p_down_pa : float or array_like
        Absolute pressures at the two ends; flow is negative when reversed.
    temperature_k : float
        Temperature of the gas on the upstream side.
    critical_ratio : float
        ISO 6358 ``b`` (ignored by ``saint_venant``).
    model : str
        One of :data:`FLOW_MODELS`.
    """
    code = FLOW_MODELS.index(model)
    a, pu, pd = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                      for x in (area_m2, p_up_pa, p_down_pa)))
    out = np.empty(a.shape)
    for i in np.ndindex(a.shape):
        out[i] = mass_flow(a[i], pu[i], pd[i], temperature_k, temperature_k, critical_ratio,
                           code, gamma, r_j_kg_k)[0]
    return out


def manual_valve_area_m2(p_s_pa: float, p1_pa: float, flow_kg_s: float, *,
                         temperature_k: float = 293.15, critical_ratio: float = 0.25,
                         model: str = 'iso6358', gamma: float = 1.4,
                         r_j_kg_k: float = 287.05) -> float:
    """Effective area that passes ``flow_kg_s`` from ``p_s_pa`` to ``p1_pa``.

    How the manual valve is "set to hold 30 psig": the area that gives the
    wanted pipe pressure at the nominal flow.
    """
    unit = orifice_mass_flow_kg_s(1.0, p_s_pa, p1_pa, temperature_k=temperature_k,
                                  critical_ratio=critical_ratio, model=model, gamma=gamma,
                                  r_j_kg_k=r_j_kg_k)
    return float(flow_kg_s / unit)
