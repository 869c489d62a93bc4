"""The package's shape (issue 12, done-when item 2): imports point one way, modules stay small,
each piece of geometry and physics has one home, no hidden state at module level."""
import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1] / "jaxform"
MAX_LINES = 525  # "no module over ~500 lines"


def _modules():
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _package(name):
    return name if MODULES[name].name == "__init__.py" else name.rsplit(".", 1)[0]


def _imports(name, path):
    """Every jaxform module ``name`` imports, at module level or inside functions."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package(name).split(".")
                base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in MODULES else mod for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in MODULES:
                t = t.rsplit(".", 1)[0] if "." in t else ""
            if t and t != name:
                found.add(t)
    return found


def test_no_import_cycle():
    graph = {name: _imports(name, path) for name, path in MODULES.items()}
    # a package's __init__ may gather its own modules; those edges are the package, not a cycle
    for name in graph:
        graph[name] = {t for t in graph[name] if not (MODULES[name].name == "__init__.py" and t.startswith(name + "."))}
    state, stack = {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                cycle = stack[stack.index(m):] + [m]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)


def test_no_module_is_large():
    big = {name: n for name, path in MODULES.items() if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not big, f"modules over {MAX_LINES} lines: {big}"


def test_each_package_states_its_job():
    for name, path in MODULES.items():
        if path.name == "__init__.py":
            doc = ast.get_docstring(ast.parse(path.read_text()))
            assert doc and doc.split("\n", 1)[0].rstrip().endswith("."), name


def _definitions(pattern):
    rx = re.compile(pattern, re.M)
    return sorted(name for name, path in MODULES.items() if rx.search(path.read_text()))


def test_one_home_for_gravity_and_safe_maths():
    assert _definitions(r"^GRAVITY\s*=") == ["jaxform.units"]
    assert _definitions(r"^def (safe_norm|_safe_norm|safe_sqrt|_safe_sqrt|tiny_sqrt)\b") == ["jaxform.geometry"]
    assert _definitions(r"^def (closest_point_triangle|point_triangle_sqdist)\b") == ["jaxform.geometry"]


def test_no_module_global_caches_or_hand_written_optimisers():
    assert _definitions(r"^import hashlib|^_[A-Z_]*(CACHE|CLOSEST)[A-Z_]*\s*[:=]") == []
    assert _definitions(r"^def _(levenberg_marquardt|lbfgs|line_search)\b") == []
