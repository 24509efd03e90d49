"""The domain-decomposed NLGS: on the contact problem of a real compacting sample, one
parallel sweep equals the serial sweep over the same points in the domains' order, bit for
bit (no two domains write the same body); the result does not depend on the thread count; the
decomposition puts every point whose moving bodies are in two slabs (or on a stress-driven
wall) on the interface; and whole runs stay admissible and equal for 1 or 2 threads."""

from __future__ import annotations

import dataclasses
import hashlib
import warnings

import numba
import numpy as np
import pytest

from grainview.contract.errors import ConvergenceWarning
from solver import Parameters, compaction_sample, nlgs, parallel_nlgs

from .conftest import compacted_problem
from solver.parallel_nlgs import FREE, SHARED
from solver.solve_records import DelassusBlocks, Impulses, Velocities


@pytest.fixture(scope="module")
def problem():
    """The contact problem of a step of 120 pentagons compacted under 10 kPa (a stress-driven
    right wall)."""
    return compacted_problem(3)

def _state(impulse, v_free, omega_free):
    return [impulse[:, 0].copy(), impulse[:, 1].copy(), v_free[:, 0].copy(), v_free[:, 1].copy(), omega_free.copy()]


def _stable_ranks_slab(x, domains):
    """The slabs by the definition: rank in a stable sort of x, times domains // n."""
    rank = np.empty(x.size, dtype=np.int64)
    rank[np.argsort(x, kind="stable")] = np.arange(x.size)
    return rank * domains // max(x.size, 1)


@pytest.mark.parametrize("ties", [False, True])
def test_slabs_by_selection_are_the_stable_sorts_slabs(ties):
    # distinct abscissae take the O(n) selection path; lattice-like repeated abscissae (a
    # boundary value shared by several particles) the stable sort's: both equal the definition
    rng = np.random.default_rng(3)
    for _ in range(500):
        n, domains = int(rng.integers(0, 80)), int(rng.integers(1, 17))
        x = rng.integers(0, 6, n).astype(float) if ties else rng.random(n)
        np.testing.assert_array_equal(parallel_nlgs.slab_of_particles(x, domains), _stable_ranks_slab(x, domains))
    # equal counts: 10 particles in 3 slabs hold 4, 3 and 3 (ranks 0-3, 4-6, 7-9)
    slabs = parallel_nlgs.slab_of_particles(np.linspace(1.0, 0.0, 10), 3)
    np.testing.assert_array_equal(slabs, [2, 2, 2, 1, 1, 1, 0, 0, 0, 0])


def test_decomposition_respects_bodies(problem):
    sim, prob, *_ = problem
    n = sim.n_particles
    domain = parallel_nlgs.body_domains(sim.position[:, 0], prob.minv_xx.size, prob.minv_xx, prob.minv_yy,
                                        prob.iinv, 3)
    assert np.bincount(domain[:n]).tolist() == [40, 40, 40]  # equal counts by x
    assert (domain[:n][np.argsort(sim.position[:, 0])] == np.repeat([0, 1, 2], 40)).all()
    walls = domain[n:]
    assert SHARED in walls and FREE in walls  # the stress-driven walls are shared, the fixed ones still
    ptr, points, interface = parallel_nlgs.partition_points(prob.a, prob.b, domain, 3)
    assert sorted(np.concatenate([points, interface]).tolist()) == list(range(prob.a.size))
    for d in range(3):
        mine = points[ptr[d]:ptr[d + 1]]
        assert (np.diff(mine) > 0).all()  # each domain in the points' own order
        for k in mine:
            bodies = {domain[prob.a[k]], domain[prob.b[k]]} - {FREE}
            assert bodies == {d}
    for k in interface:  # across slabs, on a shared wall, or between two still bodies
        da, db = domain[prob.a[k]], domain[prob.b[k]]
        assert SHARED in (da, db) or (da != db and FREE not in (da, db)) or da == db == FREE
    assert 0 < interface.size < prob.a.size // 2


