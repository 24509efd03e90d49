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


# u = W r + q for two points sharing a normal coupling: the normal impulses solve
# 2 rn1 + rn2 = 3 = rn1 + 2 rn2 (rn = 1, 1), the tangential ones stick at rt = -0.25, +0.25
# (|rt| < mu rn = 0.3)
COUPLED = (np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]), np.array([-3.0, 0.5, -3.0, -0.5]),
           np.full(2, 0.3))


def test_every_registered_matrix_method_is_measured_on_every_target():
    """measure() takes its methods from the registry (matrix_methods()): a row per method and
    target, each reaching the target on a problem every method solves, and the NLGS's sweeps
    to 1e-4 those of its trajectory."""
    from scipy import sparse

    from solver.contact_solvers import matrix_methods

    bench = load("contact_solvers")
    W, q, mu = sparse.csr_matrix(COUPLED[0]), COUPLED[1], COUPLED[2]
    rows = bench.measure([("two points", W, q, mu, np.zeros((2, 2)))])
    assert sorted((r["method"], r["target"]) for r in rows) == sorted(
        (m, t) for m in matrix_methods() for t in bench.TARGETS)
    assert all(r["problem"] == "two points" and r["points"] == 2 and r["reached"] for r in rows)
    assert all(r["residual"] <= r["effective"] for r in rows)
    trajectory = bench.nlgs_trajectory(W, q, mu, np.zeros((2, 2)))
    first = next(sweeps for sweeps, _, residual in trajectory if residual <= 1e-4)
    assert next(r for r in rows if r["method"] == "nlgs" and r["target"] == 1e-4)["iterations"] == first


def test_merged_rows_replace_the_measured_problems_and_keep_the_others():
    bench = load("contact_solvers")
    kept = [dict(problem=p, method=m, seconds=1.0) for p in ("a", "b", "c") for m in ("nlgs", "pcg")]
    fresh = [dict(problem=p, method=m, seconds=2.0) for p in ("b", "d") for m in ("nlgs", "pcg")]
    merged = bench.merge_rows(kept, fresh)
    assert [(r["problem"], r["method"], r["seconds"]) for r in merged] == [
        ("a", "nlgs", 1.0), ("a", "pcg", 1.0), ("b", "nlgs", 2.0), ("b", "pcg", 2.0), ("c", "nlgs", 1.0),
        ("c", "pcg", 1.0), ("d", "nlgs", 2.0), ("d", "pcg", 2.0)]


@pytest.fixture(scope="module")
def biaxial_file(pentagon_sample, tmp_path_factory):
    """A biaxial test of the 60 compacted pentagons, a snapshot every 5 steps."""
    import warnings

    import solver

    sim, _ = load("step_profile").load_sample(pentagon_sample)
    path = str(tmp_path_factory.mktemp("biaxial") / "biaxial.nc")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        solver.biaxial_test(sim, path, strain=0.001, every=5, progress=False)
    return path


def _stepped(path, index, name, steps):
    """The simulation at snapshot ``index`` of ``path`` with ``name`` on one domain, and the
    StepInfo of its next ``steps`` steps."""
    from dataclasses import replace

    from solver import load_sample

    sim = load_sample(path, index)
    sim.parameters = replace(sim.parameters, solver=name, domains=1)
    return sim, [sim.step() for _ in range(steps)]


def test_problems_built_from_a_snapshot_are_the_steppers_own(biaxial_file, tmp_path):
    """build_from: the first problem is the one of the step after the snapshot, from the
    snapshot's warm start; the second the one 3 plain-NLGS steps later (both posed again here
    from a fresh load of the snapshot)."""
    import pickle

    bench = load("contact_solvers")
    out = bench.build_from(biaxial_file, 1, captured=2, apart=3, out=str(tmp_path / "p.pkl"))
    with open(out, "rb") as fh:
        captured = pickle.load(fh)
    assert len(captured) == 2
    sim, _ = _stepped(biaxial_file, 1, "nlgs", 0)
    for k, (W, q, mu, initial) in enumerate(captured):
        problem, pn, pt, vx, vy, w, _ = load("common").capture_contact_problems(sim, 1)[0]
        expected = bench.matrix_problem(problem, vx, vy, w)
        assert abs(W - expected[0]).max() == 0
        np.testing.assert_array_equal(q, expected[1])
        np.testing.assert_array_equal(mu, expected[2])
        np.testing.assert_array_equal(initial, np.stack([pn, pt], -1))
        for _ in range(2 if k == 0 else 0):
            sim.step()


def test_the_stepper_stretch_records_each_methods_own_steps(biaxial_file):
    """stepper_stretch: per method, the iterations, residuals and converged flags of the steps
    that a plain run of the same method from the same snapshot makes, in order."""
    bench = load("contact_solvers")
    rows = bench.stepper_stretch(biaxial_file, 1, steps=3, methods=("nlgs", "pcg"))
    assert [r["method"] for r in rows] == ["nlgs"] * 3 + ["pcg"] * 3
    for name in ("nlgs", "pcg"):
        sim, infos = _stepped(biaxial_file, 1, name, 3)
        mine = [r for r in rows if r["method"] == name]
        assert [r["iterations"] for r in mine] == [i.iterations for i in infos]
        assert [r["local_law_residual"] for r in mine] == [i.local_law_residual for i in infos]
        assert [r["converged"] for r in mine] == [bool(i.converged) for i in infos]
        assert [r["step"] for r in mine] == list(range(sim.step_index - 2, sim.step_index + 1))
        assert all(r["seconds"] >= r["solve_seconds"] > 0 for r in mine)


def test_the_stretch_summary_is_its_rows_statistics():
    bench = load("contact_solvers")
    rows = [dict(method="a", iterations=i, seconds=s, solve_seconds=s / 2, local_law_residual=law, converged=c)
            for i, s, law, c in ((10, 1.0, 1e-4, True), (20, 2.0, 3e-4, False), (60, 3.0, 2e-4, True),
                                 (30, 2.0, 1e-4, True))]
    (summary,) = bench.stretch_summary(rows)
    assert summary.pop("method") == "a"
    assert summary == pytest.approx(dict(steps=4, median=25.0, mean=30.0, p90=51.0, max=60, seconds=2.0,
                                         solve_seconds=1.0, unconverged=1, law_median=1.5e-4, law_max=3e-4),
                                    rel=1e-12)
