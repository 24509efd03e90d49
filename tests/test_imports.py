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
    assert "solver.scenes" in graph and "grainview.app.report" in graph
    assert "solver.output" in graph["solver.scenes"]
    assert find_cycles(graph) == []


def test_the_array_layer_imports_nothing_of_the_labelled_layer():
    """grainview/analysis/arrays holds the physics on plain arrays: it may use its own modules, the
    numba kernels and the contract layer, never the xarray topic modules."""
    graph = import_graph()
    allowed = ("grainview.analysis.arrays", "grainview.analysis._kernels", "grainview.contract")
    for module, deps in graph.items():
        if module.startswith("grainview.analysis.arrays"):
            assert all(dep.startswith(allowed) for dep in deps), (module, sorted(deps))


ROOMS = {
    "grainview.contract": 0,
    "grainview.datasets": 1,
    "grainview.formats": 2,
    "grainview.analysis": 3, "solver": 3,
    "grainview.export": 4, "grainview.plot": 4,
    "grainview.app": 5,
    "grainview": 6,
}
"""The rooms of the packages and their floor: a module may import its own room and the rooms on
lower floors, never a higher floor or another room of its floor. The drawing reads contract <-
formats (other codes' files read into the contract) <- analysis <- export (the writers), plot
(the figures) <- application, with the solver beside the analysis, on the contract alone (the
signals that stop a run or a conversion cleanly are the contract's) and the example datasets
(``grainview.datasets``) on the contract; the package's front door (``grainview/__init__.py``, the
``ds.grain`` accessor and its registration, the command line) sits on top of them all."""

FRONT_DOOR = {"grainview", "grainview.__main__", "grainview._moved", "grainview._register", "grainview.accessor"}
"""The only modules of grainview outside a room's folder (``grainview.datasets`` aside, a room of its
own)."""


def room_of(module: str) -> str:
    """The room holding ``module``: the longest room name it starts with, as a package path."""
    if module in FRONT_DOOR:
        return "grainview"
    rooms = [room for room in ROOMS if room != "grainview" and (module == room or module.startswith(room + "."))]
    if not rooms:
        raise KeyError(f"{module}: in no room of {sorted(ROOMS)}")
    return max(rooms, key=len)


def wrong_way_imports(graph) -> set:
    """Every (module, imported module) whose room is on a higher floor than the importer's, or is
    another room of the same floor."""
    wrong = set()
    for module, deps in graph.items():
        here = room_of(module)
        for dep in deps:
            there = room_of(dep)
            if there != here and ROOMS[there] >= ROOMS[here]:
                wrong.add((module, dep))
    return wrong


def test_the_room_check_sees_an_import_going_up_or_sideways():
    graph = {"grainview.analysis.stress": {"grainview.contract.schema", "grainview.analysis._lift"},
             "grainview.plot.maps": {"grainview.analysis.stress", "grainview.formats.opening"},
             "grainview.contract.schema": set(), "grainview.analysis._lift": set(), "grainview.formats.opening": set(),
             "grainview.export.vtk": {"grainview.analysis.stress"},
             "grainview.app.report": {"grainview.plot.maps", "grainview.accessor"}, "grainview.accessor": set()}
    assert wrong_way_imports(graph) == {("grainview.app.report", "grainview.accessor")}
    graph["grainview.analysis.stress"].add("grainview.plot.maps")  # up
    graph["grainview.formats.opening"].add("grainview.analysis._lift")  # up
    graph["grainview.plot.maps"].add("grainview.export.vtk")  # sideways
    assert wrong_way_imports(graph) == {("grainview.app.report", "grainview.accessor"),
                                        ("grainview.analysis.stress", "grainview.plot.maps"),
                                        ("grainview.formats.opening", "grainview.analysis._lift"),
                                        ("grainview.plot.maps", "grainview.export.vtk")}
    try:
        room_of("grainview.stress")  # a module left on the flat floor
    except KeyError as error:
        assert "grainview.stress: in no room" in str(error)
    else:
        raise AssertionError("a module outside every room was given a room")


def test_every_import_goes_down_the_rooms():
    graph = import_graph()
    assert {room_of(module) for module in graph} == set(ROOMS)  # every module in a room, every room used
    assert "grainview.plot.maps" in graph and "grainview.analysis.contacts" in graph["grainview.plot.maps"]
    assert wrong_way_imports(graph) == set()


ACCESSOR_CALLERS = ("grainview.app", "grainview")
"""The rooms that may call the ``ds.grain`` accessor: it sits on the front door, so that a call
through it from a lower room is an import going up that the import graph cannot see."""