def test_each_domain_writes_its_own_contiguous_bodies_and_copies_of_the_still_walls(problem):
    sim, prob, *_ = problem
    n_bodies = prob.minv_xx.size
    dec = parallel_nlgs.decompose(prob, sim.position[:, 0], 3)
    domain = parallel_nlgs.body_domains(sim.position[:, 0], n_bodies, prob.minv_xx, prob.minv_yy, prob.iinv, 3)
    assert sorted(dec.point_order.tolist()) == list(range(prob.a.size))
    np.testing.assert_array_equal(dec.source[dec.a], prob.a[dec.point_order])  # every body stands for its original
    np.testing.assert_array_equal(dec.source[dec.b], prob.b[dec.point_order])
    spans = []
    for d in range(3):
        mine = slice(dec.ptr[d], dec.ptr[d + 1])
        written = np.union1d(dec.a[mine], dec.b[mine])
        spans.append((written.min(), written.max()))
        assert all(domain[dec.source[j]] in (d, FREE) for j in written)
    for (lo, hi), (next_lo, _) in zip(spans, spans[1:]):
        assert hi < next_lo  # each domain's bodies in a block of their own: no shared cache line but at the edge
    moving = set(dec.source[dec.moving].tolist())
    assert moving == {j for j in range(n_bodies) if domain[j] != FREE}
    assert len(dec.moving) == len(moving)


def test_parallel_sweep_is_the_serial_sweep_in_domain_order(problem):
    sim, prob, impulse, v_free, omega_free = problem
    dec = parallel_nlgs.decompose(prob, sim.position[:, 0], 2)
    blocks = nlgs.delassus(prob)
    pn, pt, vx, vy, w = _state(impulse, v_free, omega_free)
    renumbered, *parallel = dec.gather(prob, pn, pt, vx, vy, w)
    nlgs.velocities_from_impulses(renumbered, *parallel)
    serial = _state(impulse, v_free, omega_free)  # the same start, laid out as the problem is
    dec.scatter(*parallel, *serial)
    serial_impulses, serial_velocities = Impulses(*serial[:2]), Velocities(*serial[2:])
    order = dec.point_order
    for _ in range(25):
        a = nlgs.sweep(order, prob, serial_impulses, serial_velocities, blocks)
        b = parallel_nlgs.sweep_domains(dec.ptr, dec.points, dec.interface, renumbered, *parallel,
                                        DelassusBlocks(*(x[order] for x in blocks)))
        # the same updates; the sums differ only by the order of their terms
        assert b[0] == pytest.approx(a[0], rel=1e-12) and b[1] == a[1]
        assert b[2] == pytest.approx(a[2], rel=1e-12) and b[3] == a[3]
    dec.scatter(*parallel, pn, pt, vx, vy, w)
    for x, y in zip(serial, (pn, pt, vx, vy, w)):
        np.testing.assert_array_equal(x, y)
    still = np.setdiff1d(np.arange(len(dec.source)), dec.moving)  # copies of the walls keep their velocity
    np.testing.assert_array_equal(parallel[1].vx[still], serial[2][dec.source[still]])
    assert serial[0].max() > 0


def _solve(prob, sim, impulse, v_free, omega_free, domains):
    s = _state(impulse, v_free, omega_free)
    result = parallel_nlgs.solve_problem_domains(prob, sim.position[:, 0], *s, domains=domains, tolerance=1e-8,
                                                 max_tolerance=1e-6, max_iterations=20000)
    return result, s


def test_solution_does_not_depend_on_threads_and_is_admissible(problem):
    from solver import residuals

    sim, prob, impulse, v_free, omega_free = problem
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one, s1 = _solve(prob, sim, impulse, v_free, omega_free, 2)
        numba.set_num_threads(max(2, threads) if numba.config.NUMBA_NUM_THREADS >= 2 else 1)
        two, s2 = _solve(prob, sim, impulse, v_free, omega_free, 2)
    finally:
        numba.set_num_threads(threads)
    assert one == two
    for x, y in zip(s1, s2):
        np.testing.assert_array_equal(x, y)
    # an admissible solution: the local laws hold (the same measure the serial solver is judged by)
    law = residuals.local_law_residual(prob, *s1)
    serial = _state(impulse, v_free, omega_free)
    nlgs.solve_problem(prob, *serial, tolerance=1e-8, max_tolerance=1e-6, max_iterations=20000)
    assert law < 1e-5 and residuals.local_law_residual(prob, *serial) < 1e-5
    # both orders carry the same confining load on the walls (different networks, same statics)
    assert s1[0].sum() == pytest.approx(serial[0].sum(), rel=1e-3)


