"""Anderson-accelerated NLGS against a slow numpy version of the same method.

The kernel (solver.acceleration) keeps its history point by point, solves the least-squares
problem by normal equations updated one row per sweep and updates the body velocities by the
extrapolation's change. The reference below keeps whole vectors, calls numpy's least squares
and rebuilds the velocities from the free ones: the two must give the same iterates, serial
and over the domain-decomposed sweep, and the domain form must not depend on the thread count.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from solver import acceleration, nlgs, parallel_nlgs, residuals
from solver.solve_records import Impulses, Limits, Velocities

from .conftest import compacted_problem


@pytest.fixture(scope="module")
def problem():
    """The contact problem of a step of 120 pentagons compacted under 10 kPa, warm-started."""
    sim, prob, impulse, v_free, omega_free = compacted_problem(5)
    # half the warm start: the solve has work to do
    state = [0.5 * impulse[:, 0], 0.5 * impulse[:, 1], v_free[:, 0].copy(), v_free[:, 1].copy(), omega_free.copy()]
    return sim, prob, state

def _copy(state):
    return [s.copy() for s in state]


def reference_anderson(prob, state, sweep, iterations, memory, period=1, resets=None):
    """Anderson type II on the fixed-point map '``period`` sweeps', with whole vectors: gamma
    from numpy's least squares on the last ``memory`` differences, the extrapolation projected
    on the Coulomb cones, the velocities rebuilt from the free ones; the history is forgotten
    when |f| grows; the last sweep is not extrapolated (its iterate is the one its norms
    describe). Returns the impulses after ``iterations`` sweeps; ``resets``, a list, receives
    the index of each map after which a history was forgotten because |f| grew."""
    mu = prob.mu
    pn, pt, vx, vy, w = state
    impulses, velocities = Impulses(pn, pt), Velocities(vx, vy, w)
    free = (vx.copy(), vy.copy(), w.copy())
    blocks = nlgs.delassus(prob)
    nlgs.velocities_from_impulses(prob, impulses, velocities)
    fs, gs, last = [], [], np.inf
    maps = iterations // period
    for k in range(maps):
        x = np.concatenate([pn, pt])
        for _ in range(period):
            sweep(impulses, velocities, blocks)
        if k == maps - 1:
            break
        g = np.concatenate([pn, pt])
        f = g - x
        if f @ f > last and fs and resets is not None:
            resets.append(k)
        if f @ f > last or not fs:
            fs, gs = [], []
        last = f @ f
        fs, gs = (fs + [f])[-(memory + 1):], (gs + [g])[-(memory + 1):]
        if len(fs) < 2:
            continue
        d_f, d_g = np.diff(fs, axis=0).T, np.diff(gs, axis=0).T
        gamma = np.linalg.lstsq(d_f, f, rcond=None)[0]
        e = g - d_g @ gamma
        m = pn.size
        projected = np.array([residuals.cone_projection(e[k], e[m + k], mu[k]) for k in range(m)])
        pn[:], pt[:] = projected[:, 0], projected[:, 1]
        vx[:], vy[:], w[:] = free[0], free[1], free[2]
        nlgs.velocities_from_impulses(prob, impulses, velocities)
    return pn, pt


ITERATIONS = 18


@pytest.mark.parametrize("period", [1, 2, 3])
def test_serial_kernel_equals_the_numpy_reference(problem, period):
    _, prob, state = problem
    order = np.arange(prob.a.size)

    def sweep(impulses, velocities, blocks):
        nlgs.sweep(order, prob, impulses, velocities, blocks)

    expected = reference_anderson(prob, _copy(state), sweep, ITERATIONS, memory=4, period=period)
    got = _copy(state)
    result = acceleration.solve_problem_anderson(prob, *got, tolerance=0.0, max_tolerance=0.0,
                                                 max_iterations=ITERATIONS, memory=4, period=period)
    assert result.iterations == ITERATIONS
    scale = np.abs(expected[0]).max()
    np.testing.assert_allclose(got[0], expected[0], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(got[1], expected[1], rtol=0, atol=1e-9 * scale)
    # the incremental velocity updates stay v = v_free + M^-1 H p
    rebuilt = _copy(state)[2:]
    nlgs.velocities_from_impulses(prob, Impulses(got[0], got[1]), Velocities(*rebuilt))
    for v, r in zip(got[2:], rebuilt):
        np.testing.assert_allclose(v, r, rtol=0, atol=1e-12 * np.abs(r).max())


@pytest.mark.parametrize("period", [1, 2])
def test_serial_kernel_equals_the_reference_through_the_safeguard(problem, period):
    """Over 40 sweeps the iterate's change |f| grows a few times: each time the history must
    be forgotten and plain sweeps kept, in the kernel as in the reference (without the
    safeguard the kernel's iterates leave the reference's)."""
    _, prob, state = problem
    order = np.arange(prob.a.size)

    def sweep(impulses, velocities, blocks):
        nlgs.sweep(order, prob, impulses, velocities, blocks)

    resets = []
    expected = reference_anderson(prob, _copy(state), sweep, 40, memory=4, period=period, resets=resets)
    assert len(resets) >= 1  # the case this test is for
    got = _copy(state)
    acceleration.solve_problem_anderson(prob, *got, tolerance=0.0, max_tolerance=0.0, max_iterations=40, memory=4,
                                        period=period)
    scale = np.abs(expected[0]).max()
    np.testing.assert_allclose(got[0], expected[0], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(got[1], expected[1], rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("period", [1, 2])
def test_domain_kernel_equals_the_numpy_reference_over_the_domain_sweep(problem, period):
    sim, prob, state = problem
    dec = parallel_nlgs.decompose(prob, sim.position[:, 0], 3)
    renumbered, new_impulses, new_velocities = dec.gather(prob, *_copy(state))

    def sweep(impulses, velocities, blocks):
        parallel_nlgs.sweep_domains(dec.ptr, dec.points, dec.interface, renumbered, impulses, velocities, blocks)

    expected = reference_anderson(renumbered, [s.copy() for s in (*new_impulses, *new_velocities)], sweep,
                                  ITERATIONS, memory=4, period=period)
    got = _copy(state)
    acceleration.solve_problem_anderson(prob, *got, tolerance=0.0, max_tolerance=0.0, max_iterations=ITERATIONS,
                                        memory=4, domains=3, x=sim.position[:, 0], period=period)
    scale = np.abs(expected[0]).max()
    np.testing.assert_allclose(got[0][dec.point_order], expected[0], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(got[1][dec.point_order], expected[1], rtol=0, atol=1e-9 * scale)


def test_domain_form_converges_to_an_admissible_solution_whatever_the_threads(problem):
    sim, prob, state = problem
    options = dict(tolerance=1e-5, max_tolerance=1e-3, max_iterations=20000, memory=5, domains=2,
                   x=sim.position[:, 0])
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = _copy(state)
        r1 = acceleration.solve_problem_anderson(prob, *one, **options)
        numba.set_num_threads(max(2, threads) if numba.config.NUMBA_NUM_THREADS >= 2 else 1)
        two = _copy(state)
        r2 = acceleration.solve_problem_anderson(prob, *two, **options)
    finally:
        numba.set_num_threads(threads)
    assert r1 == r2 and r1.iterations < 20000
    for x, y in zip(one, two):
        np.testing.assert_array_equal(x, y)
    assert residuals.local_law_residual(prob, *one) < 2e-5
    # fewer sweeps than the plain domain sweep to the same tolerance
    plain = _copy(state)
    r0 = parallel_nlgs.solve_problem_domains(prob, sim.position[:, 0], *plain, domains=2, tolerance=1e-5,
                                             max_tolerance=1e-3, max_iterations=20000)
    assert r1.iterations < 0.5 * r0.iterations, (r1, r0)
    # the same load on the walls as the plain solution (same statics, another network): a dense
    # packing's contact forces are mostly self-stress, which the contact laws leave loosely fixed,
    # so solutions of this one problem by other methods and tolerances spread by 0.6% in the walls'
    # load (docs/reproducibility.md, "Tolerances from measured scatter")
    on_walls = np.maximum(prob.a, prob.b) >= sim.position.shape[0]
    assert one[0][on_walls].sum() == pytest.approx(plain[0][on_walls].sum(), rel=1.5e-2)


@pytest.mark.parametrize("domains", [1, 3])
def test_scratch_memory_left_dirty_changes_nothing(problem, domains):
    """The solver's working memory is reused from solve to solve (solver.scratch): a solve on
    buffers filled with NaN, on the leftovers of another sample's problem and on fresh ones
    gives the same impulses and velocities bit for bit, so no entry is read before it is
    written."""
    import threading

    from solver import scratch

    sim, prob, state = problem
    other_sim, other, impulse, v_free, omega_free = compacted_problem(6)
    other_state = [impulse[:, 0], impulse[:, 1], v_free[:, 0], v_free[:, 1], omega_free]
    options = dict(tolerance=1e-4, max_tolerance=1e-2, max_iterations=3000, memory=4, period=2, domains=domains,
                   x=sim.position[:, 0])
    runs = []
    for dirty in ("fresh", "nan", "leftovers"):
        def run():
            if dirty == "nan":
                for name in ("anderson", "renumbered"):
                    scratch.buffer(name, 10**6)[:] = np.nan
            elif dirty == "leftovers":  # a few sweeps of another sample's problem first
                acceleration.solve_problem_anderson(other, *_copy(other_state), **dict(
                    options, max_iterations=5, x=other_sim.position[:, 0]))
            got = _copy(state)
            result = acceleration.solve_problem_anderson(prob, *got, **options)
            runs.append((result, got))

        thread = threading.Thread(target=run)  # a thread of its own: its own, fresh buffers
        thread.start()
        thread.join()
    (first, expected), *others = runs
    assert 5 < first.iterations < 3000
    for result, got in others:
        assert result == first
        for x, y in zip(got, expected):
            np.testing.assert_array_equal(x, y)


def test_scratch_buffers_are_kept_grown_and_the_threads_own():
    import threading

    from solver import scratch

    small = scratch.buffer("test-buffer", 100)
    assert small.size >= 100 and scratch.buffer("test-buffer", 50) is small  # kept
    assert scratch.buffer("another-buffer", 100) is not small  # one per name
    large = scratch.buffer("test-buffer", 10_000)
    assert large.size >= 10_000 and large is not small and scratch.buffer("test-buffer", 100) is large
    theirs = []
    thread = threading.Thread(target=lambda: theirs.append(scratch.buffer("test-buffer", 100)))
    thread.start()
    thread.join()
    assert theirs[0] is not large  # another thread's


def test_a_short_work_array_is_refused(problem):
    _, prob, state = problem
    m, n = prob.a.size, prob.minv_xx.size
    work = np.empty(acceleration.scratch_size(m, n, 3) - 1)
    with pytest.raises(ValueError, match="work array"):
        pn, pt, vx, vy, w = _copy(state)
        acceleration.solve_anderson(np.array([0, m]), prob, Impulses(pn, pt), Velocities(vx, vy, w),
                                    Limits(1e-4, 1e-2, 5, 0), 3, 2, work)


def test_the_scratch_records_cut_the_work_array_without_overlap():
    """Every array of the Anderson scratch and the Delassus blocks is a view of its own stretch of
    the work array, and together they fill exactly scratch_size floats of it: each view written
    with its own number is found in as many entries as it holds, and nothing past the end is
    touched; the small normal equations are memory of their own."""
    points, bodies, memory = 7, 5, 3
    size = acceleration.scratch_size(points, bodies, memory)
    assert size == (4 * memory + 11) * points + (3 * memory + 3) * bodies
    work = np.full(size + 4, -1.0)
    scratch, blocks = acceleration.scratch_records(work, points, bodies, memory)
    views = [*blocks, *scratch[:18]]
    for number, view in enumerate(views):
        view[...] = number
    assert np.bincount(work[:size].astype(np.int64)).tolist() == [v.size for v in views]
    assert np.all(work[size:] == -1.0)
    assert scratch.dfn.shape == (memory, points) and scratch.dw.shape == (memory, bodies)
    assert not any(np.shares_memory(x, work) for x in (scratch.gram, scratch.row, scratch.rhs))


@pytest.mark.parametrize("n", [0, 1, 3, 4, 5, 17, 1001])
def test_block_sums_add_in_the_order_the_code_writes(n):
    """The history's sums run in LANES interleaved partial sums added in a fixed order (no
    reassociation, so the same bits on every processor): equal to that order computed in
    Python, and to the exact sum within rounding."""
    import math

    rng = np.random.default_rng(n)
    a, b, c, d = rng.normal(size=(4, n)) * 10.0 ** rng.uniform(-6, 6, (4, n))
    lanes = [0.0] * acceleration.LANES
    whole = n - n % acceleration.LANES
    terms = [float(a[k] * b[k] + c[k] * d[k]) for k in range(n)]
    for k, term in enumerate(terms):
        lanes[k % acceleration.LANES if k < whole else 0] += term
    written = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
    assert acceleration._dot2(a, b, c, d) == written
    assert abs(written - math.fsum(terms)) <= 4 * n * np.finfo(float).eps * sum(map(abs, terms))
    fn, ft, xn, xt = np.empty(n), np.empty(n), c.copy(), d.copy()
    size = acceleration._residual(a, b, xn, xt, fn, ft)
    assert np.array_equal(fn, a - c) and np.array_equal(ft, b - d) and np.array_equal(xn, a)
    assert size == acceleration._dot2(fn, fn, ft, ft)
    e, f = rng.normal(size=(2, n)) * 10.0 ** rng.uniform(-6, 6, (2, n))
    assert acceleration._dot2_pair(a, b, c, d, e, f) == (acceleration._dot2(a, c, b, d), acceleration._dot2(e, c, f, d))
