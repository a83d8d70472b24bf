"""The shape of the core that docs/ARCHITECTURE.md promises: read from the source, no imports run.

- no module of texsynth/ imports another of ours inside a function body (each module states its
  dependencies at the top, and importing one never hides a cycle);
- the imports among texsynth/'s modules form no cycle (a package's ``__init__`` re-exporting its
  own submodules is not a cycle: those submodules never import it back);
- the core never imports bpy;
- imports run down the layers the page draws (``LAYERS``), sideways only where it names the case;
- every method is registered from its own home under texsynth/algorithms/;
- outside tests/, no module imports or reaches a private name (``_x``) of another of ours
  (the core, the operators, the benchmarks): a name another module uses is public in its home.
"""

import ast
from pathlib import Path

import texsynth

CORE = Path(texsynth.__file__).parent
REPO = CORE.parent


def _module_name(path: Path) -> str:
    parts = path.relative_to(CORE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    base = module.split(".") if is_package else module.split(".")[:-1]
    if node.level:
        base = base[: len(base) - node.level + 1]
        return ".".join(base + ([node.module] if node.module else []))
    return node.module or ""


def _imports():
    """(module, imported module, inside a function?, line) for every import of the core."""
    modules = {_module_name(p): p for p in CORE.rglob("*.py")}
    found = []
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        in_function = set()
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                in_function.update(id(n) for n in ast.walk(node) if n is not node)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _resolve(name, path.name == "__init__.py", node)
                targets = [f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target
                           for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            for t in targets:
                found.append((name, t, id(node) in in_function, node.lineno))
    return modules, found


def test_no_project_imports_inside_functions():
    _, found = _imports()
    inside = [f"{m}:{line} imports {t}" for m, t, in_function, line in found
              if in_function and t.split(".")[0] == "texsynth"]
    assert not inside, "\n".join(inside)


def test_the_core_never_imports_blender():
    _, found = _imports()
    assert not [m for m, t, _, _ in found if t.split(".")[0] in ("bpy", "mathutils")]


def test_no_import_cycles():
    modules, found = _imports()
    graph = {m: set() for m in modules}
    for m, t, _, _ in found:
        if t in modules and t != m and not (m.startswith(t + ".") and modules[t].name ==
                                               "__init__.py"):
            graph[m].add(t)
    # a package's own __init__ importing its submodules is fine; drop those edges to the parent
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycle = stack[stack.index(nxt):] + [nxt]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node)


def test_every_method_lives_under_algorithms():
    for method in texsynth.methods():
        assert method.function.__module__.startswith("texsynth.algorithms."), method.name


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _private_uses(name: str, path: Path, modules: dict) -> list[str]:
    """``from ours import _x`` and ``ours._x`` (through any chain of our modules) in ``path``."""
    tree = ast.parse(path.read_text())
    bound, uses = {}, []   # local name -> the module of ours it stands for
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = name.split(".") if name else []
            if node.level:
                base = base[: len(base) - (path.name != "__init__.py") - node.level + 1]
            target = ".".join((base if node.level else []) + ([node.module] if node.module else []))
            if not any(m == target or m.startswith(target + ".") for m in modules):
                continue
            for alias in node.names:
                if _private(alias.name):
                    uses.append(f"{path.relative_to(REPO)}:{node.lineno} imports "
                                f"{target}.{alias.name}")
                if f"{target}.{alias.name}".lstrip(".") in modules:
                    bound[alias.asname or alias.name] = f"{target}.{alias.name}".lstrip(".")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] in {m.split(".")[0] for m in modules if m}:
                    bound[alias.asname or alias.name.split(".")[0]] = (
                        alias.name if alias.asname else alias.name.split(".")[0])
    for node in ast.walk(tree):
        if not isinstance(node, ast.Attribute):
            continue
        chain, value = [node.attr], node.value
        while isinstance(value, ast.Attribute):
            chain.insert(0, value.attr)
            value = value.value
        if not (isinstance(value, ast.Name) and value.id in bound and _private(node.attr)):
            continue
        module = bound[value.id]
        for i, part in enumerate(chain):
            if _private(part):
                if module != name:
                    uses.append(f"{path.relative_to(REPO)}:{node.lineno} reaches "
                                f"{module}.{part} ({value.id}.{'.'.join(chain[:i + 1])})")
                break
            if f"{module}.{part}" not in modules:
                break
            module = f"{module}.{part}"
    return uses


def test_no_private_names_across_modules():
    def name(path):
        parts = path.relative_to(REPO).with_suffix("").parts
        return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)

    def ours(path):  # not the tests, nor venvs, caches and build output (hidden or named so)
        parts = path.relative_to(REPO).parts
        return not any(part.startswith(".") or part in {"tests", "build", "dist", "out"}
                       for part in parts)

    paths = [p for p in REPO.rglob("*.py") if ours(p)]
    modules = {name(p): p for p in paths}
    uses = [u for n, p in sorted(modules.items()) for u in _private_uses(n, p, modules)]
    assert not uses, "\n".join(uses)


#: The layers docs/ARCHITECTURE.md draws, lowest first: a unit (a top-level module, a package,
#: or one method's home under algorithms/) imports only units of lower layers.
LAYERS = (
    ("registry", "progress", "validation", "positions", "interrupts"),
    ("blocks",),
    ("io", "budget", "metrics"),
    ("api", "algorithms.heeger_bergen", "algorithms.portilla_simoncelli",
     "algorithms.random_phase", "algorithms.efros_leung", "algorithms.multiscale_mrf",
     "algorithms.de_bonet", "algorithms.texture_optimization", "algorithms.cooccurrence",
     "algorithms.composite"),
    ("algorithms", "stack", "plane", "tileable", "norepeat"),
    ("material",),
    ("jobs",),
    ("batch",),
    ("cli",),
    ("__main__", ""),
)

#: Imports within one layer that the page names, each with its reason.
SIDEWAYS = {
    ("algorithms.composite", "api"): "the composite's fill is any method, through synthesize()",
    ("algorithms.composite", "algorithms.cooccurrence"): "its layout and subtextures are "
                                                         "clique models (Zalesny et al. 2002, 3)",
}


def _unit(module: str) -> str:
    parts = module.split(".")[1:]
    return ".".join(parts[:2] if parts[:1] == ["algorithms"] else parts[:1])


def _layer_violations(found) -> list[str]:
    layer = {unit: i for i, units in enumerate(LAYERS) for unit in units}
    wrong = []
    for module, target, _, line in found:
        if target.split(".")[0] != "texsynth":
            continue
        a, b = _unit(module), _unit(target)
        if a not in layer or b not in layer:
            wrong.append(f"{module}:{line}: {a or b!r} has no layer in LAYERS (add it there and "
                         "to docs/ARCHITECTURE.md)")
        elif a != b and layer[b] >= layer[a] and (a, b) not in SIDEWAYS:
            wrong.append(f"{module}:{line} imports {target}: layer {layer[a]} ({a}) reaches "
                         f"layer {layer[b]} ({b})")
    return wrong


def test_imports_follow_the_layers():
    _, found = _imports()
    wrong = _layer_violations(found)
    assert not wrong, "\n".join(wrong)


def test_the_layer_check_sees_an_arrow_back_up():
    wrong = _layer_violations([("texsynth.blocks.color", "texsynth.api", False, 1),
                               ("texsynth.algorithms.de_bonet", "texsynth.algorithms.efros_leung",
                                False, 2),
                               ("texsynth.api", "texsynth.api", False, 3)])
    assert len(wrong) == 2 and "blocks" in wrong[0] and "efros_leung" in wrong[1]
