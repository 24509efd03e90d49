"""benchmarks/stopping_rule.py on a block resting on a held floor at two points, whose one
self-stress mode is known by hand: the split of an impulse error into the part that moves the
block and the part that does not is exact, the velocity error is the body velocities' M-norm,
the sign conditions read the right points, and two solutions of the problem differ only in the
self-stress mode."""

import numpy as np
import pytest
from scipy import sparse

from .conftest import load_benchmark as load

# the block (m = 2 kg, I = 0.5 kg m2; dofs 0-2) on the floor (held: M^-1 = 0; dofs 3-5), touching
# it at (-1, -0.5) and (1, -0.5) from the block's centre, normal (0, 1), tangent t = (-1, 0);
# rows n1, t1, n2, t2 of H: e . (v + w x r) of the block, minus the floor's (its own lever arms)
H = sparse.csr_matrix(np.array([
    [0.0, 1.0, -1.0, 0.0, -1.0, 1.0],
    [-1.0, 0.0, -0.5, 1.0, 0.0, 0.0],
    [0.0, 1.0, 1.0, 0.0, -1.0, -1.0],
    [-1.0, 0.0, -0.5, 1.0, 0.0, 0.0]]))
MINV = sparse.diags([0.5, 0.5, 2.0, 0.0, 0.0, 0.0]).tocsr()
SELF_STRESS = np.array([0.0, 1.0, 0.0, -1.0])  # equal and opposite friction: H^T x = 0 on the block
MOVING = np.array([-0.3, -0.35, -0.1, -0.35])  # H c of c = (0.3, -0.2, 0.1) on the block, by hand


def _entry(initial=None):
    """The block falling at 1 m/s onto the floor, mu = 0.4, no Signorini shift."""
    v_free = np.array([0.0, -1.0, 0.0, 0.0, 0.0, 0.0])
    W = (H @ MINV @ H.T).tocsr()
    return dict(H=H, minv=MINV, v_free=v_free, W=W, q=H @ v_free, mu=np.array([0.4, 0.4]),
                initial=np.zeros((2, 2)) if initial is None else initial)


def test_the_hand_vectors_are_what_they_claim():
    block = H.toarray()[:, :3]
    assert np.allclose(SELF_STRESS @ block, 0.0)  # moves nothing
    assert np.allclose(block @ np.array([0.3, -0.2, 0.1]), MOVING)
    assert SELF_STRESS @ MOVING == pytest.approx(0.0)  # orthogonal, so the split is exact


def test_the_split_into_moving_and_self_stress_parts_is_exact():
    bench = load("stopping_rule")
    split = bench.Split(H, MINV)
    error = 0.7 * SELF_STRESS + 2.0 * MOVING
    assert np.allclose(split.moving(error), 2.0 * MOVING, atol=1e-9)
    assert np.allclose(split.moving(SELF_STRESS), 0.0, atol=1e-9)


