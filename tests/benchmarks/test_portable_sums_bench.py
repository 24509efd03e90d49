"""benchmarks/portable_sums.py compares what it says it compares: the solver's fixed-order sums
against the parent commit's reassociated ones and a sequential one (the same sums within
rounding), tables with one row per sum and size and per solver, and copies of the solver that
differ from the working tree by their acceleration.py only. The whole-step and solve runs, which
compile two copies of the solver, are the slow test's."""

import filecmp
import math
import os
import statistics
import subprocess

import numpy as np
import pytest

from .conftest import load_benchmark as load

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_the_three_sums_are_the_same_sum_within_rounding():
    from solver import acceleration

    bench = load("portable_sums")
    n = 1001
    found = bench.sums_apart(n, seed=3)
    a, b, c, d = bench.random_terms(n, 3)
    assert found["sums"]["lanes (now)"] == acceleration._dot2(a, b, c, d)
    running = 0.0
    for k in range(n):  # the sequential kernel adds in the points' order, as written
        running += float(a[k] * b[k] + c[k] * d[k])
    assert found["sums"]["sequential"] == running
    for error in found["error"].values():
        assert error <= n * np.finfo(float).eps
    assert found["apart"] == max(abs(x - y) for x in found["sums"].values() for y in found["sums"].values()) \
        / math.fsum(np.abs(a * b + c * d))


def test_the_kernel_table_has_a_row_per_sum_and_size_and_the_rounds_ratios():
    bench = load("portable_sums")
    sizes = [7, 64]
    rows = bench.time_kernels(sizes, rounds=2, memory=3, seconds=1e-4, log=lambda *a, **k: None)
    assert [(r["sum"], r["points"], r["kernel"]) for r in rows] == [
        (s, n, k) for n in sizes for s in ("dot2", "gram", "residual") for k in bench.KERNELS]
    assert all(len(r["ns"]) == 2 and min(r["ns"]) > 0 for r in rows)
    text = bench.kernel_table(rows, {n: bench.sums_apart(n) for n in sizes})
    body = [line.split(" | ") for line in text.splitlines()[2:]]
    names = ["`_dot2`", "Gram row and right-hand side", "`_residual`"]
    assert [(cells[0][2:], cells[1]) for cells in body] == [(name, n) for name in names for n in ("7", "64")]
    first = {r["kernel"]: r["ns"] for r in rows if r["sum"] == "dot2" and r["points"] == 7}
    ratios = [x / y for x, y in zip(first["lanes (now)"], first["reassociated (parent)"])]
    assert body[0][5].startswith(f"{statistics.median(ratios):.2f} (")
    assert body[0][2] == f"{statistics.median(first['lanes (now)']):.3f}"
    assert body[0][-1].rstrip(" |") != "" and body[2][-1].rstrip(" |") == ""  # the difference of _dot2's sums only


def test_the_gram_loops_give_the_history_pass_sums():
    """The timed Gram loops compute what the history pass adds: the solver's pair of sums per
    row, the same bits as its two _dot2 calls, and the others within rounding."""
    from solver import acceleration

    bench = load("portable_sums")
    rng = np.random.default_rng(4)
    nfn, nft, fn, ft = rng.normal(size=(4, 1001))
    dfn, dft = rng.normal(size=(2, 3, 1001))
    results = {}
    for kernel in bench.KERNELS:
        row, rhs = np.zeros(3), np.zeros(3)
        bench.kernel_loops()["gram", kernel](nfn, nft, fn, ft, dfn, dft, row, rhs, 1)
        results[kernel] = row, rhs
    row, rhs = results["lanes (now)"]
    for j in range(3):
        assert row[j] == acceleration._dot2(nfn, dfn[j], nft, dft[j])
        assert rhs[j] == acceleration._dot2(fn, dfn[j], ft, dft[j])
    for kernel in bench.KERNELS[1:]:
        np.testing.assert_allclose(np.concatenate(results[kernel]), np.concatenate([row, rhs]), rtol=1e-12)


def _has_commit(commit):
    return subprocess.run(["git", "cat-file", "-e", f"{commit}^{{commit}}"], cwd=ROOT,
                          capture_output=True).returncode == 0


