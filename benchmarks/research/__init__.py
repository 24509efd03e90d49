"""Solver research: experiments that no user path reaches.

The methods here were written to answer one question each on the stepper's captured contact
problems, and none became a method a user can choose: no command (``grainview run``, ``study``,
``ensemble``) and no method of the solver's registry (:mod:`solver.contact_solvers`) calls them.
They are kept, with their tests (``tests/benchmarks/research/``), so that the benchmarks that
measured them still run and their results can be measured again:

- :mod:`benchmarks.research.two_level`: NLGS sweeps and one AMG V-cycle on the truncated face
  (``python -m benchmarks.two_level``, benchmarks/results/two-level.md);
- :mod:`benchmarks.research.proximal_newton`: proximal-point steps around the semi-smooth Newton,
  Siconos' PROX (``python -m benchmarks.proximal``, benchmarks/results/proximal.md);
- :mod:`benchmarks.research.body_admm`: ADMM in body space (``python -m benchmarks.body_admm``,
  benchmarks/results/body-admm.md).

What they found: docs/solver-research.md. They import the solver (its residuals, its NLGS, its
semi-smooth Newton); the solver imports nothing from here. A method that earns its place moves
into ``solver/`` and registers there (:mod:`solver.contact_solvers`).
"""