def accessor_uses(source: str) -> list:
    """The lines of ``source`` that read an attribute named ``grain`` (``ds.grain.strains()``,
    ``getattr(ds, "grain")``)."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Attribute) and node.attr == "grain":
            lines.append(node.lineno)
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("getattr", "hasattr")
              and len(node.args) > 1 and isinstance(node.args[1], ast.Constant) and node.args[1].value == "grain"):
            lines.append(node.lineno)
    return sorted(lines)


def test_the_accessor_check_sees_a_call_and_not_a_docstring():
    source = ('"""Uses ``ds.grain.strains()``."""\n'
              "def f(ds):\n    return ds.grain.strains()\n"
              "def g(ds):\n    return getattr(ds, 'grain').fabric()\n"
              "def h(grain):\n    return grain.strains\n")
    assert accessor_uses(source) == [3, 5]


def test_no_room_below_the_application_calls_the_accessor():
    callers = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            module = _module_name(path)
            if room_of(module) in ACCESSOR_CALLERS:
                continue
            if lines := accessor_uses(path.read_text()):
                callers[module] = lines
    assert callers == {}, f"calls through ds.grain below the application (call the topic functions): {callers}"


def _modules_after(code: str) -> set:
    """The heavy third-party modules loaded by ``code`` in a fresh interpreter."""
    import json
    import subprocess
    import sys

    probe = (f"{code}\nimport json, sys\n"
             "print(json.dumps(sorted(m for m in ('xarray', 'dask', 'matplotlib', 'pandas', 'grainview.accessor', "
             "'grainview.analysis.stress') if m in sys.modules)))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_importing_the_solver_loads_no_xarray_dask_or_matplotlib():
    assert _modules_after("import solver") == set()


def _contract_modules() -> list:
    return sorted(_module_name(path) for path in (ROOT / "grainview" / "contract").glob("*.py"))


def test_the_solver_imports_only_the_contract_layer_of_grainview():
    graph = import_graph()
    outside = {(module, dep) for module, deps in graph.items() if module.startswith("solver")
               for dep in deps if dep.startswith("grainview") and not dep.startswith("grainview.contract")}
    assert outside == set()
    assert any(dep.startswith("grainview.contract.writer") for dep in graph["solver.output"])  # the graph sees them


def test_the_contract_imports_nothing_of_grainview_outside_itself():
    graph = import_graph()
    contract = [module for module in graph if module.startswith("grainview.contract")]
    assert len(contract) == len(_contract_modules()) >= 10
    for module in contract:
        assert all(dep.startswith("grainview.contract") for dep in graph[module] if dep.startswith("grainview")), \
            (module, sorted(graph[module]))


def test_the_formats_import_nothing_of_grainview_but_the_contract():
    """The readers of other codes' files build datasets of the contract; what is computed from
    them, and written from that, lives above them (the analysis, the exports)."""
    graph = import_graph()
    formats = [module for module in graph if module.startswith("grainview.formats")]
    assert len(formats) >= 10
    for module in formats:
        assert all(dep.startswith(("grainview.formats", "grainview.contract")) for dep in graph[module]
                   if dep.startswith("grainview")), (module, sorted(graph[module]))


def test_importing_the_contract_loads_no_xarray_dask_pandas_or_matplotlib():
    """Every module of the contract, imported in a fresh interpreter: numpy only."""
    assert _modules_after("\n".join(f"import {m}" for m in _contract_modules())) == set()


def test_opening_a_file_loads_xarray_and_the_accessor_but_no_analysis(tmp_path):
    import numpy as np

    from grainview.contract.dataset import make_dataset, netcdf_options

    ds = make_dataset(radius=np.ones(2), n_vertices=np.zeros(2, int), mass=np.ones(2), inertia=np.ones(2),
                      position=np.array([[[0.0, 0.0], [3.0, 0.0]]]), angle=np.zeros((1, 2)),
                      box_min=np.array([[-1.0, -1.0]]), box_max=np.array([[4.0, 1.0]]), contacts=[{"i": [], "j": [], "kind": [], "normal": np.zeros((0, 2)),
                                                                    "fn": [], "ft": []}])
    ds.to_netcdf(tmp_path / "two.nc", **netcdf_options(ds))
    loaded = _modules_after(f"import grainview.contract.io as io\nio.open_dataset({str(tmp_path / 'two.nc')!r})")
    assert {"matplotlib", "grainview.analysis.stress"}.isdisjoint(loaded)
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
