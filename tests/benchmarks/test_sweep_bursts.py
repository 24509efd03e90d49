"""benchmarks/archive/sweep_bursts.py: its point keys match the stepper's, its extrapolated warm start
follows the rule by hand, and its anatomy of a captured step obeys the triangle inequality and
agrees with the solver's own residuals."""

import numpy as np
import pytest

from .conftest import load_benchmark


@pytest.fixture(scope="module")
def bursts():
    return load_benchmark("archive.sweep_bursts")


@pytest.fixture(scope="module")
def captured(bursts, pentagon_sample):
    sim, _ = load_benchmark("common").load_sample(pentagon_sample)
    bounds = sim.walls.box_bounds()
    return sim, bounds, bursts.capture(sim, 2, 6)


def test_capture_keeps_the_steps_asked_for(captured):
    sim, _, caught = captured
    assert [c["step"] for c in caught] == [2, 3, 4, 5, 6]
    assert all(c["sweeps"] >= 1 and c["pn"].size == c["problem"].a.size for c in caught)
    assert "step" not in vars(sim)  # the counting wrapper is removed


def test_point_keys_match_the_stepper_keys(bursts, captured):
    """Two steps' points matched by the script's keys pair up exactly as by the stepper's
    (solver.contact_points.point_keys), whose matching gives the warm start: the captured warm
    start of step 6 is step 5's solution at the same points."""
    sim, _, caught = captured
    from solver import acceleration

    five, six = caught[3], caught[4]
    pn, pt = five["pn"].copy(), five["pt"].copy()
    o = five["options"]
    acceleration.solve_problem_anderson(five["problem"], pn, pt, five["vx"].copy(), five["vy"].copy(),
                                        five["w"].copy(), tolerance=o["tolerance"], max_tolerance=o["max_tolerance"],
                                        max_iterations=o["max_iterations"], memory=3, period=2, stall=200)
    keys5, keys6 = bursts.point_keys_of(five["problem"]), bursts.point_keys_of(six["problem"])
    assert len(np.unique(keys6)) == keys6.size
    order = np.argsort(keys5)
    where = np.minimum(np.searchsorted(keys5[order], keys6), keys5.size - 1)
    hit = keys5[order][where] == keys6
    np.testing.assert_allclose(six["pn"][hit], pn[order[where[hit]]], rtol=1e-12, atol=0)
    assert np.all(six["pn"][~hit] == 0.0)  # new points start from nothing
    assert hit.mean() > 0.9


def test_extrapolated_warm_start_by_hand(bursts, captured):
    _, _, caught = captured
    previous, case = caught[0], caught[1]
    keys, old = bursts.point_keys_of(case["problem"]), bursts.point_keys_of(previous["problem"])
    pn, pt = bursts.extrapolated(previous, case, 0.5)
    mu = case["problem"].mu
    for k in range(keys.size):
        match = np.flatnonzero(old == keys[k])
        n, t = case["pn"][k], case["pt"][k]
        if match.size:
            n, t = n + 0.5 * (n - previous["pn"][match[0]]), t + 0.5 * (t - previous["pt"][match[0]])
        n = max(n, 0.0)
        assert pn[k] == pytest.approx(n, rel=1e-12, abs=1e-300)
        assert pt[k] == pytest.approx(min(max(t, -mu[k] * n), mu[k] * n), rel=1e-12, abs=1e-300)


def test_anatomy_obeys_the_triangle_inequality_and_the_solvers_residuals(bursts, captured):
    from solver import nlgs

    sim, bounds, caught = captured
    case = caught[0]
    a = bursts.anatomy(case, bounds, sim.n_particles, sweeps=30, drift_from=10)
    assert 0.0 < a["net_over_gross"] <= 1.0 + 1e-12  # |sum of changes| <= sum of |changes| in the W_k seminorm
    assert 1 / bursts.GRID ** 2 <= a["cells90"] <= 1.0
    assert a["velocity_ratio"] >= 0.0
    assert sorted(a["checkpoints"]) == [10, 20, 30]
    # the quadratic norm after 30 plain sweeps is the NLGS's own after 30 sweeps
    P = case["problem"]
    pn, pt, vx, vy, w = (case[k].copy() for k in ("pn", "pt", "vx", "vy", "w"))
    result = nlgs.solve_problem(P, pn, pt, vx, vy, w, tolerance=0.0, max_tolerance=0.0, max_iterations=30)
    assert result.iterations == 30
    assert a["checkpoints"][30][0] == pytest.approx(result.residual, rel=1e-9)


