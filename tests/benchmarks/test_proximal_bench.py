"""benchmarks/proximal.py: the probes' convex problem (cone rows, scaling) solved by hand, and the
outer steps' counting of factorisations and targets."""

import numpy as np
import pytest
from scipy import sparse

from .conftest import load_benchmark as load


def test_cone_rows_hold_exactly_the_coulomb_cone():
    bench = load("proximal")
    mu = np.array([0.5, 0.0, 0.2])
    A, zeros, nonnegative = bench.cone_constraints(mu)
    assert (zeros, nonnegative, A.shape) == (1, 5, (6, 6))

    def inside(r):
        value = A @ np.asarray(r, float)
        return bool(np.all(value[:zeros] == 0) and np.all(value[zeros:] >= 0))

    assert inside([2, 1, 3, 0, 1, -0.2])  # on the edges (|r_t| = mu r_n) and the frictionless axis
    assert not inside([2, 1.01, 3, 0, 1, 0])  # outside the first cone
    assert not inside([2, 0, 3, 0.1, 1, 0])  # tangential impulse where mu = 0
    assert not inside([2, 0, -1, 0, 1, 0])  # pulling where mu = 0
    assert not inside([2, 0, 3, 0, 1, -0.21])


@pytest.mark.parametrize("name", ["osqp", "clarabel"])
def test_a_probe_started_at_the_answer_returns_it(name):
    pytest.importorskip(name)
    bench = load("proximal")
    # one sliding point (W diag(2, 4), q (-4, 8), mu 0.5: r = (2, -1), u = (0, 4), s = mu |u_t| = 2)
    # and one frictionless point pressed down (r = (1.5, 0))
    W = sparse.csr_matrix(np.diag([2.0, 4.0, 2.0, 1.0]))
    q, mu = np.array([-4.0, 8.0, -3.0, 0.5]), np.array([0.5, 0.0])
    answer = np.array([[2.0, -1.0], [1.5, 0.0]])
    row = bench.probe(name, W, q, mu, answer)
    assert row["steps"][0]["residual"] < 1e-5
    assert row["steps"][0]["status"].lower() == "solved"


def test_the_outer_steps_factorisations_and_times_to_a_target():
    bench = load("proximal")
    from benchmarks.research.proximal_newton import ProximalHistory

    history = ProximalHistory(residuals=(1e-2, 1e-3, 1e-5, 1e-9), seconds=(0.0, 1.0, 2.0, 3.5),
                              alphas=(1.0, 0.1, 0.01), newton_steps=(3, 4, 5), factorisations=(3, 6, 5),
                              inner_converged=(True, True, True), inner_tolerances=(1e-3, 1e-4, 1e-6))
    assert bench.first_within(history, 1e-4) == (9, 2.0, 2)
    assert bench.first_within(history, 1e-8) == (14, 3.5, 3)
    assert bench.first_within(history, 1e-12) is None
    assert bench.best_within_lus(history, 10) == 1e-5
    assert bench.best_within_lus(history, 2) == 1e-2
