"""benchmarks/sweep_cost.py: the captured problems are laid out whole for one domain and
renumbered, all points kept, for several; the measured costs are positive."""

import numpy as np
import pytest

from .conftest import load_benchmark as load


@pytest.fixture(scope="module")
def problems(pentagon_sample):
    shear = load("shear")
    sim, _ = load("common").load_sample(pentagon_sample)
    return shear.capture(sim, 3, 4)


def test_layouts_keep_every_point(problems):
    sweep_cost = load("sweep_cost")
    c = problems[0]
    problem = c["problem"]
    laid, impulses, velocities, blocks, dec = sweep_cost._layout(c, 1)
    assert dec is None and list(blocks) == [0, problem.a.size]
    np.testing.assert_array_equal(laid.bias, problem.bias)
    np.testing.assert_array_equal(impulses.pn, c["pn"])
    laid, impulses, velocities, blocks, dec = sweep_cost._layout(c, 2)
    assert blocks[-1] == problem.a.size and len(blocks) == 4
    # the same points, renumbered: the same multiset of Signorini shifts and warm-start impulses
    np.testing.assert_array_equal(np.sort(laid.bias), np.sort(problem.bias))
    np.testing.assert_array_equal(np.sort(impulses.pn), np.sort(c["pn"]))
    assert laid.minv_xx.size >= problem.minv_xx.size  # every body, walls copied into each domain that touches them


def test_costs_are_measured_for_every_kind_and_domain_count(problems):
    sweep_cost = load("sweep_cost")
    out = sweep_cost.measure(problems, [1, 2], sweeps=4, repeats=1)
    assert set(out) == {(k, d) for k in sweep_cost.KINDS for d in (1, 2)}
    assert all(np.isfinite(v) for v in out.values())


def test_the_stages_are_the_anderson_solve_taken_apart(problems):
    """Driven kernel by kernel from Python, the solve ends on the impulses of solve_anderson
    run for as many sweeps without a tolerance, bit for bit: the stages timed are the solver's."""
    from solver import acceleration
    from solver.solve_records import Limits

    sweep_cost = load("sweep_cost")
    c = problems[1]
    seconds, (histories, extrapolations), moved, (pn, pt) = sweep_cost.stage_seconds(c, 12)
    assert set(seconds) == set(sweep_cost.STAGES) and min(seconds.values()) >= 0.0
    assert histories == 5 and 1 <= extrapolations <= 5 and 0 <= moved <= extrapolations * c["problem"].a.size
    problem, impulses, velocities, blocks, _ = sweep_cost._layout(c, 1)
    work = np.empty(acceleration.scratch_size(problem.a.size, velocities.vx.size, sweep_cost.MEMORY))
    acceleration.solve_anderson(blocks, problem, impulses, velocities, Limits(0.0, 0.0, 12, 0), sweep_cost.MEMORY,
                                sweep_cost.PERIOD, work)
    np.testing.assert_array_equal(pn, impulses.pn)
    np.testing.assert_array_equal(pt, impulses.pt)


@pytest.mark.parametrize("argv, words", [
    (["--sweeps", "4", "--stages"], "--sweeps 4: expected at least 5"),
    (["--sweeps", "0"], "--sweeps 0: expected at least 1"),
    (["--strips", "1,x"], "--strips '1,x': expected domain counts"),
    (["--strips", "0,2"], "expected domain counts >= 1"),
    (["--count", "0"], "--count 0"),
    (["--threads", "999"], "--threads 999: expected 1 to"),
])
def test_bad_arguments_get_one_line(argv, words, capsys):
    sweep_cost = load("sweep_cost")
    with pytest.raises(SystemExit):
        sweep_cost.main(["--sample", "no-such-file.pkl"] + argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert words in err[-1]
