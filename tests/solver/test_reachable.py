"""Every module of solver/ is reached from a command (grainview/app/) or from a registered method
(solver.contact_solvers' entry points): research that no user path reaches lives in
benchmarks/research/, not in the product. Imports inside functions count (the registry imports
each method's module when it is called)."""

from ..test_imports import import_graph


def unreached(graph, starts) -> set:
    """The modules of ``solver`` that no chain of imports from ``starts`` reaches in ``graph``."""
    seen, todo = set(), list(starts)
    while todo:
        module = todo.pop()
        if module not in seen:
            seen.add(module)
            todo.extend(graph.get(module, ()))
    return {module for module in graph if module.startswith("solver.") and module not in seen}


def test_the_walk_sees_a_module_nothing_reaches():
    graph = {"grainview.app.cli": {"solver.stepper"}, "solver.stepper": {"solver.nlgs"}, "solver.nlgs": set(),
             "solver.contact_solvers": {"solver.projected_cg"}, "solver.projected_cg": set(), "solver.two_level": set()}
    assert unreached(graph, ["grainview.app.cli", "solver.contact_solvers"]) == {"solver.two_level"}


def test_every_solver_module_is_reached_from_a_command_or_a_registered_method():
    graph = import_graph()
    starts = [module for module in graph if module.startswith("grainview.app")] + ["solver.contact_solvers"]
    assert unreached(graph, starts) == set()