def test_apgd_probe_finds_the_weight_of_a_disk_on_the_floor(bursts):
    """One disk at rest on the floor under gravity: the one solution is p_n = m g h, p_t = 0."""
    from solver import gravity_scene
    from solver.nlgs import ContactProblem

    sim = gravity_scene([[0.0, 0.0125]], [0.0], [0.0125], [0], acceleration="off")
    caught = []
    import solver.nlgs as nlgs
    solve = nlgs.solve_problem

    def capture(problem, pn, pt, vx, vy, w, **options):
        caught.append(dict(problem=problem, pn=pn.copy(), pt=pt.copy(), vx=vx.copy(), vy=vy.copy(), w=w.copy()))
        return solve(problem, pn, pt, vx, vy, w, **options)

    nlgs.solve_problem = capture
    try:
        sim.step()
    finally:
        nlgs.solve_problem = solve
    case = caught[0]
    assert isinstance(case["problem"], ContactProblem) and case["problem"].a.size == 1
    reached, (law, pn, pt) = bursts.apgd_probe(case, 1e-12, iterations=50, check_every=1)
    assert reached is not None and law <= 1e-12
    assert pn[0] == pytest.approx(sim.mass[0] * 9.81 * 5e-4, rel=1e-10)
    assert abs(pt[0]) <= 1e-12 * pn[0]


def test_shear_with_the_probe_restores_the_solver(bursts, tmp_path_factory):
    """A shear with the probe as the step's solve: every step is recorded, a step that the
    probe finished has no NLGS sweeps in its work only if it stopped at the target, and the
    solver's own solve is back afterwards."""
    from solver import acceleration

    compaction = load_benchmark("compaction")
    path = str(tmp_path_factory.mktemp("probe") / "pentagons.pkl")
    compaction.compact("pentagon", 60, 1, "fast", acceleration="anderson", save=path)
    load_sample = load_benchmark("common").load_sample
    solve = acceleration.solve_problem_anderson
    default = bursts.shear(load_sample(path)[0], 0.002)
    probed = bursts.shear(load_sample(path)[0], 0.002, apgd_target=1e-3, apgd_iterations=50)
    assert acceleration.solve_problem_anderson is solve
    assert default["fallbacks"] == 0 and len(default["work"]) > 5
    assert len(probed["work"]) > 5 and 0 <= probed["fallbacks"] <= len(probed["work"])
    finished = probed["work"] <= 50
    assert np.all(probed["work"][finished] % 10 == 0)  # stopped at a check, every 10 iterations
    assert np.all(probed["law"][finished] <= 1e-3)  # ... at the target, by the solver's own measure


def test_shear_records_the_top_walls_q_over_p_from_its_stress(bursts, tmp_path_factory):
    """q/p of the shear's record against the wall stress the file's analysis would read: at the
    last step, (sigma_top - sigma_0) / (sigma_top + sigma_0) from the impulses on the top wall."""
    compaction = load_benchmark("compaction")
    path = str(tmp_path_factory.mktemp("qp") / "pentagons.pkl")
    compaction.compact("pentagon", 60, 2, "fast", acceleration="anderson", save=path)
    sim = load_benchmark("common").load_sample(path)[0]
    run = bursts.shear(sim, 0.002)
    top = sim.n_particles + sim.walls.index("top")
    on_top = (sim.points.body_i == top) | (sim.points.body_j == top)
    lo, hi = sim.walls.box_bounds()
    sigma = sim.impulse[on_top, 0].sum() / sim.parameters.time_step / ((hi[0] - lo[0]) * sim.parameters.thickness)
    assert run["q_over_p"][-1] == pytest.approx((sigma - sim.sigma0) / (sigma + sim.sigma0), rel=1e-9)
    assert len(run["q_over_p"]) == len(run["work"])
