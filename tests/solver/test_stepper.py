"""Moreau-Jean stepping against hand-computed answers: driven walls, a gap closing within a
step, overlaps not pushed out, warm start, random ordering, parameter validation.

(The DONE-list analytic cases -- disk and pentagon at rest, column of ten disks, pentagon on a
tilted plane, head-on collision -- are in test_physics.py.)"""

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver import Parameters, Simulation, Walls, gravity_scene

from .conftest import EXACT, G, PENTAGON_ON_EDGE, R


def test_velocity_driven_wall_moves_at_its_velocity():
    walls = Walls.box(1.0, 1.0)
    walls.drive_velocity("top", (0.0, -0.01))
    sim = Simulation([[0.5, 0.5]], [0.0], [R], [0], walls, Parameters(**EXACT))
    for _ in range(100):
        sim.step()
    assert sim.walls.point[2, 1] == pytest.approx(1.0 - 0.01 * 100 * 5e-4, rel=1e-14)
    np.testing.assert_allclose(sim.walls.point[[0, 1, 3]], [[0, 0], [1, 0], [0, 0]], atol=0)


def test_stress_driven_wall_squeezes_a_disk_with_sigma_times_length():
    sigma, height = 1e4, 0.2
    walls = Walls.box(2 * R + 1e-4, height)
    walls.drive_stress("right", sigma, mass=1.0)
    sim = Simulation([[R, 0.1]], [0.0], [R], [0], walls, Parameters(overlap_recovery_speed=0.0, **EXACT))
    for _ in range(200):
        sim.step()
    # the wall is at rest on the disk, which is at rest on the left wall
    assert abs(sim.walls.velocity[1, 0]) < 1e-12 and np.abs(sim.velocity[0]).max() < 1e-12
    assert sim.wall_stresses()[1] == pytest.approx(sigma, rel=1e-9)
    forces = sim.wall_forces()
    np.testing.assert_allclose(forces[1], [sigma * height, 0.0], rtol=1e-9, atol=1e-9)  # pushed right
    np.testing.assert_allclose(forces[3], [-sigma * height, 0.0], rtol=1e-9, atol=1e-9)  # and left


def test_open_gap_closes_within_one_step_with_theta_one():
    """theta = 1: the gap at the end of the step is g + h u_end >= 0, so a disk 0.1 mm above
    the floor falling at 1 m/s (h = 0.5 ms) lands exactly, leaving with u = -g/h = -0.2 m/s."""
    gap = 1e-4
    sim = gravity_scene([[0.0, R + gap]], [0.0], [R], [0], gravity=0.0, theta=1.0, **EXACT)
    sim.velocity[0] = (0.0, -1.0)
    sim.step()
    assert sim.velocity[0, 1] == pytest.approx(-gap / 5e-4, rel=1e-12)
    assert sim.position[0, 1] == pytest.approx(R, rel=1e-14)
    sim.step()  # now in contact: the disk stops, without bouncing
    assert sim.velocity[0, 1] == 0.0 and sim.position[0, 1] == pytest.approx(R, rel=1e-14)


@pytest.mark.parametrize("method", ["off", "anderson"])
def test_existing_overlap_is_not_pushed_out_explosively(method):
    """Two disks at rest overlapping by 0.1 mm: the real velocities stay zero (IQS law); the
    split-impulse recovery (solved with the step's own kind of sweeps) separates them at most
    at ``overlap_recovery_speed``."""
    overlap, speed, h = 1e-4, 1e-3, 5e-4
    sim = Simulation([[0.0, 0.0], [2 * R - overlap, 0.0]], [0.0, 0.0], [R, R], [0, 0], Walls([], []),
                     Parameters(overlap_recovery_speed=speed, acceleration=method, **EXACT))
    for k in range(1, 6):
        sim.step()
        assert np.abs(sim.velocity[:2]).max() == 0.0
        distance = sim.position[1, 0] - sim.position[0, 0]
        assert 2 * R - overlap < distance <= 2 * R - overlap + k * speed * h * (1 + 1e-9)
    assert sim.last.max_interpenetration > 0


def test_warm_start_makes_a_settled_step_converge_in_one_sweep():
    n = 6
    sim = gravity_scene(np.stack([np.zeros(n), R + 2 * R * np.arange(n)], -1), np.zeros(n), np.full(n, R),
                        np.zeros(n), tolerance=1e-8, max_tolerance=1e-8)
    first = sim.step()
    for _ in range(5):
        sim.step()
    assert first.iterations > 1
    assert sim.last.iterations == 1 and sim.last.converged


def test_warm_start_set_from_pairs_and_scaled():
    # a settled column: its impulses, given back pair by pair, warm-start the next step to one
    # sweep; the same impulses halved (a time step halved) too, since h is halved with them
    n = 6
    kwargs = dict(tolerance=1e-8, max_tolerance=1e-8)
    sim = gravity_scene(np.stack([np.zeros(n), R + 2 * R * np.arange(n)], -1), np.zeros(n), np.full(n, R),
                        np.zeros(n), **kwargs)
    for _ in range(6):
        sim.step()
    pts = sim.points
    pairs = np.flatnonzero(np.r_[True, pts.pair[1:] != pts.pair[:-1]])
    assert np.all(pts.kind == 1)  # disks: one point per pair, rank 0
    normal = np.zeros((len(pairs), 2))
    tangential = np.zeros((len(pairs), 2))
    normal[:, 0], tangential[:, 0] = sim.impulse[pairs, 0], sim.impulse[pairs, 1]
    fresh = gravity_scene(sim.position, sim.angle, sim.radius, np.zeros(n), **kwargs)
    fresh.velocity[:] = sim.velocity
    fresh.set_warm_start(pts.body_i[pairs], pts.body_j[pairs], normal, tangential)
    assert fresh.step().iterations == 1
    np.testing.assert_allclose(fresh.impulse, sim.impulse, rtol=1e-6)
    fresh.scale_warm_start(0.5)
    fresh.parameters.time_step *= 0.5
    assert fresh.step().iterations == 1
    np.testing.assert_allclose(fresh.impulse, 0.5 * sim.impulse, rtol=1e-6)


