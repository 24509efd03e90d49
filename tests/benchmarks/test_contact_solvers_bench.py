"""benchmarks/contact_solvers.py: Siconos' 2D problem files read entry for entry, and a
stepper's contact problem assembled into u = W r + q with the stepper's own Delassus blocks and
velocities."""

import numpy as np
import pytest

from .conftest import load_benchmark as load

# two contacts, W (column by column, as CSparse's cs_print writes it), q and mu
SICONOS_TEXT = """2
2
2
4
4
2
CSparse Version 3.1.9, May 4, 2016.  Copyright (c) Timothy A. Davis, 2006-2016
4-by-4, nzmax: 6 nnz: 6, 1-norm: 3.5
    col 0 : locations 0 to 1
      0 : 2
      2 : -0.5
    col 1 : locations 2 to 2
      1 : 1.25
    col 2 : locations 3 to 4
      0 : -0.5
      2 : 3
    col 3 : locations 5 to 5
      3 : 0.75
  -1.000000000000000000000000e+00   2.500000000000000000000000e-01   3.000000000000000000000000e-01   0.000000000000000000000000e+00
  5.000000000000000000000000e-01   4.000000000000000000000000e-01
"""


def test_a_siconos_problem_file_is_read_entry_for_entry(tmp_path):
    path = tmp_path / "fc2d_two.dat"
    path.write_text(SICONOS_TEXT)
    W, q, mu = load("contact_solvers").read_siconos_fc2d(str(path))
    np.testing.assert_array_equal(W.toarray(), [[2, 0, -0.5, 0], [0, 1.25, 0, 0], [-0.5, 0, 3, 0], [0, 0, 0, 0.75]])
    np.testing.assert_array_equal(q, [-1.0, 0.25, 0.3, 0.0])
    np.testing.assert_array_equal(mu, [0.5, 0.4])


def test_a_file_that_is_no_2d_problem_is_refused(tmp_path):
    path = tmp_path / "fc3d.dat"
    path.write_text(SICONOS_TEXT.replace("2\n2\n2\n4\n4\n", "3\n2\n2\n6\n6\n", 1))
    with pytest.raises(ValueError, match="not a sparse 2D frictional-contact problem"):
        load("contact_solvers").read_siconos_fc2d(str(path))


def test_a_stepper_problem_as_a_matrix(pentagon_sample):
    """W's diagonal blocks are the stepper's Delassus blocks, W is symmetric, and W r + q gives
    the stepper's own local velocities for the impulses of a few sweeps (check_assembly)."""
    from solver import nlgs

    bench = load("contact_solvers")
    sim, _ = load("step_profile").load_sample(pentagon_sample)
    problem, pn, pt, vx, vy, w, _ = load("common").capture_contact_problems(sim, 1)[0]
    W, q, mu = bench.matrix_problem(problem, vx, vy, w)
    blocks = nlgs.delassus(problem)
    diagonal = W.diagonal()
    np.testing.assert_allclose(diagonal[0::2], blocks[0], rtol=1e-12)
    np.testing.assert_allclose(diagonal[1::2], blocks[2], rtol=1e-12)
    np.testing.assert_allclose(W[0::2, 1::2].diagonal(), blocks[1], rtol=1e-12, atol=1e-12 * blocks[0].max())
    assert abs(W - W.T).max() <= 1e-12 * abs(W).max()
    np.testing.assert_array_equal(mu, problem.mu)
    bench.check_assembly(problem, W, q, pn, pt, vx, vy, w)
    with pytest.raises(AssertionError, match="differs from the stepper's velocities"):
        bench.check_assembly(problem, W, q + 1e-3 * np.abs(q).max(), pn, pt, vx, vy, w)
