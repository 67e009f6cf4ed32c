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

"""A new hysteresis family is one module: the smallest one (a single play) plugs in end to end.

The family below is the example of ``docs/model.md`` ("Adding a hysteresis
family"): ``H(v) = m_p * F_r[v] + c_p`` with ``F_r`` the play operator of
half width ``r_p``. Registered for the test (the one registry line), it is
identified from a simulated recording by the unchanged ``identify()`` and
inverted in-line by the unchanged ``Compensator``.
"""

from __future__ import annotations

from numba import njit
import numpy as np
import pytest

from hyst_id.compensation import Compensator, InverseModel
from hyst_id.errors import InvalidParametersError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.domains import domains_from_data
from hyst_id.io.recording import Recording
from hyst_id.models import registry
from hyst_id.models.family import HysteresisFamily, HysteresisInverse, LoopBox

__all__: list[str] = []


@njit
def _feasible_rows(pop):
    ok = np.empty(pop.shape[0], dtype=np.bool_)
    for i in range(pop.shape[0]):
        ok[i] = pop[i, 0] > 0.0 and pop[i, 1] >= 0.0 and np.isfinite(pop[i, 2])
    return ok


@njit
def _simulate_rows(pop, v, ok, out):
    for i in range(pop.shape[0]):
        if not ok[i]:
            continue
        m, r, c = pop[i, 0], pop[i, 1], pop[i, 2]
        z = v[0] - r                                  # rising boundary
        for j in range(v.shape[0]):
            z = max(v[j] - r, min(v[j] + r, z))
            out[i, j] = m * z + c


class PlayInverse(HysteresisInverse):
    def __init__(self, p):
        self.m, self.r, self.c = (float(x) for x in p)
        self.reset(0.0)

    def reset(self, v0, u0=None):
        self.v = float(v0)
        z = self.v - self.r
        if u0 is not None:
            z = min(max((float(u0) - self.c) / self.m, self.v - self.r), self.v + self.r)
        self.z = z

    @property
    def command(self):
        return self.v

    @property
    def output(self):
        return self.m * self.z + self.c

    def command_for(self, u_d):
        z_d = (u_d - self.c) / self.m
        if z_d > self.z:
            return z_d + self.r
        if z_d < self.z:
            return z_d - self.r
        return self.v

    def advance(self, v):
        self.v = float(v)
        self.z = max(self.v - self.r, min(self.v + self.r, self.z))
        return self.output


class Play(HysteresisFamily):
    id = 'play'  # noqa: A003
    title = 'a single play operator'
    names = ('m_p', 'r_p', 'c_p')
    units = {'m_p': 'out/cmd', 'r_p': 'cmd', 'c_p': 'out'}

    def check(self, params):
        p = np.asarray(params, dtype=float).ravel()
        if p.shape[0] != 3 or not np.all(np.isfinite(p)) or not (p[0] > 0 and p[1] >= 0):
            raise InvalidParametersError('play needs m_p > 0, r_p >= 0')
        return p

    def feasible_rows(self, pop):
        return _feasible_rows(np.ascontiguousarray(pop, dtype=np.float64))

    def simulate_rows(self, pop, v, ok, out):
        _simulate_rows(pop, v, ok, out)

    def map_output(self, params, alpha, delta):
        m, r, c = params
        return np.array([alpha * m, r, alpha * c + delta])

    def domains(self, box: LoopBox):
        m_hi = box.steep * box.slope
        return {'m_p': (0.0, m_hi), 'r_p': (0.0, 0.5 * box.span_v),
                'c_p': (box.u_lo - m_hi * max(abs(box.v_lo), abs(box.v_hi)),
                        box.u_hi + m_hi * max(abs(box.v_lo), abs(box.v_hi)))}

    def starts(self, box, width=None):
        w = box.loop_width if width is None else width
        u_mid, v_mid = 0.5 * (box.u_lo + box.u_hi), 0.5 * (box.v_min + box.v_max)
        return [np.array([box.slope, 0.5 * w, u_mid - box.slope * v_mid])]

    def inverse(self, params):
        return PlayInverse(self.check(params))


PLAY = Play()


@pytest.fixture
def play_registered(monkeypatch):
    monkeypatch.setitem(registry.FAMILIES, 'play', PLAY)   # the one registry line
    return PLAY


def _recording(seed: int = 0) -> Recording:
    t = np.arange(0.0, 100.0, 0.05)
    v = 3.0 + 2.0 * np.sin(2 * np.pi * t / 10.0) * np.exp(-t / 200.0)
    x = np.array([[2.0, 0.4, 1.0]])
    u = np.empty((1, t.size))
    PLAY.simulate_rows(x, v, np.ones(1, dtype=np.bool_), u)
    y = 25.0 * u[0] - 7.0 + np.random.default_rng(seed).normal(0.0, 0.02, t.size)
    return Recording(t, v, y, 'position', 'V', 'um', 'play test')


def test_a_registered_family_is_identified_to_the_noise_floor(play_registered):
    rec = _recording()
    spec = domains_from_data(rec, family='play')
    assert spec.names[:3] == ('m_p', 'r_p', 'c_p')
    ident = identify(rec, spec=spec, settings=IdentifySettings(seeds=(0, 1), maxiter=100,
                                                               workers=1))
    assert ident.family == 'play'
    assert ident.er_percent < 1.1 * ident.noise_floor_percent
    # the play's width and the backlash's add up: together they are the true 0.4 V
    width = ident.params['r_p'] + ident.params['c_br'] / ident.params['m_p']
    assert width == pytest.approx(0.4, rel=0.05)


def test_a_registered_family_is_inverted_in_line(play_registered):
    model = InverseModel.from_mapping({'family': 'play', 'm_p': 2.0, 'r_p': 0.4, 'c_p': 1.0,
                                       'm_bl': 1.0, 'c_bl': -0.1, 'c_br': 0.1})
    comp = Compensator(model, v0=3.0)
    desired = 7.0 + 2.0 * np.sin(np.linspace(0.0, 12.0, 400))
    v = comp.run(desired)
    # the actuator: the same play and backlash, started in the compensator's state
    act = PLAY.inverse(np.array([2.0, 0.4, 1.0]))
    act.reset(3.0)
    y = 1.0 * (act.output - 0.1)
    out = []
    for vj in v:
        u = act.advance(vj)
        y = min(max(y, u - 0.1), u + 0.1)
        out.append(y)
    np.testing.assert_allclose(out[1:], desired[1:], atol=1e-9)
