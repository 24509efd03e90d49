"""The solution measures of solver.residuals: zero for every admissible solution, and only there."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solver import nlgs, residuals
from solver.solve_records import Impulses, Velocities

finite = st.floats(-10, 10, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(finite, finite, st.floats(0, 2))
def test_cone_projection_is_the_euclidean_projection(zn, zt, mu):
    pn, pt = residuals.cone_projection(zn, zt, mu)
    assert abs(pt) <= mu * pn + 1e-12  # in the cone
    dn, dt = zn - pn, zt - pt
    assert abs(dn * pn + dt * pt) <= 1e-9 * (1 + zn * zn + zt * zt)  # z - P z orthogonal to P z
    assert dn + mu * abs(dt) <= 1e-9 * (1 + abs(zn) + abs(zt))  # and in the polar cone
    assert residuals.cone_projection(pn, pt, mu) == pytest.approx((pn, pt), abs=1e-12)  # idempotent


def test_cone_projection_by_hand():
    assert residuals.cone_projection(2.0, 0.5, 0.5) == (2.0, 0.5)  # inside
    assert residuals.cone_projection(-1.0, 0.5, 0.5) == (0.0, 0.0)  # polar cone
    # onto the edge (1, 1)/sqrt 2 for mu = 1: (0, 2) -> (1, 1)
    assert residuals.cone_projection(0.0, 2.0, 1.0) == pytest.approx((1.0, 1.0), rel=1e-15)
    assert residuals.cone_projection(3.0, -1.0, 0.0) == (3.0, 0.0)  # frictionless: drop the tangent
    assert residuals.cone_projection(-3.0, 0.0, 0.0) == (0.0, 0.0)  # frictionless, pulling: nothing


def one_point(ufn, uft, mu=0.5, bias=0.0, mass=2.0):
    """A particle (body 1) on a fixed floor (body 0): point at its centre, normal +y, so that
    W = diag(1/m, 1/m). The free velocity is (uft along t = (-1, 0)... ) set through vx, vy."""
    problem = nlgs.ContactProblem(
        np.array([0]), np.array([1]), np.array([0.0]), np.array([1.0]), np.zeros(1), np.zeros(1), np.zeros(1),
        np.zeros(1), np.array([bias]), np.array([mu]), np.array([0.0, 1 / mass]), np.zeros(2),
        np.array([0.0, 1 / mass]), np.zeros(2))
    # t = (-n_y, n_x) = (-1, 0): u_t = -v_x
    vx, vy, w = np.array([0.0, -uft]), np.array([0.0, ufn]), np.zeros(2)
    return problem, vx, vy, w


@pytest.mark.parametrize("ufn, uft, state", [(-1.0, 0.2, "stick"), (-1.0, 3.0, "slide"), (-1.0, -3.0, "slide"),
                                             (0.5, 1.0, "open")])
def test_exact_local_solutions_have_zero_residual(ufn, uft, state):
    problem, vx, vy, w = one_point(ufn, uft)
    pn, pt = np.zeros(1), np.zeros(1)
    nlgs.solve_problem(problem, pn, pt, vx, vy, w, tolerance=1e-14, max_tolerance=1e-14, max_iterations=5)
    # by hand (m = 2): stick p = -m u_free; slide p_n = -m u_n, p_t = -mu p_n sign(u_t); open p = 0
    expected = {"stick": (2.0, -0.4), "slide": (2.0, -np.sign(uft) * 1.0), "open": (0.0, 0.0)}[state]
    assert (pn[0], pt[0]) == pytest.approx(expected, abs=1e-14)
    assert residuals.local_law_residual(problem, pn, pt, vx, vy, w) == pytest.approx(0.0, abs=1e-14)


def test_violations_are_measured():
    problem, vx, vy, w = one_point(-1.0, 0.2)
    # half the needed normal impulse: the particle still sinks at 0.5 m/s; the natural map sees it
    pn, pt = np.array([1.0]), np.array([-0.4])
    vy[1] += pn[0] / 2.0
    vx[1] += 0.4 / 2.0  # t = (-1, 0): p_t = -0.4 pushes +x
    r = residuals.local_law_residual(problem, pn, pt, vx, vy, w)
    # u = (-0.5, 0): z = r - rho u^ = (1 + 2 * 0.5, -0.4) inside the cone -> F = r - z = (-1, 0); |F|/|r|
    assert r == pytest.approx(1.0 / np.hypot(1.0, 0.4), rel=1e-14)
    # an impulse outside the cone
    problem, vx, vy, w = one_point(0.0, 0.0)
    pn, pt = np.array([1.0]), np.array([1.0])
    assert residuals.local_law_residual(problem, pn, pt, vx, vy, w) > 0.1


def test_every_admissible_split_of_a_hyperstatic_load_has_zero_residual():
    """Two coincident points under one particle: any split of its weight is a solution."""
    mass, g_h = 2.0, 0.3  # g_h: the weight's impulse over the step / mass (m/s)
    # bodies as the solver numbers them: particle 0, then the floor (1), which pushes it up (+y)
    problem = nlgs.ContactProblem(
        np.array([1, 1]), np.array([0, 0]), np.zeros(2), np.ones(2), np.zeros(2), np.zeros(2), np.zeros(2),
        np.zeros(2), np.zeros(2), np.full(2, 0.5), np.array([1 / mass, 0.0]), np.zeros(2),
        np.array([1 / mass, 0.0]), np.zeros(2))
    vx, vy, w = np.zeros(2), np.zeros(2), np.zeros(2)  # end velocity: at rest on the floor
    for share in (0.0, 0.3, 0.5, 1.0):
        pn = np.array([share, 1 - share]) * mass * g_h
        assert residuals.local_law_residual(problem, pn, np.zeros(2), vx, vy, w) == pytest.approx(0, abs=1e-15)
        force, torque = residuals.unbalanced_ratios(problem, pn, np.zeros(2), np.array([[0.0, -mass * g_h]]),
                                                    np.array([0.01]))
        assert force == pytest.approx(0.0, abs=1e-12) and torque == 0.0
    # too little support: unbalanced by half the weight, i.e. the mean point impulse
    pn = np.array([0.25, 0.25]) * mass * g_h
    force, _ = residuals.unbalanced_ratios(problem, pn, np.zeros(2), np.array([[0.0, -mass * g_h]]), np.array([0.01]))
    assert force == pytest.approx(2.0, rel=1e-14)


def compacting(n, seed, steps):
    """A compaction sample of ``n`` pentagons after ``steps`` steps with plain NLGS sweeps (a
    fixed state whatever the solver's default; warnings of the collapse ignored)."""
    from solver import compaction_sample

    sim = compaction_sample(n, "pentagon", seed=seed, acceleration="off")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(steps):
            sim.step()
    return sim


def test_step_reports_the_measures_and_momentum_balances():
    sim = compacting(40, seed=2, steps=150)
    v_before = sim.velocity[:sim.n_particles].copy()
    info = sim.step()
    assert np.isfinite(info.local_law_residual) and info.unbalanced_force >= 0 and info.unbalanced_torque >= 0
    # the contact impulses and gravity are the particles' momentum change (Moreau-Jean balance)
    p = sim.parameters
    problem = sim._contact_problem(sim.points, sim.velocity, sim.angular_velocity)[0]  # same a, b, normals
    fx, fy, _ = residuals.particle_imbalance(problem, Impulses(sim.impulse[:, 0].copy(), sim.impulse[:, 1].copy()),
                                             sim.n_particles)
    momentum = sim.mass[:, None] * (sim.velocity[:sim.n_particles] - v_before)
    expected = np.stack([fx, fy], -1) + p.time_step * sim.mass[:, None] * np.asarray(p.gravity)
    scale = np.abs(sim.impulse).max()
    np.testing.assert_allclose(momentum, expected, atol=1e-9 * scale)


def test_a_tighter_tolerance_gives_a_smaller_local_law_residual():
    """One dense state, solved cold (no warm start) at two NLGS tolerances, with plain and with
    Anderson sweeps. The state is a settled compaction under 10 kPa, so its problem carries the
    confining load whatever the trajectory (a state part-way through the compaction may have only
    separating contacts, which any tolerance solves exactly); over eight seeds the ratio of the two
    residuals was 1e-5 to 1e-4 (docs/reproducibility.md)."""
    import copy
    from dataclasses import replace

    from solver import compaction_sample, isotropic_compaction

    sim = compaction_sample(60, "pentagon", seed=5, acceleration="off")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, progress=False)
    assert sim.settled
    for acceleration in ("off", "anderson"):
        found = []
        for tolerance in (1e-2, 1e-7):
            trial = copy.deepcopy(sim)
            trial.parameters = replace(trial.parameters, tolerance=tolerance, max_tolerance=tolerance * 10,
                                       max_iterations=100000, acceleration=acceleration).validate()
            trial.scale_warm_start(0.0)
            found.append(trial.step().local_law_residual)
        assert sim.last.n_points > 30 and found[1] < 0.01 * found[0], (acceleration, found)


