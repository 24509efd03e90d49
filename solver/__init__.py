"""A compact contact-dynamics solver for rigid disks and convex polygons (regular or any other,
:mod:`solver.shapes`), between walls or in a biperiodic cell.

Moreau–Jean time stepping with a nonlinear Gauss–Seidel solution of Signorini's condition and
Coulomb's law (Jean 1999; Moreau 2004), polygon contacts by the shadow-overlap idea (simple
and double contacts), and the paper's protocol: geometric deposit, isotropic compaction,
biaxial compression, written as netCDF files of the grainview data contract.

    from solver import compaction_sample, isotropic_compaction, biaxial_test
    sim = compaction_sample(400, "pentagon")
    isotropic_compaction(sim)
    biaxial_test(sim, "biaxial.nc", strain=0.05)
"""

__version__ = "0.1.0"

_NAMES = {"biaxial_test": "scenes", "compaction_sample": "scenes", "gravity_scene": "scenes",
          "is_equilibrium": "scenes", "isotropic_compaction": "scenes", "wall_state": "scenes",
          "load_sample": "restart", "resume": "restart", "Parameters": "parameters", "Simulation": "stepper",
          "StepInfo": "stepper", "Walls": "walls"}


def __getattr__(name):
    """The solver's names on first use (PEP 562): ``import solver.preparation`` (the command
    line's presets) loads no numba kernel, and ``python -m solver.restart`` runs its module
    once, not after ``import solver`` has imported it already."""
    if name in _NAMES:
        import importlib

        return getattr(importlib.import_module(f".{_NAMES[name]}", __name__), name)
    raise AttributeError(f"module 'solver' has no attribute {name!r}")


__all__ = ["Simulation", "Parameters", "StepInfo", "Walls", "compaction_sample", "isotropic_compaction",
           "biaxial_test", "resume", "load_sample", "gravity_scene", "is_equilibrium", "wall_state", "__version__"]
