"""benchmarks/body_admm.py: the body-space capture's checks refuse a problem whose W or q is not
H M^-1 H^T and H v_free + bias, and the verdict reads iterations off the rows as stated."""

import numpy as np
import pytest
from scipy import sparse

from .conftest import load_benchmark as load


def _entry():
    # one particle (m = 2, I = 0.5) on a fixed floor, one point: W = diag(0.5, 1), q = H v_free + (bias, 0)
    H = sparse.csr_matrix(np.array([[0.0, 1.0, 0.0, 0.0, -1.0, 0.0], [-1.0, 0.0, -0.5, 1.0, 0.0, 0.0]]))
    minv = sparse.diags([0.5, 0.5, 2.0, 0.0, 0.0, 0.0]).tocsr()
    v_free, bias = np.array([0.1, -2.0, 0.0, 0.0, 0.0, 0.0]), np.array([0.3])
    return dict(H=H, minv=minv, v_free=v_free, bias=bias, mu=np.array([0.4]),
                W=sparse.csr_matrix(np.diag([0.5, 1.0])), q=np.array([-1.7, -0.1]), initial=np.zeros((1, 2)))


def test_the_body_form_is_checked_against_the_matrix_form():
    bench = load("body_admm")
    bench.check_body_form(_entry())  # W and q by hand agree
    wrong_q = dict(_entry(), q=np.array([-2.0, -0.1]))  # the Signorini shift left out: 0.3 / 2
    with pytest.raises(AssertionError, match="q by 1.5e-01"):
        bench.check_body_form(wrong_q)
    wrong_w = dict(_entry(), W=sparse.csr_matrix(np.diag([0.5, 0.5])))  # the rotation left out: 0.5 / 0.5
    with pytest.raises(AssertionError, match=r"W by 1.0e\+00"):
        bench.check_body_form(wrong_w)


def test_the_verdict_counts_iterations_to_1e_4_per_size():
    bench = load("body_admm")

    def row(n, method, iterations, seconds):
        reach = {1e-4: (iterations, seconds) if iterations else None, 1e-6: None}
        return dict(problem=f"pentagons {n} #1", method=method, reach=reach)

    rows = [row(1000, "nlgs", 300, 0.04), row(1000, "admm", 40, 0.02),
            row(14400, "nlgs", 1500, 3.0), row(14400, "admm", 55, 6.0)]
    text = bench.verdict(rows)
    assert "admm: iterations to 1e-4 per problem (1000: 40; 14400: 55); flat within 1.5x and <= 100: yes." in text
    assert "1000 #1: 0.5x; 14400 #1: 2x" in text
    rows[-1] = row(14400, "admm", 61, 6.0)  # 61 > 1.5 x 40
    assert "flat within 1.5x and <= 100: no." in bench.verdict(rows)
