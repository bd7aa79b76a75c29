"""The house: the import graph of the project's packages, read from the source, has no cycle
and no arrow from a lower layer to a higher one.

Every ``import`` / ``from ... import`` statement counts wherever it sits: at module level, in
a function (a lazy import does not hide a dependency), under ``if TYPE_CHECKING:``.  An edge
goes to the module named, or to ``pkg.name`` when ``from pkg import name`` names a submodule.

Layers, lowest first (a module may import from its own layer and the layers below):

====  ==============================================================================
0     ``geometry`` -- exact regions from the scene (paper sections 3-5)
1     ``sensorplan_gym`` -- the envs on the batched core, the viewer
2     ``agents.planning`` -- the analytic oracle (placement, motion, aim, recognition);
      ``agents.checks`` (checks of user input, imports nothing of the project)
3     ``agents.learning`` -- SB3/RLlib training and loading any policy
4     ``agents.evaluation`` -- episodes, the benchmark protocol, statistics, Ray backend
5     ``agents`` (the package facade), ``agents.__main__``, ``agents.cli``, ``agents.demo``
6     ``benchmarks`` -- measurements of everything above
====  ==============================================================================

Inside ``sensorplan_gym``, ``sensorplan_gym.core`` (the batched simulation core) imports
nothing else of ``sensorplan_gym``.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("geometry", "sensorplan_gym", "agents", "benchmarks")
LAYERS = (
    ("geometry",),
    ("sensorplan_gym",),
    ("agents.planning", "agents.checks"),
    ("agents.learning",),
    ("agents.evaluation",),
    ("agents", "agents.__main__", "agents.cli", "agents.demo"),
    ("benchmarks",),
)


def _modules() -> dict[str, Path]:
    """Every module of :data:`PACKAGES`: dotted name -> file (``pkg/__init__.py`` is ``pkg``)."""
    out = {}
    for pkg in PACKAGES:
        for f in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(f.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = f
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The project modules that module ``name`` (file ``path``) imports anywhere in its body."""
    is_pkg = path.name == "__init__.py"
    here = name if is_pkg else name.rpartition(".")[0]
    found: set[str] = set()

    def add(target: str) -> None:
        # the longest project module that ``target`` names (a.b.func -> a.b)
        while target and target not in modules:
            target = target.rpartition(".")[0]
        if target and target != name:
            found.add(target)

    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            for alias in node.names:
                sub = f"{mod}.{alias.name}"
                add(sub if sub in modules else mod)
    return found


def import_graph() -> dict[str, set[str]]:
    """Module -> the project modules it imports (see the module docstring)."""
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def layer(module: str) -> int:
    """The layer index of ``module`` (:data:`LAYERS`): its longest matching prefix's."""
    best, best_len = None, -1
    for i, prefixes in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best_len:
                # agents.cli and agents.demo are exact names; "agents" alone is the facade
                if p == "agents" and module != "agents":
                    continue
                best, best_len = i, len(p)
    if best is None:
        raise AssertionError(f"module {module} is in no layer of tests/test_imports.py")
    return best


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every strongly connected component with more than one module, or a self-import
    (Tarjan's algorithm), each as a sorted list of modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
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
            if len(comp) > 1 or v in graph.get(v, ()):
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_graph_is_read_from_the_source():
    g = import_graph()
    # a module-level, a function-level and a relative import the graph must see
    assert "geometry.scene" in g["geometry"]
    assert "agents.evaluation.stats" in g["agents.evaluation.evaluate"]
    assert "agents.learning.train" in g["agents.cli"]  # imported inside main()
    assert {"geometry", "sensorplan_gym", "agents", "benchmarks"} <= set(g)


def test_cycles_and_layers_are_detected():
    """The checks can fail: a planted cycle and a planted upward import are found."""
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"a"}}) == [["a"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    assert layer("sensorplan_gym.viewer.replay") < layer("agents.planning.oracle")
    assert layer("agents.planning.watch_oracle") < layer("agents.learning.rllib_train")
    assert layer("agents.learning.policies") < layer("agents.evaluation.evaluate")
    assert layer("agents.evaluation.evaluate") < layer("agents.cli") == layer("agents")


def test_no_import_cycle():
    found = cycles(import_graph())
    assert not found, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in found)


def test_no_import_from_a_lower_layer_to_a_higher_one():
    up = [
        f"{a} (layer {layer(a)}) imports {b} (layer {layer(b)})"
        for a, targets in sorted(import_graph().items())
        for b in sorted(targets)
        if layer(b) > layer(a)
    ]
    assert not up, "upward imports:\n" + "\n".join(up)


def test_the_core_imports_nothing_above_it():
    bad = [
        f"{a} imports {b}"
        for a, targets in sorted(import_graph().items())
        if a.startswith("sensorplan_gym.core")
        for b in sorted(targets)
        if b.startswith("sensorplan_gym") and not b.startswith("sensorplan_gym.core")
    ]
    assert not bad, "\n".join(bad)


def test_every_module_has_a_layer():
    for module in sorted(_modules()):
        assert 0 <= layer(module) < len(LAYERS), module  # layer() raises for an unknown one