def test_runs_with_domains_are_deterministic_and_refuse_other_orders():
    def run(threads):
        numba.set_num_threads(threads)
        sim = compaction_sample(80, "disk", seed=1)
        sim.parameters = dataclasses.replace(sim.parameters, domains=2)
        with warnings.catch_warnings():  # the first steps of a deposit hit the sweep cap, whatever the order
            warnings.simplefilter("ignore", ConvergenceWarning)
            for _ in range(150):
                sim.step()
        return hashlib.sha256(sim.position.tobytes() + sim.velocity.tobytes()).hexdigest()

    threads = numba.get_num_threads()
    try:
        assert run(1) == run(threads)
    finally:
        numba.set_num_threads(threads)
    from grainview.contract.errors import ParameterError

    with pytest.raises(ParameterError, match="domains"):
        Parameters(domains=2, shuffle=True, acceleration="off").validate()
    Parameters(domains=2, acceleration="anderson").validate()  # the Anderson form runs on domains too
    with pytest.raises(ParameterError, match="domains"):
        Parameters(domains=0).validate()


def test_gather_and_scatter_are_numpy_indexing(problem):
    """The renumbering kernels against numpy's fancy indexing: the arrays taken at the new
    numbering, and written back (the moving bodies' velocities only)."""
    sim, prob, impulse, v_free, omega_free = problem
    dec = parallel_nlgs.decompose(prob, sim.position[:, 0], 3)
    state = _state(impulse, v_free, omega_free)
    renumbered_problem, *renumbered = dec.gather(prob, *state)
    k, j = dec.point_order, dec.source
    assert renumbered_problem.a is dec.a and renumbered_problem.b is dec.b
    for got, original in zip(renumbered_problem[2:], prob[2:]):
        np.testing.assert_array_equal(got, original[k if original.size == prob.a.size else j])
    renumbered = (*renumbered[0], *renumbered[1])
    for got, original, index in zip(renumbered, state, (k, k, j, j, j)):
        np.testing.assert_array_equal(got, original[index])
    rng = np.random.default_rng(0)
    solved = tuple(rng.normal(size=x.size) for x in renumbered)
    back = [x.copy() for x in state]
    dec.scatter(Impulses(*solved[:2]), Velocities(*solved[2:]), *back)
    expected = [x.copy() for x in state]
    expected[0][k], expected[1][k] = solved[0], solved[1]
    for original, new in zip(expected[2:], solved[2:]):
        original[j[dec.moving]] = new[dec.moving]
    for got, want in zip(back, expected):
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("domains", [2, 3])
def test_start_of_a_domain_solve_is_the_serial_start_bit_for_bit(problem, domains):
    """The threads' Delassus blocks and start velocities against the serial kernels on the same
    renumbered problem, and the velocities against numpy: v = v_free + M^-1 H p summed point by
    point with np.add.at (a different order of the sums: equal to round-off)."""
    sim, prob, impulse, v_free, omega_free = problem
    dec = parallel_nlgs.decompose(prob, sim.position[:, 0], domains)
    renumbered_problem, *state = dec.gather(prob, *_state(impulse, v_free, omega_free))
    renumbered = (*state[0], *state[1])
    m = dec.a.size
    blocks = np.append(dec.ptr, m)
    threads = [x.copy() for x in renumbered]
    w_threads = DelassusBlocks(np.empty(m), np.empty(m), np.empty(m))
    parallel_nlgs.start_domains(blocks, renumbered_problem, Impulses(*threads[:2]), Velocities(*threads[2:]),
                                w_threads)
    serial = [x.copy() for x in renumbered]
    w_serial = DelassusBlocks(np.empty(m), np.empty(m), np.empty(m))
    nlgs.delassus_into(renumbered_problem, w_serial)
    nlgs.velocities_from_impulses(renumbered_problem, Impulses(*serial[:2]), Velocities(*serial[2:]))
    for got, want in zip([*w_threads, *threads], [*w_serial, *serial]):
        np.testing.assert_array_equal(got, want)
    # the velocities by numpy: each point's impulse p_n n + p_t t applied at its lever arms
    a, b, nx, ny, rax, ray, rbx, rby = renumbered_problem[:8]
    minv_xx, minv_xy, minv_yy, iinv = renumbered_problem[10:]
    pn, pt, vx, vy, w = [x.copy() for x in renumbered]
    fx, fy = pn * nx - pt * ny, pn * ny + pt * nx
    for body, sign, rx, ry in ((a, -1.0, rax, ray), (b, 1.0, rbx, rby)):
        gx, gy = sign * fx, sign * fy
        np.add.at(vx, body, minv_xx[body] * gx + minv_xy[body] * gy)
        np.add.at(vy, body, minv_xy[body] * gx + minv_yy[body] * gy)
        np.add.at(w, body, iinv[body] * (rx * gy - ry * gx))
    for got, want in zip(threads[2:], (vx, vy, w)):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("acceleration", ["anderson", "off"])
