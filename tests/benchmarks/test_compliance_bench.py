"""benchmarks/compliance.py: the compliant law u = (W + eps diag W) r + q solved by the NLGS and
the projected conjugate gradient on hand-made problems (one closed frictionless contact; two
bodies stacked on a floor) matches the hand-computed impulses, and the comparisons against the
rigid answer (body velocities, sink speeds, normal impulses, the rigid law's residual) are the
hand-computed ones."""

import numpy as np
import pytest
from scipy import sparse

from .conftest import load_benchmark as load

EPS = 0.1


def test_one_closed_frictionless_contact_gives_r_n_over_one_plus_eps():
    bench = load("compliance")
    W = sparse.csr_matrix(np.diag([0.5, 1.0]))
    q, mu = np.array([-1.7, 0.0]), np.array([0.0])
    We = bench.regularised(W, EPS)
    assert We.toarray() == pytest.approx(np.diag([0.55, 1.1]), abs=1e-15)
    expected = 1.7 / (0.5 * (1 + EPS))  # r_n = -q_n / (W_nn (1 + eps)) = 3.0909...
    _, best, at_target = bench.nlgs_run(We, q, mu, np.zeros((1, 2)), stop=1e-12, cap=10)
    assert best[0] == pytest.approx([expected, 0.0], rel=1e-12, abs=1e-12)
    assert at_target is not None
    iterations, _, residual, converged = bench.pcg_run(We, q, mu, np.zeros((1, 2)), target=1e-12, cap=10)
    assert converged and residual <= 1e-12


