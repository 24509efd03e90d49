"""benchmarks/archive/same_sample.py: the tolerance study's table pairs the runs by seed and computes
their differences as by hand."""

import json

import numpy as np
import pytest

from .conftest import load_benchmark


@pytest.fixture()
def same_sample(tmp_path, monkeypatch):
    module = load_benchmark("archive.same_sample")
    monkeypatch.setattr(module, "OUT", str(tmp_path))
    return module


def _write(folder, seed, q_default, q_tight, tighter=4):
    runs = {}
    for run, q in (("B-and", q_default), ("B-tight", q_tight)):
        runs[run] = {key: 1.0 for key in ("steps", "seconds", "sweeps median", "sweeps p90",
                                          "local-law residual median", "local-law residual p90",
                                          "unbalanced force median", "unbalanced force p90")}
        runs[run].update({key: 0.5 for key in load_benchmark("archive.same_sample").QUANTITIES})
        runs[run]["q/p (residual)"] = q
    with open(folder / f"tolerance_pentagon_{seed}_{tighter}.json", "w") as fh:
        json.dump({"seed": seed, "shape": "pentagon", "tighter": tighter, **runs}, fh)


def test_tolerance_table_pairs_by_seed(same_sample, tmp_path):
    _write(tmp_path, 0, 0.50, 0.45)
    _write(tmp_path, 1, 0.60, 0.58)
    _write(tmp_path, 2, 0.55, 0.49)
    table = same_sample.tolerance_table("pentagon")
    row = next(line for line in table.splitlines() if line.startswith("| q/p (residual)"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    # by hand: B-and 0.50, 0.60, 0.55 -> mean 0.55, sd 0.05; differences -0.05, -0.02, -0.06 ->
    # mean -0.0433, sd sqrt(8.667e-4 / 2) = 0.0208, standard error 0.0208 / sqrt(3) = 0.0120
    assert cells[1] == "0.550 (0.050)"
    assert cells[3] == "-0.043"
    assert cells[4] == "0.012"
    assert "seeds 0, 1, 2" in table and "4x tighter" in table


def test_tolerance_table_has_a_table_per_factor(same_sample, tmp_path):
    _write(tmp_path, 0, 0.5, 0.4, tighter=4)
    _write(tmp_path, 1, 0.5, 0.4, tighter=4)
    _write(tmp_path, 0, 0.5, 0.3, tighter=10)
    table = same_sample.tolerance_table("pentagon")
    assert "seeds 0, 1: the default tolerance (B-and) and 4x tighter" in table
    assert "seeds 0: the default tolerance (B-and) and 10x tighter" in table
    rows = [line for line in table.splitlines() if line.startswith("| q/p (residual)")]
    assert [r.split("|")[4].strip() for r in rows] == ["-0.100", "-0.200"]
    assert same_sample.tolerance_table("disk").startswith("(no disk")


def test_q_over_p_of_two_contacts_by_hand(same_sample):
    """A point along x (normal (1, 0), p_n = 1, branch (1, 0)) and one along y (p_n = 0.5,
    branch (0, 1)) with tangential impulses that cancel in the symmetric part: sigma = diag(1,
    0.5) times a constant, q/p = 0.5 / 1.5. The branch of a wall point is r_a (r_b = 0)."""
    from solver import nlgs

    z = np.zeros(2)
    problem = nlgs.ContactProblem(np.array([0, 0]), np.array([1, 2]), np.array([1.0, 0.0]), np.array([0.0, 1.0]),
                                  np.array([0.5, 0.0]), np.array([0.0, 1.0]), np.array([-0.5, 0.0]), z, z, z, z, z, z, z)
    assert same_sample._q_over_p(problem, np.array([1.0, 0.5]), np.zeros(2)) == pytest.approx(1 / 3, rel=1e-12)
    # a tangential impulse on the x point adds f_y l_x: sigma_yx = 0.2, symmetric part 0.1 off the diagonal
    q = np.hypot(0.25, 0.1)
    assert same_sample._q_over_p(problem, np.array([1.0, 0.5]), np.array([0.2, 0.0])) == pytest.approx(q / 0.75, rel=1e-12)


def test_static_table_averages_per_seed_then_over_seeds(same_sample, tmp_path):
    """Seed 0: steps whose 10x tighter q/p sits 0.01 and 0.03 above the default's (mean 0.02);
    seed 1: 0.00 and 0.02 (mean 0.01). Over the seeds: mean 0.015, sd 0.00707, standard error
    0.00707 / sqrt(2) = 0.0050. The other factors sit 0.001 f above."""
    for seed, shifts in ((0, (0.01, 0.03)), (1, (0.00, 0.02))):
        rows = []
        for k, shift in enumerate(shifts):
            base = 0.5 + 0.1 * k + 0.05 * seed
            rows.append({"step": 30_000 + 20 * k, **{
                str(f): {"q/p": base + (shift if f == 10 else 0.001 * f if f > 1 else 0.0), "sweeps": 10 * f + k,
                         "local-law residual": 1e-4 / f} for f in same_sample.STATIC_FACTORS}})
        with open(tmp_path / f"static_pentagon_{seed}.json", "w") as fh:
            json.dump({"seed": seed, "shape": "pentagon", "rows": rows}, fh)
    table = same_sample.static_table("pentagon")
    assert "seeds 0, 1: 4 residual-state steps" in table
    line = next(x for x in table.splitlines() if x.startswith("| 10x tighter"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    # q/p mean: defaults 0.5, 0.6, 0.55, 0.65 (mean 0.575) plus the shifts' mean 0.015
    assert cells[1] == "0.5900"
    assert cells[2] == "+0.0200, +0.0100" and cells[3] == "+0.0150" and cells[4] == "0.0050"
    assert cells[5] == "100" and cells[6] == "1.00e-05"
    default = next(x for x in table.splitlines() if x.startswith("| default"))
    assert "+0.0000, +0.0000" in default


def test_the_runs_are_exclusive(same_sample):
    with pytest.raises(SystemExit):
        same_sample.main(["--tighter", "4", "--static"])
