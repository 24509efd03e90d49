"""The solver against analytic answers: resting bodies, a column, a tilted plane, a collision."""

import numpy as np
import pytest

from solver import Parameters, Simulation, Walls, contact_solvers
from solver.shapes import mass_and_inertia

G = 9.81
R = 0.0125
EXACT = dict(tolerance=1e-12, max_tolerance=1e-12, max_iterations=100_000)
VARIANTS = [({"solver": name}, name) for name in contact_solvers.stepper_methods()] + [
    ({"solver": "nlgs", "stall_sweeps": 200}, "nlgs-stall"), ({"solver": "anderson", "anderson_period": 2},
                                                               "anderson-every-2-sweeps"),
    ({"solver": "nlgs", "domains": 2}, "nlgs-domains2"), ({"solver": "anderson", "domains": 2}, "anderson-domains2")]
SOLVERS = pytest.mark.parametrize("solver", [v for v, _ in VARIANTS], ids=[i for _, i in VARIANTS])
"""Every method of the registry the stepper can use, and their variants: the same answers."""
PENTAGON_ON_EDGE = np.radians(-54.0)  # vertices at -54 + 72 k degrees: an edge at the bottom


@SOLVERS
def test_disk_and_pentagon_resting_on_the_floor(solver):
    inradius = R * np.cos(np.pi / 5)
    sim = Simulation([[0.0, R], [0.1, inradius]], [0.0, PENTAGON_ON_EDGE], [R, R], [0, 5],
                     Walls.floor(), Parameters(gravity=(0, -G), **solver, **EXACT))
    for _ in range(10):
        sim.step()
    weight = sim.mass * G
    forces = sim.impulse[:, 0] / sim.parameters.time_step
    pts = sim.points
    disk = pts.body_i == 0
    pent = pts.body_i == 1
    assert forces[disk].sum() == pytest.approx(weight[0], rel=1e-6)
    assert forces[pent].sum() == pytest.approx(weight[1], rel=1e-6)
    assert np.all(pts.kind[pent] == 2) and pent.sum() == 2  # a double contact
    assert forces[pent][0] == pytest.approx(forces[pent][1], rel=1e-6)  # equal by symmetry
    application = (forces[pent] @ pts.point[pent]) / forces[pent].sum()
    assert application[0] == pytest.approx(0.1, abs=1e-9)  # under the centre
    np.testing.assert_allclose(sim.wall_forces()[0], [0.0, -weight.sum()], rtol=1e-6)
    assert np.abs(sim.velocity[:2]).max() < 1e-12


@SOLVERS
def test_column_of_ten_disks_carries_the_weight_above(solver):
    n = 10
    y = R + 2 * R * np.arange(n)
    sim = Simulation(np.stack([np.zeros(n), y], -1), np.zeros(n), np.full(n, R), np.zeros(n),
                     Walls.floor(), Parameters(gravity=(0, -G), **solver, **EXACT))
    for _ in range(20):
        sim.step()
    pts = sim.points
    force = sim.impulse[:, 0] / sim.parameters.time_step
    weight = sim.mass[0] * G
    for k in range(len(force)):
        above = n - max(pts.body_i[k], pts.body_j[k]) if pts.body_j[k] < n else n
        if pts.body_j[k] >= n:  # disk 0 on the floor carries all ten
            above = n
        else:
            above = n - pts.body_j[k]
        assert force[k] == pytest.approx(above * weight, rel=1e-6)


