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

"""The package's shape holds: imports run one way between the stages, with no circles.

Every module of ``hyst_id`` is parsed (nothing is imported) and every
import of another hyst_id module, at module level or inside a function, is
an edge. The stages are ranked as ``docs/architecture.md`` draws them; a
module may import its own stage and the stages ranked below it, never a
stage ranked above or beside it. Only ``hyst_id/nodes`` imports ROS
(rclpy and message packages), and nodes never import the CLI's commands.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / 'hyst_id'

#: Stage -> rank. A module may import stages of a lower rank and its own stage.
RANKS = {
    'errors': 0, 'pins': 0, '_deprecated': 0,
    'checks': 1,
    'signals': 1,
    'io': 2,
    'models': 3, 'solvers': 3,
    'identification': 4,
    'compensation': 5, 'rig': 5,
    'diagnosis': 6,
    'experiment': 7, 'live': 7, 'fleet': 7,
    'commands': 8, 'nodes': 8,
    'cli': 9,
}
ROS_MODULES = ('rclpy', 'std_msgs', 'sensor_msgs', 'diagnostic_msgs', 'rcl_interfaces',
               'builtin_interfaces', 'rosgraph_msgs', 'std_srvs', 'hyst_id_interfaces',
               'lifecycle_msgs')


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix('')
    parts = list(rel.parts)
    if parts[-1] == '__init__':
        parts = parts[:-1]
    return '.'.join(parts)


MODULES = {module_name(p): p for p in sorted(PKG.rglob('*.py'))}


def stage(module: str) -> str:
    parts = module.split('.')
    return parts[1] if len(parts) > 1 else ''


def imports(path: Path) -> list[tuple[str, int]]:
    """Every imported module name (resolved to a hyst_id module where it is one)."""
    tree = ast.parse(path.read_text(encoding='utf-8'))
    me = module_name(path)
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                pkg = me.split('.')
                pkg = pkg[:len(pkg) - node.level + (1 if path.name == '__init__.py' else 0)]
                base = '.'.join(pkg + ([base] if base else []))
            for a in node.names:
                sub = f'{base}.{a.name}'
                out.append((sub if sub in MODULES else base, node.lineno))
    return out


def hyst_edges() -> dict[str, set[str]]:
    edges: dict[str, set[str]] = {m: set() for m in MODULES}
    for mod, path in MODULES.items():
        for name, _ in imports(path):
            while name and name not in MODULES and '.' in name:
                name = name.rsplit('.', 1)[0]
            if name in MODULES and name != mod and name.startswith('hyst_id.'):
                edges[mod].add(name)
    return edges


def test_every_stage_has_a_rank():
    stages = {stage(m) for m in MODULES if stage(m)}
    assert stages <= set(RANKS), f'stages without a rank: {sorted(stages - set(RANKS))}'


def test_imports_run_one_way_between_stages():
    bad = []
    for mod, targets in hyst_edges().items():
        a = stage(mod)
        if not a:
            continue                   # hyst_id/__init__.py: lazy public API only
        for t in targets:
            b = stage(t)
            if b and b != a and RANKS[b] >= RANKS[a]:
                bad.append(f'{mod} ({a}, rank {RANKS[a]}) imports {t} ({b}, rank {RANKS[b]})')
    assert not bad, '\n'.join(sorted(bad))


def test_no_import_circles():
    edges = hyst_edges()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in edges:
        if v not in index:
            visit(v)
    assert not cycles, f'import circles: {cycles}'


@pytest.mark.parametrize('mod', sorted(MODULES))
def test_ros_is_imported_only_by_the_nodes(mod):
    if stage(mod) == 'nodes':
        return
    ros = [f'{name} (line {line})' for name, line in imports(MODULES[mod])
           if name.split('.')[0] in ROS_MODULES]
    assert not ros, f'{mod} imports ROS: {ros}'


def test_nodes_do_not_borrow_the_cli():
    bad = [f'{m} -> {t}' for m, ts in hyst_edges().items() if stage(m) == 'nodes'
           for t in ts if stage(t) in ('commands', 'cli')]
    assert not bad, bad


def test_init_modules_hold_no_logic():
    """Package ``__init__`` files hold a docstring, imports, ``__all__`` and nothing else.

    The root package's lazy public API (PEP 562 ``__getattr__``) and the deprecated
    attribute forwarding of ``hyst_id.nodes`` are the two exceptions.
    """
    allowed_defs = {'hyst_id': {'__getattr__'}, 'hyst_id.nodes': {'__getattr__'}}
    bad = []
    for mod, path in MODULES.items():
        if path.name != '__init__.py':
            continue
        for node in ast.parse(path.read_text(encoding='utf-8')).body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                if node.name not in allowed_defs.get(mod, set()):
                    bad.append(f'{mod}: {node.name}')
            elif isinstance(node, (ast.For, ast.While, ast.If, ast.With, ast.Try)):
                bad.append(f'{mod}: a {type(node).__name__} statement at line {node.lineno}')
    assert not bad, bad


def test_modules_stay_small():
    """Modules under ~500 lines (the conventions); a few over by a little are listed."""
    big = {m: n for m, p in MODULES.items()
           if (n := len(p.read_text(encoding='utf-8').splitlines())) > 520}
    assert not big, big


@pytest.mark.parametrize('mod', sorted(m for m in MODULES if stage(m) != 'nodes'))
def test_all_is_the_real_public_api(mod):
    """``__all__`` lists names (strings) that the module defines, and it exists."""
    import importlib

    module = importlib.import_module(mod)
    names = getattr(module, '__all__', None)
    assert names is not None, f'{mod} has no __all__'
    assert all(isinstance(n, str) for n in names), f'{mod}.__all__ holds non-strings'
    missing = [n for n in names if not hasattr(module, n) and n != '__version__'
               and not (mod == 'hyst_id' and n in module._API)]
    assert not missing, f'{mod}.__all__ names what it lacks: {missing}'
