"""The biaxial test's right wall of a chosen mass (``BiaxialTest.wall_mass``, in units of the
sample's mass): recorded in the file, obeyed by the wall's equation of motion step by step
(its momentum changes by the impulse of sigma0 and of the grains, divided by that mass, not
by the compaction's), kept by a resumed run bit for bit."""

import warnings

import netCDF4
import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver import biaxial_test, compaction_sample, isotropic_compaction
from solver import stepper
from solver.restart import resume

RATIO = 0.05


def _compacted():
    sim = compaction_sample(40, "pentagon", seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=300, progress=False)
    return sim


def _test(sim, path, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return biaxial_test(sim, path, strain=0.0005, every=1, progress=False, compress=False, **kwargs)


def _read(path):
    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        names = [str(w) for w in nc["wall"][:]]
        values = {name: np.asarray(nc[name][:]) for name in ("wall_velocity", "wall_force", "box_min", "box_max",
                                                             "step", "position", "normal_impulse")}
        attrs = {name: nc.getncattr(name) for name in nc.ncattrs()}
    return names.index("right"), values, attrs


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("wall_mass")
    sim = _compacted()
    sample_mass = float(sim.mass.sum())
    assert sim.walls.mass[sim.walls.index("right")] == pytest.approx(sample_mass)  # the compaction's wall
    _test(sim, folder / "light.nc", wall_mass=RATIO)
    _test(_compacted(), folder / "default.nc")
    return folder, sample_mass


def test_the_wall_mass_is_recorded(runs):
    folder, sample_mass = runs
    right, _, attrs = _read(folder / "light.nc")
    assert attrs["right_wall_mass_ratio"] == RATIO
    assert attrs["wall_mass_kg"][right] == pytest.approx(RATIO * sample_mass, rel=1e-15)
    right, _, attrs = _read(folder / "default.nc")
    assert attrs["right_wall_mass_ratio"] == "none" and attrs["wall_mass_kg"][right] == pytest.approx(sample_mass)


def test_the_right_wall_moves_by_newtons_law_with_that_mass(runs):
    """M (v_k - v_k-1) . n = h (sigma0 L_k-1 + F_k . n) along the wall's normal n (pointing into
    the sample), L the wall's length at the step's start, F the grains' force on it: the
    balance holds with the mass asked for, and with the compaction's mass it does not."""
    folder, sample_mass = runs
    for name, mass in (("light.nc", RATIO * sample_mass), ("default.nc", sample_mass)):
        right, v, attrs = _read(folder / name)
        h, sigma0 = float(attrs["solver_time_step"]), float(attrs["sigma0_Pa"])
        assert np.all(np.diff(v["step"]) == 1)
        normal = np.array([-1.0, 0.0])  # the right wall pushes to -x
        height = (v["box_max"] - v["box_min"])[:-1, 1]
        change = mass * (v["wall_velocity"][1:, right] - v["wall_velocity"][:-1, right]) @ normal
        impulse = h * (sigma0 * height * float(attrs["thickness_m"]) + v["wall_force"][1:, right] @ normal)
        assert np.abs(impulse).max() > 0
        np.testing.assert_allclose(change, impulse, rtol=1e-9, atol=1e-12 * np.abs(impulse).max())
        if name == "light.nc":  # the other mass would break it: the test can tell the two apart
            wrong = sample_mass * (v["wall_velocity"][1:, right] - v["wall_velocity"][:-1, right]) @ normal
            assert not np.allclose(wrong, impulse, rtol=1e-3)


def test_a_stopped_test_resumes_with_its_wall_mass_bit_for_bit(runs, tmp_path, monkeypatch):
    folder, _ = runs
    path = tmp_path / "stopped.nc"
    original = stepper.Simulation.step
    sim = _compacted()
    first = sim.step_index

    def step(self):
        info = original(self)
        if self.step_index == first + 7:
            raise KeyboardInterrupt  # what a kill leaves: the complete snapshots so far
        return info

    monkeypatch.setattr(stepper.Simulation, "step", step)
    with pytest.raises(KeyboardInterrupt):
        _test(sim, path, wall_mass=RATIO)
    monkeypatch.setattr(stepper.Simulation, "step", original)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert resume(path, compress=False) > 0
    _, resumed, _ = _read(path)
    _, light, _ = _read(folder / "light.nc")
    for name in resumed:
        np.testing.assert_array_equal(resumed[name], light[name], err_msg=name)


def test_a_wall_mass_that_is_no_mass_is_refused_before_anything_is_written(tmp_path):
    for bad in (0.0, -1.0, float("nan"), float("inf"), 1e-300):
        with pytest.raises(ParameterError, match="wall_mass=.*expected a finite multiple >= 1e-06 of the sample's mass"):
            _test(_compacted(), tmp_path / "x.nc", wall_mass=bad)
    assert list(tmp_path.iterdir()) == []
