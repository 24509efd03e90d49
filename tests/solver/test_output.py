"""Writing a run into a file of the data contract: a double contact once with its resultant,
wall forces, branches, parameters and diagnostics, snapshot by snapshot."""

import numpy as np
import pytest

import grainview
from solver import gravity_scene
from solver.output import Recorder, pair_contacts

from .conftest import EXACT, G, PENTAGON_ON_EDGE, R

H = 5e-4


def _resting_pair():
    """A disk (0) at x = 0 and a pentagon (1) on an edge at x = 0.1 m, resting on the floor."""
    inradius = R * np.cos(np.pi / 5)
    sim = gravity_scene([[0.0, R], [0.1, inradius]], [0.0, PENTAGON_ON_EDGE], [R, R], [0, 5], **EXACT)
    for _ in range(5):
        sim.step()
    return sim


def test_double_contact_is_written_once_with_its_resultant():
    sim = _resting_pair()
    c = pair_contacts(sim)
    weight = sim.mass * G
    assert len(c["i"]) == 2  # the disk's contact and the pentagon's double contact
    order = np.argsort(c["i"])
    i, j, kind = c["i"][order], c["j"][order], c["kind"][order]
    fn, ft, point, branch = c["fn"][order], c["ft"][order], c["point"][order], c["branch"][order]
    np.testing.assert_array_equal(i, [0, 1])
    np.testing.assert_array_equal(j, [2, 2])  # the floor is body N + 0 = 2
    np.testing.assert_array_equal(kind, [1, 2])
    np.testing.assert_allclose(fn, weight, rtol=1e-9)
    np.testing.assert_allclose(ft, 0.0, atol=1e-9 * weight.max())
    # application points: under the centres, on the floor
    np.testing.assert_allclose(point, [[0.0, 0.0], [0.1, 0.0]], atol=1e-9)
    # wall contacts: branch from the particle centre to the contact point
    np.testing.assert_allclose(branch, point - sim.position[[0, 1]], atol=1e-15)
    np.testing.assert_allclose(c["normal"][order], [[0, -1], [0, -1]], atol=1e-12)


def test_file_of_a_run_passes_validation_and_holds_the_run(tmp_path):
    sim = _resting_pair()
    path = tmp_path / "rest.nc"
    with Recorder(path, sim, attrs={"scene": "rest"}) as rec:
        rec.write()
        for _ in range(3):
            sim.step()
            rec.write()
        # the file is readable while the run goes on
        ds_live = grainview.open_dataset(path, chunks=None)
        assert ds_live.sizes["time"] == 4
        ds_live.close()
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    assert ds.sizes["time"] == 4 and ds.sizes["particle"] == 2
    np.testing.assert_array_equal(ds["contact_count"].values, [2, 2, 2, 2])
    np.testing.assert_array_equal(ds["step"].values, [5, 6, 7, 8])
    np.testing.assert_allclose(ds["time"].values, H * np.array([5, 6, 7, 8]), rtol=1e-12)
    weight = (ds["mass"] * G).values
    floor = ds["wall_force"].sel(wall="bottom").values
    np.testing.assert_allclose(floor, np.tile([0.0, -weight.sum()], (4, 1)), rtol=1e-9, atol=1e-9)
    assert set(ds["kind"].values[-1, :2]) == {1, 2}
    np.testing.assert_allclose(ds["position"].values[-1], sim.position, rtol=0, atol=0)
    assert np.all(ds["nlgs_iterations"].values >= 1) and np.all(ds["nlgs_residual"].values <= 1e-12)
    assert np.all(ds["kinetic_energy"].values < 1e-20)
    assert ds.attrs["solver_version"] == __import__("solver").__version__
    assert ds.attrs["solver_time_step"] == pytest.approx(H)
    assert ds.attrs["solver_friction"] == pytest.approx(0.4)
    assert ds.attrs["scene"] == "rest"
    ds.close()
