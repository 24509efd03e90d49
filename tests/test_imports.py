"""The import structure: no import cycle between the modules of grainview and solver, counting
the imports made inside functions (which hide a cycle from Python but not from a reader)."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("grainview", "solver")


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph() -> dict:
    """{module: set of modules of the packages it imports}, relative imports resolved."""
    graph = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            name = _module_name(path)
            here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
            deps = set()
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom):
                    base = ".".join(here[:len(here) - node.level + 1] + [node.module or ""]).strip(".") \
                        if node.level else (node.module or "")
                    deps.add(base)
                    deps.update(f"{base}.{alias.name}" for alias in node.names)
                elif isinstance(node, ast.Import):
                    deps.update(alias.name for alias in node.names)
            graph[name] = deps
    return {m: {d for d in deps if d in graph and d != m} for m, deps in graph.items()}


def find_cycles(graph) -> list:
    """Every cycle met by a depth-first walk (a package importing its own submodules is no
    cycle: Python runs the package first)."""
    cycles, state, stack = [], {}, []

    def visit(module):
        state[module] = "open"
        stack.append(module)
        for dep in sorted(graph[module]):
            if dep.startswith(module + "."):
                continue
            if state.get(dep) == "open":
                cycles.append(stack[stack.index(dep):] + [dep])
            elif dep not in state:
                visit(dep)
        stack.pop()
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module)
    return cycles


def test_the_cycle_finder_sees_a_cycle():
    assert find_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c", "a"]]
    assert find_cycles({"p": {"p.x"}, "p.x": {"p"}}) == []


def test_no_import_cycle_in_the_packages():
    graph = import_graph()
    assert "solver.scenes" in graph and "grainview.report" in graph
    assert "solver.output" in graph["solver.scenes"]
    assert find_cycles(graph) == []


def test_the_array_layer_imports_nothing_of_the_labelled_layer():
    """grainview/arrays holds the physics on plain arrays: it may use its own modules, the
    numba kernels and the contract's constants, never the xarray topic modules."""
    graph = import_graph()
    allowed = ("grainview.arrays", "grainview._kernels", "grainview.schema")
    for module, deps in graph.items():
        if module.startswith("grainview.arrays"):
            assert all(dep.startswith(allowed) for dep in deps), (module, sorted(deps))


def _modules_after(code: str) -> set:
    """The heavy third-party modules loaded by ``code`` in a fresh interpreter."""
    import json
    import subprocess
    import sys

    probe = (f"{code}\nimport json, sys\n"
             "print(json.dumps(sorted(m for m in ('xarray', 'dask', 'matplotlib', 'pandas', 'grainview.accessor', "
             "'grainview.stress') if m in sys.modules)))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_importing_the_solver_loads_no_xarray_dask_or_matplotlib():
    assert _modules_after("import solver") == set()


def test_reading_files_loads_no_analysis_dask_or_plotting():
    loaded = _modules_after("import grainview.io")
    assert {"dask", "matplotlib", "grainview.stress"}.isdisjoint(loaded)
    assert "xarray" in loaded and "grainview.accessor" in loaded  # ds.grain is registered


def test_the_accessor_is_registered_whichever_is_imported_first(tmp_path):
    """``import grainview`` before or after ``import xarray``: ``ds.grain`` works either way."""
    import subprocess
    import sys

    for order in ("import grainview, xarray", "import xarray, grainview"):
        code = (f"{order}\nimport numpy as np\nds = xarray.Dataset({{'radius': ('particle', np.ones(3))}})\n"
                "print(type(ds.grain).__name__)")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
        assert out.stdout.strip() == "GrainAccessor", order
