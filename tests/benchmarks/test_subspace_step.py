"""benchmarks/archive/subspace_step.py: its face map is P and P^T, its conjugate gradient solves a
hand-made sticking contact exactly, and on a captured shear step its energies, gradients and the
split of the direction agree with independent recomputations."""

import numpy as np
import pytest

from .conftest import load_benchmark


@pytest.fixture(scope="module")
def subspace():
    return load_benchmark("archive.subspace_step")


def test_lift_and_restrict_are_adjoint(subspace):
    rng = np.random.default_rng(1)
    mu = np.full(9, 0.4)
    pn = np.array([0.0, 1.0, 2.0, 1.0, 0.0, 3.0, 1.0, 2.0, 0.5])
    pt = np.array([0.0, 0.4, -0.8, 0.1, 0.0, 0.0, -0.4, 0.3, 0.2])  # sliding: points 1, 2, 6 and 8
    face = subspace.Face(mu, pn, pt)
    assert face.slide.tolist() == [False, True, True, False, False, False, True, False, True]
    assert face.stick.sum() == 3 and face.closed.sum() == 7
    zn, zt = rng.standard_normal((2, 9))
    gn, gt = rng.standard_normal((2, 9))
    zn, zt = np.where(face.closed, zn, 0.0), np.where(face.stick, zt, 0.0)  # z lives on the face's unknowns
    ln, lt = face.lift(zn, zt)
    rn, rt = face.restrict(gn, gt)
    assert np.sum(ln * gn + lt * gt) == pytest.approx(np.sum(zn * rn + zt * rt), rel=1e-13)
    np.testing.assert_allclose(lt[face.slide], 0.4 * np.sign(pt[face.slide]) * zn[face.slide])
    n, t = face.lift(np.where(face.closed, pn, 0.0), np.where(face.stick, pt, 0.0))
    np.testing.assert_allclose(n, pn)
    np.testing.assert_allclose(t[face.closed], pt[face.closed], rtol=1e-8)  # P z_0 = p_0 (sliding: |p_t| = mu p_n)


def test_one_sticking_disk_is_solved_exactly(subspace):
    """A disk (mass m, radius R, I = m R^2 / 2) on a fixed floor, falling at g dt and sliding at
    v. The face of the warm start (closed, sticking) is the solution's, but De Saxcé's shift is
    frozen at the warm start's sliding velocity, mu |v|: on the face, u_n + mu |v| = 0 and u_t = 0
    give p_n = m (g dt - mu |v|) and p_t = v / W_tt (the tangent t = (-n_y, n_x) points along -x, so
    u_t = -v before the impulse and the force -p_t along x opposes the sliding), W_tt = 1/m + R^2/I = 3/m, which the
    block-preconditioned CG reaches in one iteration: at the first checkpoint the reduced gradient
    is zero."""
    from solver import nlgs

    m, radius, g_dt, v, mu = 2.0, 0.1, 0.01, 0.005, 0.5
    one = lambda x: np.array([x], dtype=float)  # noqa: E731
    problem = nlgs.ContactProblem(np.array([1]), np.array([0]), one(0), one(1), one(0), one(0), one(0),
                                  one(-radius), one(0), one(mu), np.array([1 / m, 0.0]), np.zeros(2),
                                  np.array([1 / m, 0.0]), np.array([2 / (m * radius ** 2), 0.0]))
    case = dict(problem=problem, pn=one(1e-9), pt=one(0), vx=np.array([v, 0.0]), vy=np.array([-g_dt, 0.0]),
                w=np.zeros(2))
    r = subspace.probe(case, n_particles=1, sweeps=0)
    pn, pt = r["end"]
    assert r["shift"][0] == pytest.approx(mu * v, rel=1e-12)
    assert pn[0] == pytest.approx(m * (g_dt - mu * v), rel=1e-12)
    assert pt[0] == pytest.approx(v * m / 3, rel=1e-12)
    assert r["rows"][1]["gradient"] == pytest.approx(0.0, abs=1e-15)
    assert r["rows"][-1]["energy"] == pytest.approx(-0.5 * (m * (g_dt - mu * v) ** 2 + m * v ** 2 / 3), rel=1e-12)
    assert r["rows"][0]["energy"] > r["rows"][-1]["energy"]


@pytest.fixture(scope="module")
def probed(subspace, pentagon_sample):
    sim, _ = load_benchmark("common").load_sample(pentagon_sample)
    case = subspace.capture(sim, 3, 3)[0]
    return case, sim.n_particles, subspace.probe(case, sim.n_particles, sweeps=5, checkpoints=(2, 4))


def test_energy_change_is_the_sum_of_the_split(probed):
    _, _, r = probed
    change = r["rows"][-1]["energy"] - r["rows"][0]["energy"]
    split = r["quadratic"] + r["linear_free"] + r["linear_bias"] + r["linear_shift"] + r["linear_iterate"]
    assert change == pytest.approx(split, rel=1e-9, abs=1e-18)
    assert r["rows"][2]["energy"] <= r["rows"][1]["energy"] <= r["rows"][0]["energy"]  # CG lowers E on the face


def test_reduced_gradient_recomputed_from_the_impulses(subspace, probed):
    """The CG's recursive residual equals P^T (W p + q + b) evaluated afresh at its iterate."""
    case, _, r = probed
    P = case["problem"]
    n, t = r["end"]
    wn, wt = subspace.delassus_apply(P, n, t)
    qn, qt = subspace._relative_velocity(P, case["vx"], case["vy"], case["w"])
    gn, gt = r["face"].restrict(wn + qn + P.bias + r["shift"], wt + qt)
    assert np.sqrt(np.sum(gn ** 2 + gt ** 2)) == pytest.approx(r["rows"][-1]["gradient"], rel=1e-6, abs=1e-15)
    assert [row["iterations"] for row in r["rows"]] == [0, 2, 4]