@SOLVERS
@pytest.mark.parametrize("alpha_deg", [15.0, 30.0])
def test_pentagon_on_a_tilted_plane(alpha_deg, solver):
    mu = 0.4
    alpha = np.radians(alpha_deg)
    gravity = (G * np.sin(alpha), -G * np.cos(alpha))  # the plane is the floor, gravity tilted
    inradius = R * np.cos(np.pi / 5)
    sim = Simulation([[0.0, inradius]], [PENTAGON_ON_EDGE], [R], [5], Walls.floor(),
                     Parameters(gravity=gravity, wall_friction=mu, **solver, **EXACT))
    h = sim.parameters.time_step
    for _ in range(5):
        sim.step()
    v0 = sim.velocity[0, 0]
    steps = 40
    for _ in range(steps):
        sim.step()
    acceleration = (sim.velocity[0, 0] - v0) / (steps * h)
    if np.tan(alpha) < mu:
        assert abs(sim.velocity[0, 0]) < 1e-12 and abs(acceleration) < 1e-9
    else:
        expected = G * (np.sin(alpha) - mu * np.cos(alpha))
        assert acceleration == pytest.approx(expected, rel=1e-6)
        assert abs(sim.velocity[0, 1]) < 1e-12 and abs(sim.angular_velocity[0]) < 1e-9


@pytest.mark.parametrize("recovery_speed, steps", [(0.0, 20), (1e-3, 1000)])
def test_head_on_collision_conserves_momentum_and_is_inelastic(recovery_speed, steps):
    """Without overlap recovery the disks stop dead against each other; with it, the overlap
    the theta-scheme leaves (about h (1 - theta) u) is removed gently and they still end at
    rest relative to each other. Momentum is conserved throughout."""
    v = 0.3
    sim = Simulation([[0.0, 0.0], [2 * R + 1e-5, 0.0]], [0.0, 0.0], [R, R], [0, 0], Walls([], []),
                     Parameters(overlap_recovery_speed=recovery_speed, **EXACT), velocity=[[v, 0.0], [-v, 0.0]])
    momentum = sim.mass @ sim.velocity[:2]
    for _ in range(steps):
        sim.step()
        np.testing.assert_allclose(sim.mass @ sim.velocity[:2], momentum, atol=1e-12 * sim.mass.sum() * v)
    relative = sim.velocity[1] - sim.velocity[0]
    assert abs(relative[0]) < 1e-12  # inelastic: no rebound
    assert abs(relative[1]) < 1e-15
    assert sim.velocity[0, 0] == pytest.approx(0.0, abs=1e-12)  # equal masses: both at rest
    if recovery_speed:
        # overlaps below the recovery threshold (1e-4 of the diameter) are left alone
        assert sim.last.max_interpenetration <= 1e-4 * 2 * R


def test_masses_and_inertia_of_regular_polygons():
    from grainview.contract.shapes import particle_area
    # a square of circumscribed radius 1: side sqrt(2), area 2, I = m s^2/6 = m/3
    m, inertia = mass_and_inertia(1.0, 4, density=1.0)
    assert m == pytest.approx(2.0, rel=1e-14) and inertia == pytest.approx(2.0 / 3, rel=1e-14)
    # a triangle-fan integral for a pentagon
    r, n = 0.7, 5
    k = np.arange(n)
    v = r * np.stack([np.cos(2 * np.pi * k / n), np.sin(2 * np.pi * k / n)], -1)
    w = np.roll(v, -1, axis=0)
    cross = v[:, 0] * w[:, 1] - v[:, 1] * w[:, 0]
    area = 0.5 * cross.sum()
    polar = (cross * (np.sum(v * v, 1) + np.sum(v * w, 1) + np.sum(w * w, 1))).sum() / 12
    m, inertia = mass_and_inertia(r, n, density=3.0, thickness=2.0)
    assert m == pytest.approx(6.0 * area, rel=1e-13)
    assert inertia == pytest.approx(6.0 * polar, rel=1e-13)
    assert particle_area(r, n) == pytest.approx(area, rel=1e-13)


def test_non_convergence_warns():
    n = 10
    y = R + 2 * R * np.arange(n)
    sim = Simulation(np.stack([np.zeros(n), y], -1), np.zeros(n), np.full(n, R), np.zeros(n), Walls.floor(),
                     Parameters(gravity=(0, -G), tolerance=1e-14, max_tolerance=1e-14, max_iterations=2))
    with pytest.warns(Warning, match=r"the contact solver \(anderson\) did not converge at step 0 \(t = 0 s\): "
                                    r"stopped by the sweep cap after 2 sweeps"):
        sim.step()
    assert not sim.last.converged and sim.last.iterations == 2
