"""The paper's protocol: isotropic compaction under sigma_0 on the right and top walls, then
biaxial compression at constant lateral stress, written as a file of the contract."""

import numpy as np
import pytest

import grainview
from grainview.errors import ParameterError
from grainview.schema import particle_area
from solver import biaxial_test, compaction_sample, is_equilibrium, isotropic_compaction

SIGMA0 = 1e4


def _compacted(n, shape, seed=1):
    sim = compaction_sample(n, shape, seed=seed)
    isotropic_compaction(sim, max_steps=20000, progress=False)
    return sim


def _check_compacted(sim):
    assert sim.settled
    np.testing.assert_allclose(sim.compaction_stress, SIGMA0, rtol=0.01)  # right and top walls
    d_mean = 2 * sim.radius.mean()
    assert sim.last.max_interpenetration < 1e-3 * d_mean
    lo, hi = sim.walls.box_bounds()
    return particle_area(sim.radius, sim.n_vertices).sum() / np.prod(hi - lo)


def test_is_equilibrium_on_hand_made_windows():
    stresses = np.array([[1.0e4, 0.99e4], [1.005e4, 1.0e4]])
    assert is_equilibrium(stresses, np.zeros((2, 2)), SIGMA0)
    assert not is_equilibrium(stresses * 1.02, np.zeros((2, 2)), SIGMA0)  # 2% off
    assert not is_equilibrium(stresses, np.full((2, 2), 2e-3), SIGMA0)  # walls still moving


@pytest.mark.parametrize("shape", ["disk", "pentagon"])
def test_small_isotropic_compaction_reaches_sigma0(shape):
    phi = _check_compacted(_compacted(40, shape))
    assert 0.65 < phi < 0.9


def test_short_biaxial_test_writes_a_valid_file(tmp_path):
    sim = _compacted(40, "pentagon")
    top0 = sim.walls.point[2, 1]
    path = tmp_path / "biaxial.nc"
    steps = biaxial_test(sim, path, strain=0.002, every=5, progress=False)
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    h = sim.parameters.time_step
    assert ds.sizes["time"] == 1 + int(np.ceil(steps / 5))
    # the top wall moves down at 1 cm/s exactly
    np.testing.assert_allclose(ds["box_max"].values[:, 1], top0 - 0.01 * (ds["step"] - ds["step"][0]) * h,
                               rtol=1e-12)
    kinds = ds["kind"].values[ds["kind"].values > 0]
    assert {1, 2} <= set(np.unique(kinds))
    assert ds.attrs["scene"] == "biaxial" and ds.attrs["solver_time_step"] == pytest.approx(5e-4)
    ds.close()


def test_scene_parameters_are_validated(tmp_path):
    with pytest.raises(ParameterError, match="sigma0"):
        compaction_sample(10, "disk", sigma0=-1.0)
    with pytest.raises(ParameterError, match="shape"):
        compaction_sample(10, "hexagram")
    sim = compaction_sample(10, "disk")
    with pytest.raises(ParameterError, match="strain"):
        biaxial_test(sim, tmp_path / "x.nc", strain=2.0)


@pytest.mark.slow
@pytest.mark.parametrize("shape, paper_phi", [("disk", 0.82), ("pentagon", 0.80)])
def test_isotropic_compaction_of_400_particles(shape, paper_phi):
    phi = _check_compacted(_compacted(400, shape))
    print(f"{shape}: solid fraction {phi:.4f} (paper {paper_phi})")
    assert abs(phi - paper_phi) < 0.05


@pytest.mark.slow
def test_biaxial_test_of_400_pentagons(tmp_path):
    sim = _compacted(400, "pentagon")
    path = tmp_path / "biaxial400.nc"
    biaxial_test(sim, path, strain=0.005, every=20, progress=False)
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    kinds = ds["kind"].values[ds["kind"].values > 0]
    assert {1, 2} <= set(np.unique(kinds))
    assert float(ds["max_interpenetration"].max()) < 1e-3 * 2 * float(ds["radius"].mean())
    ds.close()
