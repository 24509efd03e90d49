"""benchmarks/same_sample.py: the tolerance study's table pairs the runs by seed and computes
their differences as by hand."""

import json

import numpy as np
import pytest

from .conftest import load_benchmark


@pytest.fixture()
def same_sample(tmp_path, monkeypatch):
    module = load_benchmark("same_sample")
    monkeypatch.setattr(module, "OUT", str(tmp_path))
    return module


def _write(folder, seed, q_default, q_tight, tighter=4):
    runs = {}
    for run, q in (("B-and", q_default), ("B-tight", q_tight)):
        runs[run] = {key: 1.0 for key in ("steps", "seconds", "sweeps median", "sweeps p90",
                                          "local-law residual median", "local-law residual p90",
                                          "unbalanced force median", "unbalanced force p90")}
        runs[run].update({key: 0.5 for key in load_benchmark("same_sample").QUANTITIES})
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
    d = np.array([-0.05, -0.02, -0.06])
    assert cells[1] == f"{np.mean([0.50, 0.60, 0.55]):.3f} ({np.std([0.50, 0.60, 0.55], ddof=1):.3f})"
    assert cells[3] == f"{d.mean():+.3f}"
    assert cells[4] == f"{d.std(ddof=1) / np.sqrt(3):.3f}"
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


def test_static_table_pairs_each_step_with_its_default(same_sample, tmp_path):
    rows = [{"step": k, **{str(f): {"q/p": 0.5 + 0.01 * k + (0.002 * f if f > 1 else 0.0), "sweeps": 10 * f,
                                    "local-law residual": 1e-4 / f} for f in same_sample.STATIC_FACTORS}}
            for k in range(4)]
    with open(tmp_path / "static_pentagon_0.json", "w") as fh:
        json.dump({"seed": 0, "shape": "pentagon", "rows": rows}, fh)
    table = same_sample.static_table("pentagon")
    line = next(x for x in table.splitlines() if x.startswith("| 10x tighter"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[1] == f"{0.515 + 0.02:.4f}" and cells[2] == "+0.0200" and cells[3] == "0.0000"
    assert cells[4] == "100" and cells[5] == "1.00e-05"