def _stack(m1=1.0, m2=2.0, radius=0.5, inertia=0.1, gh=1.0):
    # body 1 on a fixed floor (point a), body 2 on body 1 (point b); degrees of freedom (vx, vy, w)
    # of body 1 then body 2; rows: a normal, a tangential, b normal, b tangential
    H = sparse.csr_matrix(np.array([[0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                                    [1.0, 0.0, radius, 0.0, 0.0, 0.0],
                                    [0.0, -1.0, 0.0, 0.0, 1.0, 0.0],
                                    [-1.0, 0.0, radius, 1.0, 0.0, radius]]))
    minv = sparse.diags([1 / m1, 1 / m1, 1 / inertia, 1 / m2, 1 / m2, 1 / inertia]).tocsr()
    v_free = np.array([0.0, -gh, 0.0, 0.0, -gh, 0.0])  # one step of gravity, g h = 1 m/s
    W = (H @ minv @ H.T).tocsr()
    q = H @ v_free  # bias 0: both closed
    return dict(H=H, minv=minv, v_free=v_free, W=W, q=q, mu=np.array([0.3, 0.3]), initial=np.zeros((2, 2)))


def test_two_stacked_bodies_match_the_hand_computed_impulses_and_changes():
    bench = load("compliance")
    m1, m2 = 1.0, 2.0
    entry = _stack(m1, m2)
    # by hand: (1 + eps) r_a / m1 - r_b / m1 = 1 and -r_a / m1 + (1 + eps)(1/m1 + 1/m2) r_b = 0
    r_b = m1 / ((1 + EPS) ** 2 * (1 + m1 / m2) - 1)  # 1.22699...
    r_a = (1 + EPS) * (1 + m1 / m2) * r_b  # 2.02454...
    rigid = np.array([[m1 + m2, 0.0], [m2, 0.0]])  # eps = 0: each body held at rest
    # the same by a dense solve of the normal rows of W + eps diag W
    normal = entry["W"].toarray()[0::2, 0::2]
    solved = np.linalg.solve(normal + EPS * np.diag(np.diag(normal)), -entry["q"][0::2])
    assert solved == pytest.approx([r_a, r_b], rel=1e-12)
    We = bench.regularised(entry["W"], EPS)
    _, best, _ = bench.nlgs_run(We, entry["q"], entry["mu"], entry["initial"], stop=1e-13, cap=2000)
    assert best == pytest.approx(np.array([[r_a, 0.0], [r_b, 0.0]]), rel=1e-10, abs=1e-12)
    _, reference, _ = bench.nlgs_run(entry["W"], entry["q"], entry["mu"], entry["initial"], stop=1e-13, cap=2000)
    assert reference == pytest.approx(rigid, rel=1e-10, abs=1e-12)

    got = bench.compare(entry, best, reference, EPS, time_step=5e-4)
    # body velocities: v_1y = -eps r_a / m1 (its floor contact sinks), v_2y = -1 + r_b / m2; v_0 = 0
    v1, v2 = -EPS * r_a / m1, -1.0 + r_b / m2
    assert got["dv"] == pytest.approx(np.sqrt((m1 * v1 ** 2 + m2 * v2 ** 2) / (m1 + m2)), rel=1e-9)
    assert got["dv_w"] == pytest.approx(got["dv"], rel=1e-9)
    sinks = [EPS * r_a / m1, EPS * r_b * (1 / m1 + 1 / m2)]  # eps W_nn r_n: 0.2025, 0.1840 m/s
    assert got["sink"] == pytest.approx((np.median(sinks), max(sinks)), rel=1e-9)
    assert got["sink_step"] == pytest.approx((np.median(sinks) * 5e-4, max(sinks) * 5e-4), rel=1e-9)
    assert got["over_recovery"] == 1.0  # both faster than 1 mm/s
    assert got["total"] == pytest.approx((r_a + r_b) / (m1 + 2 * m2) - 1.0, rel=1e-9)
    assert got["mean"] == pytest.approx(got["total"], rel=1e-9)  # both closed in both answers
    assert got["below"] == (0.5, 0.5) and got["closed"] == (2, 2)
    assert got["largest"] == pytest.approx((r_a / ((r_a + r_b) / 2), 3.0 / 2.5), rel=1e-9)
    # samples {1.227, 2.025} against {2, 3}: the CDFs differ by 1/2 on [1.227, 2) and on [2.025, 3)
    assert got["ks"] == 0.5
    # rigid law: F_k = rho_k (-u_k) = rho_k eps W_nn,k r_n,k = eps r_n,k on each closed, sticking point
    assert got["rigid_law"] == pytest.approx(EPS, rel=1e-9)
    # share of W's energy of the rigid answer (3, 0, 2, 0): normal block [[1, -1], [-1, 1.5]] gives
    # r^T W r = 9 - 12 + 6 = 3 and r^T D r = 9 + 1.5 x 4 = 15
    assert bench.energy_share(entry["W"], reference) == pytest.approx(3.0 / 15.0, rel=1e-9)


def test_the_verdict_names_the_smallest_eps_that_is_flat_and_few():
    bench = load("compliance")
    physics = dict(dv=0.5, sink=(1e-5, 1e-3), total=-0.9, ks=0.8, rigid_law=0.01)

    def row(n, eps, sweeps, pcg):
        return dict(problem=f"pentagons {n} #1", eps=eps, nlgs=(sweeps, 0.1) if sweeps else None,
                    cold=(sweeps, 0.1) if sweeps else None, pcg=(pcg, 0.1, 1e-5, True), physics=physics)

    rows = [row(1000, 0.01, 40, 20), row(14400, 0.01, 200, 25),  # nlgs grows 5x; pcg flat and few
            row(1000, 0.1, 20, 10), row(14400, 0.1, 25, 12),  # both flat and few
            dict(row(14400, "rigid at 1e-4", None, 1), physics=dict(physics, dv=0.3))]
    rows = [r for r in rows if not isinstance(r["eps"], str)] + rows[-1:]
    text = bench.verdict(rows)
    assert "nlgs, eps 0.01: sweeps to 1e-4 per problem (1000: 40; 14400: 200; '-': not reached); flat in N" in text
    assert "nlgs: the smallest eps with flat and few: 0.1;" in text
    assert "pcg: the smallest eps with flat and few: 0.01;" in text
    assert "(the rigid answer at 1e-4: 3.0e-01)" in text
