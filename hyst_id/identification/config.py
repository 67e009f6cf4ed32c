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

"""Build a chain spec and identification settings from plain values (CLI, nodes, fleet).

One place turns what a user gives (``--domains auto|paper|FILE``, seed
counts, generations, ...) into a :class:`~hyst_id.identification.chains.ChainSpec`
and :class:`~hyst_id.identification.result.IdentifySettings`, with one-line errors,
so that ``hyst-id identify`` and the identifier node build them alike.
"""

from __future__ import annotations

from collections.abc import Mapping
import math

from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec, ChainSpec
from hyst_id.identification.domains import AUTO, domains_from_data, preset_spec, PRESETS
from hyst_id.identification.result import IdentifySettings
from hyst_id.io.params_file import read_yaml
from hyst_id.io.recording import Recording
from hyst_id.models.registry import DEFAULT_FAMILY, get_family
from hyst_id.solvers.gaass import check_rates

__all__ = ['check_domains_file', 'make_settings', 'make_spec', 'MAX_GENERATIONS', 'MAX_HOPS',
           'MAX_POP_SIZE', 'MAX_SEEDS', 'read_domains_file']


#: Largest GAASS population and number of seeds accepted (the paper's are 10 and 10): a
#: review's --pop-size 100000000 was killed by the kernel for memory without a word.
MAX_POP_SIZE = 10_000
MAX_SEEDS = 10_000
#: Most generations and basin-hopping jumps accepted (the paper's 500 and the default 100):
#: a review's --generations 10^7 took 2.3 GB up front and 10^8 ended in a MemoryError, and
#: --hops 2^31 - 1 in one of 176 GiB.
MAX_GENERATIONS = 1_000_000
MAX_HOPS = 100_000


def make_settings(*, seeds: int = 10, seed_offset: int = 0, pop_size: int = 10,
                  generations: int = 500, c: float = 0.007, xi: float = 0.02,
                  workers: int = 0, refine: bool = True, restarts: int = 4,
                  er_bound_percent: float | None = None,
                  global_evals: int = 200000, global_runs: int = 14, hops: int = 100,
                  search_samples: int = 20000, more_starts: bool = False,
                  start_state: bool = True, loose_loops: bool = True) -> IdentifySettings:
    """GAASS and refinement settings (the paper's by default), checked.

    Raises
    ------
    ConfigError
        Fewer than one seed or generation, a population below two, negative restarts,
        global evaluations, runs or hops, search samples or workers, an %e_r bound <= 0,
        a contraction rate ``c`` that is not a finite number > 0 or a ``xi`` outside
        (0, 1] (checked here as GAASS checks them, before any work is printed or done).
    """
    check_rates(c, xi, ('the contraction rate c (--c)', 'xi (--xi)'))
    if seeds < 1 or pop_size < 2 or generations < 1 or restarts < 0 or global_evals < 0 \
            or global_runs < 0 or hops < 0 or search_samples < 0:
        raise ConfigError('need seeds >= 1, pop size >= 2, generations >= 1, restarts >= 0, '
                          'global evaluations and runs >= 0, hops >= 0 and search samples '
                          '>= 0')
    if seed_offset < 0:
        raise ConfigError(f'the first seed must be >= 0, got {seed_offset}')
    if workers < 0:
        raise ConfigError(f'workers must be >= 0 (0: one per core), got {workers}')
    if er_bound_percent is not None and not 0.0 < er_bound_percent < math.inf:
        raise ConfigError(f'the %e_r bound (--er-bound) must be a finite number > 0 (or none), '
                          f'got {er_bound_percent}')
    if pop_size > MAX_POP_SIZE or seeds > MAX_SEEDS or generations > MAX_GENERATIONS \
            or hops > MAX_HOPS:                          # refused, not killed for memory
        raise ConfigError(f'need pop size <= {MAX_POP_SIZE}, seeds <= {MAX_SEEDS}, generations '
                          f'<= {MAX_GENERATIONS} and hops <= {MAX_HOPS}; got {pop_size}, '
                          f'{seeds}, {generations} and {hops}')
    return IdentifySettings(
        pop_size=int(pop_size), maxiter=int(generations), c=float(c), xi=float(xi),
        seeds=tuple(range(int(seed_offset), int(seed_offset) + int(seeds))),
        workers=int(workers), refine=bool(refine), restarts=int(restarts),
        er_bound_percent=er_bound_percent, global_evals=int(global_evals),
        global_runs=int(global_runs), hops=int(hops),
        search_samples=int(search_samples), more_starts=bool(more_starts),
        start_state=bool(start_state), loose_loops=bool(loose_loops))


def read_domains_file(path: str) -> dict[str, tuple[float, float]]:
    """Search domains from a YAML file: ``name: [low, high]`` (optionally under ``domains:``)."""
    data = read_yaml(path, 'domains file') or {}
    data = data.get('domains', data) if isinstance(data, Mapping) else data
    if isinstance(data, Mapping) and not data:     # it had been taken as auto without a word
        raise ConfigError(f'domains file {path} names no parameter (for domains from the '
                          "data give 'auto')")
    if not isinstance(data, Mapping):
        raise ConfigError(f'domains file {path} must map parameter names to [low, high]')
    bad = [str(k) for k, v in data.items() if not (isinstance(v, (list, tuple)) and len(v) == 2)]
    if bad:          # [0, 1, 2] had been read as [0, 1]
        raise ConfigError(f'domains file {path}: each entry must be [low, high]; not so: '
                          f'{", ".join(bad)}')
    try:
        return {str(k): (float(v[0]), float(v[1])) for k, v in data.items()}
    except (TypeError, ValueError):
        raise ConfigError(f'domains file {path}: each entry must be [low, high]') from None


def check_domains_file(path: str, channel: str, family: str | None = None) -> None:
    """Check a domains file before a recording exists: readable, known names, low < high.

    What :func:`make_spec` would refuse later, said when the file is named
    (a node's ``domains`` parameter), not after a run was collected.

    Raises
    ------
    ConfigError
        The file cannot be read, names a parameter the ``channel``'s chain of
        ``family`` does not have, or an entry is not ``[low, high]`` with
        finite ``low < high``.
    """
    try:
        chain_spec(channel, read_domains_file(path), family=family)
    except ConfigError as exc:
        text = str(exc)
        raise ConfigError(text if str(path) in text else f'domains file {path}: {text}') from None


def make_spec(rec: Recording, domains: str | Mapping = AUTO,
              family: str | None = None) -> ChainSpec:
    """Chain spec for a recording with the search domains asked for.

    Parameters
    ----------
    rec : Recording
        The recording to identify.
    domains : str or mapping
        ``'auto'`` (derived from the data), a preset name (``'paper'``), a
        YAML file of overrides, or a mapping ``name -> (low, high)`` of overrides.
    family : str, optional
        H's family (default ``tk``, the paper's). Presets hold ``tk`` domains only.
    """
    fam = get_family(family)
    if isinstance(domains, Mapping):
        return domains_from_data(rec, overrides=domains, family=fam)
    if domains == AUTO:
        return domains_from_data(rec, family=fam)
    if domains in PRESETS:
        if fam.id != DEFAULT_FAMILY:
            raise ConfigError(f'the {domains!r} domain preset is for the {DEFAULT_FAMILY!r} '
                              f'family, not {fam.id!r}; use auto or a YAML file')
        return preset_spec(domains, rec.channel)
    return domains_from_data(rec, overrides=read_domains_file(domains), family=fam)