def test_random_ordering_gives_the_same_column_forces():
    n = 8
    forces = []
    for shuffle in (False, True):
        sim = gravity_scene(np.stack([np.zeros(n), R + 2 * R * np.arange(n)], -1), np.zeros(n), np.full(n, R),
                            np.zeros(n), shuffle=shuffle, acceleration="off", seed=3, **EXACT)
        for _ in range(5):
            sim.step()
        key = sim.points.body_i * 100 + sim.points.body_j
        forces.append(sim.impulse[np.argsort(key), 0] / 5e-4)
    weight = sim.mass[0] * G
    np.testing.assert_allclose(forces[0], forces[1], rtol=1e-9)
    assert forces[1].max() == pytest.approx(n * weight, rel=1e-9)


def test_pentagon_double_contact_forces_are_equal_with_random_ordering():
    inradius = R * np.cos(np.pi / 5)
    sim = gravity_scene([[0.0, inradius]], [PENTAGON_ON_EDGE], [R], [5], shuffle=True, acceleration="off", seed=11,
                       **EXACT)
    for _ in range(5):
        sim.step()
    f = sim.impulse[:, 0] / 5e-4
    assert len(f) == 2 and np.all(sim.points.kind == 2)
    assert f[0] == pytest.approx(f[1], rel=1e-6)
    assert f.sum() == pytest.approx(sim.mass[0] * G, rel=1e-9)


@pytest.mark.parametrize("bad", [dict(theta=0.3), dict(time_step=-1.0), dict(friction=-0.1), dict(friction=1e9),
                                 dict(wall_friction=np.inf), dict(max_iterations=0), dict(gravity=(0.0, np.nan)),
                                 dict(alert=-1.0), dict(acceleration="fast"), dict(anderson_memory=0),
                                 dict(anderson_period=0), dict(domains=2, shuffle=True, acceleration="off"),
                                 dict(shuffle=True), dict(stall_sweeps=600, max_iterations=1000)])
def test_invalid_parameters_are_refused_with_their_name(bad):
    name = next(iter(bad))
    with pytest.raises(ParameterError, match=name):
        Parameters(**bad).validate()


def test_invalid_bodies_are_refused():
    with pytest.raises(ParameterError, match="n_vertices"):
        Simulation([[0.0, 0.0]], [0.0], [R], [2], Walls.floor())
    with pytest.raises(ParameterError, match="radius"):
        Simulation([[0.0, 0.0]], [0.0], [-R], [0], Walls.floor())


def test_shuffled_sweeps_are_random_permutations_and_leave_numbas_generator_alone():
    from numba import njit

    from solver.nlgs import _shuffle

    @njit
    def draws(seed):
        np.random.seed(seed)
        return np.random.random()

    @njit
    def next_draw():
        return np.random.random()

    order = np.arange(50)
    state = _shuffle(order, np.uint64(12345))
    assert sorted(order.tolist()) == list(range(50)) and order.tolist() != list(range(50))
    again = np.arange(50)
    _shuffle(again, np.uint64(12345))
    np.testing.assert_array_equal(order, again)  # the same seed, the same order
    other = np.arange(50)
    _shuffle(other, state)
    assert other.tolist() != order.tolist()
    # a shuffled NLGS step between two draws of numba's global generator does not move it
    draws(7)
    expected = next_draw()
    draws(7)
    sim = gravity_scene(np.stack([np.zeros(4), R + 2 * R * np.arange(4)], -1), np.zeros(4), np.full(4, R),
                        np.zeros(4), shuffle=True, acceleration="off", seed=3, **EXACT)
    sim.step()
    assert next_draw() == expected


def test_matched_impulses_are_those_of_the_same_keys():
    """The warm start against a dictionary from key to last impulse: points kept (in a new
    order), points new (0) and points gone, keys nearly sorted as detection gives them."""
    from types import SimpleNamespace

    rng = np.random.default_rng(5)
    last_keys = np.sort(rng.choice(10**6, 400, replace=False)).astype(np.int64)
    last_keys[[10, 11]] = last_keys[[11, 10]]  # nearly sorted
    last = rng.normal(size=(400, 2))
    keys = np.concatenate([last_keys[50:300], rng.choice(np.arange(10**6, 2 * 10**6), 30, replace=False)])
    rng.shuffle(keys)
    state = SimpleNamespace(_keys=last_keys, _impulse=last)
    got = Simulation._matched_impulses(state, keys)
    reference = dict(zip(last_keys.tolist(), map(tuple, last)))
    expected = np.array([reference.get(k, (0.0, 0.0)) for k in keys.tolist()])
    np.testing.assert_array_equal(got, expected)
    assert np.count_nonzero(got[:, 0]) == 250
