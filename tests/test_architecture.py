"""The package's layering (docs/architecture.md), checked on its source.

Read with ``ast`` (nothing is imported): every import, the lazy ones inside
functions included, resolved to the module it names.
"""
import ast
import functools
from collections import defaultdict
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "acausal"

# bottom up: a folder (or loose module) may import only ranks below its own
RANK = {
    "errors": 0,
    "infra": 1,
    "data": 1,
    "lang": 2,
    "blocks": 3,
    "mechanics": 4,
    "compiler": 4,
    "viz": 5,
    "runtime": 6,
    "analysis": 7,
    "modelfile": 7,
    "studies": 8,
    "interop": 8,
    "diagnose": 9,
    "cli": 10,
}
LOOSE = {"__init__", "errors", "cli", "modelfile"}


def _modules():
    out = {}
    for p in sorted(PKG.rglob("*.py")):
        rel = p.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (p, is_pkg)
    return out


MODULES = _modules()


@functools.lru_cache(maxsize=None)
def _tree(path):
    """A module's syntax tree, parsed once for all the rules."""
    return ast.parse(path.read_text())


@functools.lru_cache(maxsize=None)
def _imports(name):
    """(line, imported module, imported names) of every import in a module."""
    return tuple(_walk_imports(name))


def _walk_imports(name):
    path, is_pkg = MODULES[name]
    package = name if is_pkg else name.rsplit(".", 1)[0]
    tree = _tree(path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("acausal"):
                    yield node.lineno, a.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if not mod.startswith("acausal"):
                continue
            names = [a.name for a in node.names]
            # "from pkg import module" names a module
            subs = [f"{mod}.{n}" for n in names if f"{mod}.{n}" in MODULES]
            if subs:
                for s in subs:
                    yield node.lineno, s, []
                rest = [n for n in names if f"{mod}.{n}" not in MODULES]
                if rest:
                    yield node.lineno, mod, rest
            else:
                yield node.lineno, mod, names


def _layer(mod):
    parts = mod.split(".")
    if len(parts) == 1:
        return None            # the package face
    return parts[1]


def _rank(mod):
    layer = _layer(mod)
    return None if layer is None else RANK.get(layer)


def test_every_folder_and_loose_module_has_a_layer():
    layers = {_layer(m) for m in MODULES} - {None}
    assert layers <= set(RANK), f"not in docs/architecture.md's layers: {layers - set(RANK)}"


def test_no_loose_modules_beyond_the_four():
    loose = {p.stem for p in PKG.glob("*.py")}
    assert loose <= LOOSE, f"modules loose in acausal/: {sorted(loose - LOOSE)}"


def test_no_import_runs_back_up():
    bad = []
    for name in MODULES:
        own = _rank(name)
        if own is None:
            continue
        for line, mod, _ in _imports(name):
            if mod == "acausal":
                bad.append(f"{name}:{line} imports the package face (acausal); "
                           f"import from its layer instead")
                continue
            other = _rank(mod)
            if other is not None and other > own:
                bad.append(f"{name}:{line} -> {mod}")
    assert not bad, "imports that run back up:\n" + "\n".join(bad)


def test_no_private_name_imported_from_another_module():
    bad = []
    for name in MODULES:
        for line, mod, names in _imports(name):
            if mod == name:
                continue
            priv = [n for n in names if n.startswith("_") and not n.startswith("__")]
            last = mod.rsplit(".", 1)[-1]
            if last.startswith("_") and last != "__init__":
                priv.append(last)
            if priv:
                bad.append(f"{name}:{line} imports {', '.join(priv)} from {mod}")
    assert not bad, "\n".join(bad)


def _cycle(graph):
    colour = defaultdict(int)
    stack = []

    def visit(n):
        colour[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if colour[m] == 1:
                return stack[stack.index(m):] + [m]
            if colour[m] == 0:
                found = visit(m)
                if found:
                    return found
        stack.pop()
        colour[n] = 2
        return None

    for n in sorted(graph):
        if colour[n] == 0:
            found = visit(n)
            if found:
                return found
    return None


def _owner(mod):
    """The module an imported name resolves to (a package's name is its __init__)."""
    while mod and mod not in MODULES:
        mod = mod.rsplit(".", 1)[0] if "." in mod else ""
    return mod


def test_no_import_circle_between_folders():
    graph = defaultdict(set)
    for name in MODULES:
        src = ".".join(name.split(".")[:3]) if name.count(".") >= 2 else name
        for _, mod, _ in _imports(name):
            dst_mod = _owner(mod)
            if not dst_mod or dst_mod == "acausal":
                continue
            dst = ".".join(dst_mod.split(".")[:3]) if dst_mod.count(".") >= 2 else dst_mod
            if dst != src and not src.startswith(dst + ".") and not dst.startswith(src + "."):
                graph[src].add(dst)
    found = _cycle(graph)
    assert found is None, "import circle: " + " -> ".join(found)


def test_no_module_level_import_circle():
    graph = defaultdict(set)
    for name, (path, is_pkg) in MODULES.items():
        package = name if is_pkg else name.rsplit(".", 1)[0]
        for node in _tree(path).body:
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("acausal")):
                base = package.split(".")
                if node.level:
                    base = base[:len(base) - (node.level - 1)]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module
                for a in node.names:
                    target = _owner(f"{mod}.{a.name}") if f"{mod}.{a.name}" in MODULES else _owner(mod)
                    if target and target != name:
                        graph[name].add(target)
    # a package importing its own submodules (its face) is not a circle
    for name in list(graph):
        graph[name] = {m for m in graph[name] if not (MODULES[name][1] and m.startswith(name + "."))}
    found = _cycle(graph)
    assert found is None, "module-level import circle: " + " -> ".join(found)


def _is_component_class(cls):
    return any(isinstance(b, ast.Name) and (b.id in {"Component", "Model", "Declaration"}
                                            or b.id.startswith("Partial"))
               for b in cls.bases) or any(isinstance(b, ast.Name) and b.id.endswith(("Friction", "Contact"))
                                          for b in cls.bases)


@pytest.mark.parametrize("limit", [8])
def test_public_functions_take_at_most_eight_parameters(limit):
    """Component constructors (their parameters are the model's, as in
    Modelica), declarations (their keywords are Modelica's attributes: unit,
    min, max, nominal, ...) and click commands (one parameter per
    command-line option) are exempt; every other public function and method
    is not."""
    bad = []
    for name, (path, _) in MODULES.items():
        tree = _tree(path)
        exempt = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and _is_component_class(node):
                exempt |= {id(f) for f in node.body if isinstance(f, ast.FunctionDef)
                           and f.name == "__init__"}
            if isinstance(node, ast.FunctionDef) and any(
                    isinstance(d, ast.Call) and getattr(d.func, "attr", "") in {"command", "group"}
                    for d in node.decorator_list):
                exempt.add(id(node))
        for node in ast.walk(tree):
            if not isinstance(node, ast.FunctionDef) or id(node) in exempt:
                continue
            if node.name.startswith("_") and node.name != "__init__":
                continue
            a = node.args
            params = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs
                      if x.arg not in ("self", "cls")]
            if len(params) > limit:
                bad.append(f"{name}:{node.lineno} {node.name} ({len(params)})")
    assert not bad, "functions with more than 8 parameters:\n" + "\n".join(bad)