def test_a_load_carried_by_held_walls_moves_nothing():
    # the block between the floor (below) and a ceiling (above), one point each at (0, -0.5) and
    # (0, 0.5) from its centre, normals (0, 1) and (0, -1); columns: block, floor, ceiling
    bench = load("stopping_rule")
    H2 = sparse.csr_matrix(np.array([
        [0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0],
        [-1.0, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        [1.0, 0.0, -0.5, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]]))
    squeeze = np.array([1.0, 0.0, 1.0, 0.0])  # the walls press the block from both sides
    assert np.allclose(squeeze @ H2.toarray()[:, :3], 0.0) and not np.allclose(squeeze @ H2.toarray(), 0.0)
    held = sparse.diags([0.5, 0.5, 2.0] + [0.0] * 6).tocsr()
    assert np.allclose(bench.Split(H2, held).moving(squeeze), 0.0, atol=1e-9)  # a self-stress: W squeeze = 0
    assert np.allclose((H2 @ held @ H2.T) @ squeeze, 0.0)
    free_floor = sparse.diags([0.5, 0.5, 2.0, 0.1, 0.1, 0.1, 0.0, 0.0, 0.0]).tocsr()
    # a floor free to move is pushed down: its y column (-1, 0, 0, 0) and the block's (1, 0, -1, 0)
    # span both normal rows, so all of the squeeze moves bodies
    assert np.allclose(bench.Split(H2, free_floor).moving(squeeze), squeeze, atol=1e-9)


def test_errors_measure_the_velocities_and_the_two_parts():
    bench = load("stopping_rule")
    entry = _entry()
    reference = np.array([[1.0, 0.3], [1.0, -0.3]])  # stops the block (2 N s up), pinched by 0.3 N s
    scales = bench.Scales(entry, reference)
    split = bench.Split(H, MINV)
    impulse = reference + (0.7 * SELF_STRESS + 0.01 * MOVING).reshape(2, 2)
    values = bench.errors(entry["W"], impulse, reference, scales, split)
    # the velocities directly: v = v_free + M^-1 H^T r, |x|_M over the block's dofs (M = 2, 2, 0.5)
    velocity = [entry["v_free"] + MINV @ (H.T @ r.reshape(-1)) for r in (impulse, reference)]
    mass = np.array([2.0, 2.0, 0.5])

    def m_norm(x):
        return np.sqrt(np.sum(mass * x[:3] ** 2))

    assert m_norm(velocity[1]) == pytest.approx(0.0, abs=1e-12)  # the reference stops the block
    change = m_norm(velocity[1] - entry["v_free"])  # sqrt(2 * 1^2) = sqrt(2)
    assert change == pytest.approx(np.sqrt(2.0))
    assert values["velocity"] == pytest.approx(m_norm(velocity[0] - velocity[1]) / change, rel=1e-12)
    # by hand: dv = M^-1 H^T (0.01 H c) on the block = 0.01 M^-1 (H^T H) c
    block = H.toarray()[:, :3]
    dv = 0.01 * np.array([0.5, 0.5, 2.0]) * (block.T @ MOVING)
    assert values["velocity"] == pytest.approx(m_norm(dv) / np.sqrt(2.0), rel=1e-12)
    r_size = np.sqrt(2 * 1.0 + 2 * 0.09)
    assert values["impulse"] == pytest.approx(np.linalg.norm(0.7 * SELF_STRESS + 0.01 * MOVING) / r_size)
    assert values["self-stress part"] == pytest.approx(0.7 * np.sqrt(2.0) / r_size, rel=1e-9)
    assert values["moving part"] == pytest.approx(0.01 * np.linalg.norm(MOVING) / r_size, rel=1e-6)
    assert scales.speed == pytest.approx(0.0, abs=1e-12)  # the block ends at rest
    # a zero scale gives 0 for a zero value and infinity otherwise, not a warning and nan
    assert (bench._ratio(0.0, 0.0), bench._ratio(1.0, 0.0), bench._ratio(1.0, 4.0)) == (0.0, float("inf"), 0.25)


def test_sign_violations_read_the_points_that_violate():
    bench = load("stopping_rule")
    mu = np.array([0.4, 0.4, 0.0, 0.4, 0.4])
    impulse = np.array([[1.0, 0.2], [1.0, -0.3], [1.0, 0.0], [0.0, 0.0], [2.0, 0.5]])
    velocity = np.array([[-0.2, 0.1],   # approaching at 0.2; friction along its slip: 0.1
                         [0.0, 0.5],    # friction opposes the slip: fine
                         [-0.05, 5.0],  # frictionless point sliding: fine, approaching at 0.05
                         [0.3, 9.0],    # open point: fine
                         [0.0, 0.04]])  # friction along its slip: 0.04
    assert bench.sign_violations(velocity, impulse, mu) == pytest.approx((0.2, 0.1))
    velocity[0], velocity[4] = [0.0, -0.1], [0.1, -0.04]  # both now slip against their friction
    assert bench.sign_violations(velocity, impulse, mu) == pytest.approx((0.05, 0.0))


def test_two_solutions_differ_only_in_the_self_stress_mode():
    bench = load("stopping_rule")
    pinched = np.array([[1.0, 0.3], [1.0, -0.3]])  # a solution: the block stopped, |r_t| <= 0.4 r_n
    records, reference, trajectory = bench.track(_entry(pinched), sweeps=40, cap=20)
    assert np.allclose(reference, pinched)  # a solution is a fixed point of the sweeps
    assert [k for k, _ in records] == list(range(1, 21))  # a record after every sweep up to 50
    assert all(v["velocity"] < 1e-12 and v["residual"] < 1e-12 for _, v in records)
    _, other, _ = bench.track(_entry(), sweeps=400, cap=0)
    scales = bench.Scales(_entry(), reference)
    values = bench.errors(_entry()["W"], other, reference, scales, bench.Split(H, MINV))
    assert values["velocity"] < 1e-9 and values["moving part"] < 1e-9  # the same motion
    pinch = (other[0, 1] - other[1, 1]) / 2  # the other solution's own pinch
    assert abs(pinch - 0.3) > 0.05  # NLGS from rest finds another one
    assert values["self-stress part"] == pytest.approx(abs(pinch - 0.3) * np.sqrt(2) / np.linalg.norm(pinched),
                                                       rel=1e-6)
    assert values["impulse"] == pytest.approx(values["self-stress part"], rel=1e-6)


def test_records_schedule_first_within_and_stops():
    bench = load("stopping_rule")
    assert [bench.schedule(k, 10_000) for k in (0, 49, 50, 100, 5000, 9990)] == [1, 1, 1, 2, 100, 10]
    assert bench.schedule(7, 7) == 0
    records = [(1, dict(residual=1e-2, **{"quadratic norm": 3e-4, "max norm": 1e-3, "velocity change": 1e-3})),
               (2, dict(residual=1e-3, **{"quadratic norm": 1e-4, "max norm": 2e-2, "velocity change": 1e-4})),
               (4, dict(residual=2e-3, **{"quadratic norm": 1e-4, "max norm": 1e-3, "velocity change": 1e-5}))]
    assert bench.first_within(records, "residual", 1e-3) == 2  # the first, not the last
    assert bench.first_within(records, "residual", 1e-4) is None
    found = dict((name, None if r is None else r[0]) for name, r in bench.stops(records))
    assert list(found.values()) == [4, 2, 4]  # the stepper's also needs its max norm <= 1e-2