def test_one_decomposition_per_step_serves_the_main_solve_and_the_recovery(acceleration):
    """A step decomposes its problem once and the overlap recovery's solve reuses it: the run is
    bit for bit the one in which every solve decomposes its own problem, with Anderson sweeps
    and with plain ones; a decomposition of another problem is refused."""

    def run(share):
        sim = compaction_sample(80, "pentagon", seed=1)
        sim.parameters = dataclasses.replace(sim.parameters, domains=2, acceleration=acceleration)
        if not share:
            sim._decomposition = lambda problem: None  # each solve then decomposes on its own
        made = []
        decompose = parallel_nlgs.decompose

        def counted(*args):
            made.append(1)
            return decompose(*args)

        parallel_nlgs.decompose = counted
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ConvergenceWarning)
                for _ in range(120):
                    sim.step()
        finally:
            parallel_nlgs.decompose = decompose
        return sim, len(made)

    shared, shared_made = run(True)
    own, own_made = run(False)
    assert shared.counters["recovery_sweeps"] > 0  # the recovery ran
    assert shared_made == 120 and own_made > 120  # once per step, against once per solve
    for name in ("position", "angle", "velocity", "impulse"):
        np.testing.assert_array_equal(getattr(shared, name), getattr(own, name))
    problem = shared._contact_problem(shared.detect(), shared.velocity, shared.angular_velocity)[0]
    other = parallel_nlgs.decompose(problem, shared.position[:shared.n_particles, 0], 3)
    state = [np.zeros(problem.a.size) for _ in range(2)] + [np.zeros(problem.minv_xx.size) for _ in range(3)]
    with pytest.raises(ValueError, match="decomposition"):
        parallel_nlgs.solve_problem_domains(problem, shared.position[:shared.n_particles, 0], *state, domains=2,
                                            tolerance=1e-4, max_tolerance=1e-2, max_iterations=5,
                                            decomposition=other)


def test_sleeping_thread_pool_is_named_once_domains_are_asked_for(monkeypatch):
    """OMP_WAIT_POLICY=passive made domain-decomposed sweeps slower than serial ones: asking for
    domains with it set warns, naming the variable; one domain, or the policy unset or active,
    does not."""
    warn_if_threads_sleep = parallel_nlgs.warn_if_threads_sleep
    with pytest.warns(RuntimeWarning, match="OMP_WAIT_POLICY=PASSIVE"):
        assert warn_if_threads_sleep(2, {"OMP_WAIT_POLICY": "PASSIVE"})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert not warn_if_threads_sleep(1, {"OMP_WAIT_POLICY": "passive"})
        assert not warn_if_threads_sleep(2, {"OMP_WAIT_POLICY": "active"})
        assert not warn_if_threads_sleep(2, {})
    monkeypatch.setenv("OMP_WAIT_POLICY", "passive")
    with pytest.warns(RuntimeWarning, match="domains=2"):
        Parameters(domains=2).validate()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Parameters(domains=1).validate()
