"""The paper's protocol (solver/scenes.py): isotropic compaction under sigma_0 on the right and
top walls, biaxial compression at constant lateral stress written in the data contract;
parameter errors; determinism. The 400-particle runs are marked slow."""

import hashlib
import re
import warnings

import numpy as np
import pytest

import grainview
from grainview.contract.errors import ParameterError
from grainview.contract.shapes import particle_area
from solver.preparation import prepare_sample, preparation
from solver import (Parameters, Simulation, Walls, biaxial_test, compaction_sample, is_equilibrium,
                    isotropic_compaction)

SIGMA0 = 1e4


def _compact(n, shape, seed=0, max_steps=20000):
    sim = compaction_sample(n, shape, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=max_steps, progress=False)
    return sim


def _solid_fraction(sim):
    lo, hi = sim.walls.box_bounds()
    return float(particle_area(sim.radius, sim.n_vertices).sum() / np.prod(hi - lo))


def test_is_equilibrium_on_hand_made_windows():
    stresses = np.array([[1.0e4, 0.99e4], [1.005e4, 1.0e4]])
    assert is_equilibrium(stresses, np.zeros((2, 2)), SIGMA0)
    assert not is_equilibrium(stresses * 1.02, np.zeros((2, 2)), SIGMA0)  # 2% off
    assert not is_equilibrium(stresses, np.full((2, 2), 2e-3), SIGMA0)  # walls still moving


@pytest.mark.parametrize("shape", ["disk", "pentagon"])
def test_small_isotropic_compaction_reaches_sigma0(shape):
    sim = _compact(40, shape, seed=1)
    assert sim.settled
    np.testing.assert_allclose(sim.compaction_stress, SIGMA0, rtol=0.01)  # right and top walls
    assert sim.last.max_interpenetration < 1e-3 * 2 * sim.radius.mean()
    assert 0.65 < _solid_fraction(sim) < 0.9


def test_the_top_wall_moves_down_at_one_centimetre_per_second(tmp_path):
    sim = _compact(40, "pentagon", seed=1)
    top0 = sim.walls.point[2, 1]
    path = tmp_path / "biaxial.nc"
    steps = biaxial_test(sim, path, strain=0.002, every=5, progress=False)
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    h = sim.parameters.time_step
    assert ds.sizes["time"] == 1 + int(np.ceil(steps / 5))
    np.testing.assert_allclose(ds["box_max"].values[:, 1], top0 - 0.01 * (ds["step"] - ds["step"][0]) * h,
                               rtol=1e-12)
    ds.close()


def test_small_biaxial_test_writes_a_valid_file_with_both_contact_kinds(tmp_path):
    sim = _compact(60, "pentagon", seed=3, max_steps=6000)
    path = tmp_path / "biaxial.nc"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steps = biaxial_test(sim, path, strain=0.004, every=10, progress=False)
    ds = grainview.open_dataset(path, validate=True)
    assert ds.sizes["time"] == 1 + int(np.ceil(steps / 10))
    kinds = set(np.unique(ds.kind.values)) - {0}
    assert kinds == {1, 2}
    assert ds.attrs["scene"] == "biaxial" and ds.attrs["solver_friction"] == 0.4
    # the file's stress agrees with the wall stresses: sigma_yy at the end ~ top wall stress
    assert float(ds.max_interpenetration.max()) < 1e-3 * 2 * sim.radius.mean()
    eps = ds.grain.strains()["eps_1"].values
    assert eps[-1] == pytest.approx(0.004, rel=0.05)
    # branch vectors: particle pairs join the centres
    k = -1
    m = int(ds.contact_count[k])
    i, j = ds.i.values[k, :m], ds.j.values[k, :m]
    pairs = j < ds.sizes["particle"]
    np.testing.assert_allclose(ds.branch.values[k, :m][pairs],
                               ds.position.values[k, j[pairs]] - ds.position.values[k, i[pairs]], atol=1e-15)


def test_same_parameters_give_the_same_file(tmp_path):
    digests = []
    for name in ("a.nc", "b.nc"):
        sim = compaction_sample(30, "pentagon", seed=5)
        for _ in range(200):
            sim.step()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            biaxial_test(sim, tmp_path / name, strain=0.001, every=5, progress=False)
        ds = grainview.open_dataset(tmp_path / name, chunks=None)
        digests.append(hashlib.sha256(b"".join(ds[v].values.tobytes() for v in ("position", "fn", "ft", "i", "j"))).hexdigest())
    assert digests[0] == digests[1]