def test_anderson_acceleration_reaches_the_same_solution_in_fewer_sweeps():
    """A column of 40 disks on the floor, solved cold: the load must travel down the chain,
    one contact per NLGS sweep at best. The Anderson-accelerated sweeps end at the same
    forces (each contact carries the weight above it) in fewer sweeps."""
    from solver import Parameters, Simulation, Walls

    n, radius, g = 40, 0.0125, 9.81
    found = {}
    for method in ("off", "anderson"):
        sim = Simulation(np.stack([np.zeros(n), radius + 2 * radius * np.arange(n)], -1), np.zeros(n),
                         np.full(n, radius), np.zeros(n), Walls.floor(),
                         Parameters(gravity=(0, -g), tolerance=1e-10, max_tolerance=1e-10, max_iterations=100_000,
                                    acceleration=method))
        info = sim.step()
        force = sim.impulse[:, 0] / sim.parameters.time_step
        above = np.where(sim.points.body_j >= n, n, n - sim.points.body_j)
        np.testing.assert_allclose(force, above * sim.mass[0] * g, rtol=1e-7)
        assert info.local_law_residual < 1e-8
        found[method] = info.iterations
    assert found["anderson"] < 0.5 * found["off"], found


def test_one_pass_measures_are_the_plain_whole_array_ones():
    """On a compacted sample's problem, solved loosely (violations everywhere): the one-pass
    local-law residual and unbalanced ratios against the same formulas written with whole-array
    numpy operations (the Delassus diagonal, the per-point natural maps, masks and sums)."""
    from .conftest import compacted_problem

    sim, problem, impulse, v_free, omega_free = compacted_problem(3)
    pn, pt = impulse[:, 0].copy(), impulse[:, 1].copy()
    vx, vy, w = v_free[:, 0].copy(), v_free[:, 1].copy(), omega_free.copy()
    nlgs.solve_problem(problem, pn, pt, vx, vy, w, tolerance=1e-2, max_tolerance=1.0, max_iterations=3)
    wnn = nlgs.delassus(problem).nn
    fn, ft = residuals.local_law_residuals(problem, Impulses(pn, pt), Velocities(vx, vy, w), wnn)
    expected = np.sqrt(np.sum(fn * fn + ft * ft)) / np.sqrt(np.sum(pn * pn + pt * pt))
    got = residuals.local_law_residual(problem, pn, pt, vx, vy, w)
    assert got == pytest.approx(expected, rel=1e-12) and got > 1e-4
    external = 1e-4 * sim.mass[:, None] * np.array([0.0, -9.81])
    loaded = pn > 0
    mean = np.mean(np.hypot(pn[loaded], pt[loaded]))
    fx, fy, torque = residuals.particle_imbalance(problem, Impulses(pn, pt), sim.n_particles)
    force = np.hypot(fx + external[:, 0], fy + external[:, 1]).max() / mean
    moment = np.max(np.abs(torque) / sim.radius) / mean
    assert residuals.unbalanced_ratios(problem, pn, pt, external, sim.radius) == pytest.approx((force, moment),
                                                                                              rel=1e-12)