def test_the_copies_differ_from_the_working_tree_by_their_acceleration_py_only(tmp_path):
    bench = load("portable_sums")
    if not _has_commit(bench.BASE):
        pytest.skip(f"no commit {bench.BASE} in this clone")
    candidate = tmp_path / "candidate.py"
    candidate.write_text("# a candidate\n")
    trees = bench.solver_trees(str(tmp_path / "work"), variants=[("mine", str(candidate))])
    assert list(trees) == ["now", "parent", "mine"]
    here = os.path.join(ROOT, "solver")
    for label, folder in trees.items():
        compared = filecmp.dircmp(here, os.path.join(folder, "solver"), ignore=["__pycache__"])
        assert not compared.left_only and not compared.right_only and not compared.funny_files
        assert compared.diff_files == ([] if label == "now" else ["acceleration.py"])
    parent = open(os.path.join(trees["parent"], "solver", "acceleration.py")).read()
    assert 'fastmath={"reassoc"}' in parent and "LANES" not in parent
    assert open(os.path.join(trees["mine"], "solver", "acceleration.py")).read() == "# a candidate\n"
    stamp = subprocess.run(["git", "show", "-s", "--format=%ct", bench.BASE], cwd=ROOT, capture_output=True,
                           text=True).stdout.strip()
    assert os.path.getmtime(os.path.join(trees["parent"], "solver", "acceleration.py")) == int(stamp)


def test_the_steps_table_gives_each_solver_and_its_rounds_ratios_to_the_parent():
    bench = load("portable_sums")
    rows = [dict(label=label, round=r, seconds=2 * s, cpu=s, solve=s / 2, sweeps=w, points=1000, steps=10,
                 particles=60)
            for r, (now, parent) in enumerate([(1.2, 1.0), (1.1, 1.1), (0.9, 1.0)])
            for label, s, w in (("now", now, 400), ("parent", parent, 500))]
    text = bench.steps_table(rows)
    body = {line.split(" | ")[0][2:]: line.split(" | ") for line in text.splitlines()[2:]}
    assert list(body) == ["now", "parent"]
    assert body["now"][1] == "3" and body["now"][2] == "220.000" and body["now"][3] == "110.000"
    assert body["parent"][3] == "100.000" and body["parent"][4] == "50.000"
    assert body["now"][6] == "40.0" and body["parent"][6] == "50.0"  # sweeps per step
    assert body["now"][9] == "1.000 (0.900-1.200)"  # CPU ms per step: the rounds' ratios 1.2, 1.0, 0.9
    per_sweep = sorted((n / 400) / (p / 500) for n, p in [(1.2, 1.0), (1.1, 1.1), (0.9, 1.0)])
    assert body["now"][11].rstrip(" |") == f"{per_sweep[1]:.3f} ({per_sweep[0]:.3f}-{per_sweep[2]:.3f})"
    assert body["parent"][9] == ""


def test_the_solves_table_gives_each_measure_and_its_rounds_ratios_to_the_parent():
    bench = load("portable_sums")
    rows = [dict(label=label, round=r, solve=s, history=s / 2, sweep=10.0, points=500)
            for r, (now, parent) in enumerate([(21.0, 20.0), (19.0, 20.0)])
            for label, s in (("parent", parent), ("now", now))]
    text = bench.solves_table(rows)
    body = {line.split(" | ")[0][2:]: line.split(" | ") for line in text.splitlines()[2:]}
    assert list(body) == ["parent", "now"] and len(text.splitlines()[0].split(" | ")) == 8
    assert body["now"][2:5] == ["20.00", "10.00", "10.00"]
    assert body["now"][5] == "1.000 (0.950-1.050)" and body["now"][7].rstrip(" |") == "1.000 (1.000-1.000)"
    assert body["parent"][5] == ""


@pytest.mark.slow
def test_both_solvers_step_the_sample_in_processes_of_their_own(pentagon_sample, tmp_path):
    """The whole-step part at a tiny size: each copy compiles into its own cache (minutes)."""
    bench = load("portable_sums")
    if not _has_commit(bench.BASE):
        pytest.skip(f"no commit {bench.BASE} in this clone")
    trees = bench.solver_trees(str(tmp_path / "work"))
    rows = bench.time_steps(trees, pentagon_sample, skip=2, steps=3, rounds=2, log=lambda *a, **k: None)
    assert [(r["label"], r["round"]) for r in rows] == [("now", 0), ("parent", 0), ("parent", 1), ("now", 1)]
    assert all(r["steps"] == 3 and r["particles"] == 60 and r["sweeps"] >= 3 and r["cpu"] > r["solve"] > 0
               and r["seconds"] > 0 for r in rows)
    assert os.listdir(os.path.join(trees["now"], "numba")) and os.listdir(os.path.join(trees["parent"], "numba"))
    assert len(bench.steps_table(rows).splitlines()) == 4
    problems = str(tmp_path / "problems.pkl")
    assert bench.capture_problems(pentagon_sample, 2, 2, problems) > 0
    solves = bench.time_solves(trees, problems, bench.MIN_SWEEPS, 1, 1, log=lambda *a, **k: None)
    assert [r["label"] for r in solves] == ["now", "parent"]
    assert all(r["solve"] > 0 and r["history"] > 0 and r["sweep"] > 0 for r in solves)