@pytest.mark.parametrize("kwargs, message", [
    (dict(time_step=-1.0), "time_step=-1.0"),
    (dict(friction=-0.1), "friction=-0.1"),
    (dict(theta=0.2), "theta=0.2"),
    (dict(tolerance=0.0), "tolerance=0.0"),
    (dict(alert=-1.0), "alert=-1.0"),
    (dict(gravity=(0.0, np.nan)), "gravity"),
])
def test_invalid_parameters_are_named(kwargs, message):
    with pytest.raises(ParameterError, match=message.replace("(", r"\(").replace(")", r"\)")):
        Simulation([[0.0, 0.1]], [0.0], [0.01], [0], Walls.floor(), Parameters(**kwargs))


def test_invalid_samples_and_scenes():
    with pytest.raises(ParameterError, match="empty"):
        Simulation(np.empty((0, 2)), [], [], [], Walls.floor())
    with pytest.raises(ParameterError, match="radius must be > 0"):
        Simulation([[0.0, 0.1]], [0.0], [-0.01], [0], Walls.floor())
    with pytest.raises(ParameterError, match="n_vertices"):
        Simulation([[0.0, 0.1]], [0.0], [0.01], [2], Walls.floor())
    with pytest.raises(ParameterError, match="shape='hexagram'"):
        compaction_sample(10, "hexagram")
    with pytest.raises(ParameterError, match="sigma0"):
        compaction_sample(10, "disk", sigma0=-5)
    sim = compaction_sample(10, "disk")
    with pytest.raises(ParameterError, match="strain=1.5"):
        biaxial_test(sim, "unused.nc", strain=1.5)
    with pytest.raises(ParameterError, match="every=2.5"):  # not silently 2
        biaxial_test(sim, "unused.nc", every=2.5)
    # at 30 m/s the top wall crosses 0.015 m > the smallest radius 0.0125 m in one 5e-4 s step
    with pytest.raises(ParameterError, match=r"travels 0.015 m per step.*time_step <= 0.000417 s"):
        biaxial_test(sim, "unused.nc", velocity=30.0)
    with pytest.raises(ParameterError, match="a closing wall of the compaction"):
        prepare_sample(preparation("paper", particles=10, shape="disk", max_wall_speed=50.0))
    with pytest.raises(ParameterError, match="no wall named 'ceiling'"):
        sim.walls.drive_velocity("ceiling", (0, -1))


def test_a_test_beyond_the_step_counter_is_refused_before_anything_is_written(tmp_path):
    """The steps are counted from the compacted sample's own height (a compaction that let the
    walls run away gives a box that no prediction foresaw): beyond the 32-bit step counter the
    test is refused in one line and no file is made."""
    sim = compaction_sample(10, "disk")
    lo, hi = sim.walls.box_bounds()
    steps = (hi[1] - lo[1]) * (np.exp(0.1) - 1) / 1e-9 / sim.parameters.time_step
    assert steps > 2**31 - 1
    with pytest.raises(ParameterError, match=re.escape(f"would take {steps:.3g} steps of")) as caught:
        biaxial_test(sim, tmp_path / "never.nc", strain=0.1, velocity=1e-9)
    assert "beyond a file's step counter (2147483647" in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_existing_file_is_not_overwritten(tmp_path):
    path = tmp_path / "keep.nc"
    path.write_bytes(b"user data")
    sim = compaction_sample(10, "disk")
    with pytest.raises(FileExistsError):
        biaxial_test(sim, path, strain=0.001, progress=False)
    assert path.read_bytes() == b"user data"


@pytest.mark.slow
@pytest.mark.parametrize("shape, paper", [("disk", 0.82), ("pentagon", 0.80)])
def test_isotropic_compaction_of_400_particles(shape, paper):
    sim = _compact(400, shape, seed=1, max_steps=20000)
    assert sim.settled
    np.testing.assert_allclose(sim.compaction_stress, 1e4, rtol=0.01)
    assert sim.last.max_interpenetration < 1e-3 * 2 * sim.radius.mean()
    phi = _solid_fraction(sim)
    print(f"{shape}: solid fraction {phi:.3f} (paper {paper})")
    assert abs(phi - paper) < 0.03


@pytest.mark.slow
def test_biaxial_test_of_400_pentagons(tmp_path):
    sim = _compact(400, "pentagon", seed=1)
    path = tmp_path / "b.nc"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        biaxial_test(sim, path, strain=0.01, every=50, progress=False)
    ds = grainview.open_dataset(path, validate=True)
    assert set(np.unique(ds.kind.values)) - {0} == {1, 2}
    assert float(ds["max_interpenetration"].max()) < 1e-3 * 2 * float(ds["radius"].mean())
