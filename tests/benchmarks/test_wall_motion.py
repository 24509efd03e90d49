"""benchmarks/wall_motion.py reads a walled test as the solver wrote it: the right wall's mass
ratio and free-flight time from the file's attributes, the grains' stress on the right wall
from its recorded force equal to the sum of the normal forces of its contacts (an independent
computation from the contact list), and p over the three thirds averaging to about the whole
sample's contact p."""

import warnings

import netCDF4
import numpy as np
import pytest

from solver import biaxial_test, compaction_sample, isotropic_compaction

from .conftest import load_benchmark


@pytest.fixture(scope="module")
def walled(tmp_path_factory):
    path = tmp_path_factory.mktemp("wall_motion") / "walled.nc"
    sim = compaction_sample(60, "pentagon", seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=3000, progress=False)
        biaxial_test(sim, path, strain=0.01, every=20, wall_mass=0.2, progress=False)
    return path, sim


def test_the_wall_numbers_are_the_files(walled):
    import grainview
    from grainview.analysis.coarse_graining import mean_diameter

    path, sim = walled
    motion = load_benchmark("wall_motion")
    r = motion.wall_motion(path, window=0.0)
    assert r["mass ratio"] == pytest.approx(0.2, rel=1e-12) and r["particles"] == 60
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        right = [str(w) for w in nc["wall"][:]].index("right")
        j, fn, kind = nc["j"][:], nc["fn"][:], nc["kind"][:]
        height = (nc["box_max"][:] - nc["box_min"][:])[:, 1]
        sigma0, thickness = nc.getncattr("sigma0_Pa"), nc.getncattr("thickness_m")
        h0 = height[0]
    on_wall = (j == 60 + right) & (kind > 0)
    by_contacts = np.where(on_wall, fn, 0.0).sum(axis=1) / (height * thickness) / sigma0
    np.testing.assert_allclose(r["wall"], by_contacts, rtol=1e-9)
    assert r["snapshots"] == len(by_contacts)
    mass = 0.2 * float(sim.mass.sum())
    with grainview.open_dataset(path, chunks=None) as ds:
        p = ds.grain.stress_invariants()["p"].values
        thirds = motion.thirds_p(ds)
        d = mean_diameter(ds)
    assert r["t_w"] == pytest.approx(np.sqrt(mass * d / (sigma0 * thickness * h0)), rel=1e-12)
    # the three thirds share the sample's area and what the kernels spill: their mean p is the
    # whole sample's Love-Weber p (stress_invariants), up to the grid's quadrature
    np.testing.assert_allclose(thirds.mean(axis=1), p, rtol=1e-3)
    assert np.ptp(thirds, axis=1).max() > 1e-3 * p.max()  # and the thirds differ


def test_the_table_has_a_row_per_file(walled, tmp_path):
    path, _ = walled
    motion = load_benchmark("wall_motion")
    out = tmp_path / "wall-motion.md"
    assert motion.main([str(path), str(path), "--labels", "a,b", "--window", "0", "--out", str(out)]) == 0
    lines = [line for line in out.read_text().splitlines() if line.startswith("| ")]
    assert len(lines) == 3 and lines[1].startswith("| a | 60 | 1 | 0.2 |") and lines[2].startswith("| b |")


def test_a_file_or_window_without_a_walled_snapshot_is_refused_in_one_line(walled, tmp_path, capsys):
    path, sim = walled
    motion = load_benchmark("wall_motion")
    with pytest.raises(SystemExit):
        motion.main([str(path), "--window", "5", "--out", str(tmp_path / "w.md")])
    assert "no snapshot with eps_q >= 5 (its largest is" in capsys.readouterr().err.splitlines()[-1]
    from solver.output import Recorder

    compacted = tmp_path / "compacted.nc"  # a sample as written alone: no biaxial test
    with Recorder(compacted, sim, attrs={"scene": "isotropic"}) as rec:
        rec.write()
    with pytest.raises(ValueError, match="scene isotropic, walls .*; expected a walled biaxial test"):
        motion.wall_motion(compacted)
