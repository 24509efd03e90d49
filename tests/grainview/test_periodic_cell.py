"""The periodic cell of the contract: minimum images against a brute-force search, a hand-made
periodic lattice's stress and fabric, the same sample shifted across the cell, the file round
trip and the schema version, and validation of what a periodic file must hold."""

from __future__ import annotations

import numpy as np
import pytest

import grainview
from grainview.contract import cell as cells
from grainview.contract.errors import ParameterError, SchemaError


def brute_minimum_image(d, cell, periodic, reach=20):
    """The shortest d + m a + n b over |m|, |n| <= reach: a search with no cleverness."""
    ms = range(-reach, reach + 1) if periodic[0] else (0,)
    ns = range(-reach, reach + 1) if periodic[1] else (0,)
    candidates = np.stack([d + m * cell[0] + n * cell[1] for m in ms for n in ns], axis=1)
    lengths = np.linalg.norm(candidates, axis=-1)
    return candidates[np.arange(d.shape[0]), lengths.argmin(axis=1)]


@pytest.mark.parametrize("tilt", [0.0, 0.3, -0.49, 0.8, -1.7])
@pytest.mark.parametrize("periodic", [(1, 1), (1, 0), (0, 1)])
def test_minimum_image_is_the_shortest_image(tilt, periodic):
    rng = np.random.default_rng(7)
    cell = cells.restricted_cell([0.2, -0.1], [1.2, 0.6], tilt)
    d = rng.uniform(-4, 4, (2000, 2))
    got = cells.minimum_image(d, cell, periodic)
    want = brute_minimum_image(d, cell, periodic)
    np.testing.assert_allclose(np.linalg.norm(got, axis=-1), np.linalg.norm(want, axis=-1), rtol=0, atol=1e-12)
    # and it is an image of d: whole cells apart
    shift = cells.fractional(got - d, cell)
    np.testing.assert_allclose(shift, np.rint(shift), atol=1e-9)
    assert np.all(np.abs(shift[:, ~np.asarray(periodic, bool)]) < 1e-9)
    assert np.all(cells.image_shift(d, cell, periodic)[:, ~np.asarray(periodic, bool)] == 0)


def test_wrap_moves_points_into_the_cell_by_whole_cells():
    rng = np.random.default_rng(3)
    origin = np.array([0.5, -1.0])
    cell = cells.restricted_cell(origin, origin + [2.0, 1.5], 0.7)
    x = rng.uniform(-10, 10, (500, 2))
    wrapped = cells.wrap(x, origin, cell, [1, 1])
    st = cells.fractional(wrapped - origin, cell)
    assert np.all((st >= -1e-12) & (st < 1 + 1e-12))
    moved = cells.fractional(wrapped - x, cell)
    np.testing.assert_allclose(moved, np.rint(moved), atol=1e-9)
    assert cells.cell_area(cell) == pytest.approx(3.0)


def test_unwrap_tilt_undoes_a_flip():
    width = 2.0
    tilt = np.array([0.0, 0.5, 0.9, 1.1 - 2.0, 1.4 - 2.0])  # LAMMPS flipped past l/2 = 1
    np.testing.assert_allclose(cells.unwrap_tilt(tilt, width), [0.0, 0.5, 0.9, 1.1, 1.4])


def lattice(tilt=0.0, shift=(0.0, 0.0)):
    """A periodic square lattice of 4 x 4 disks of radius 0.55 in a 4 x 4 cell (tilt 0) or a
    sheared one, each overlapping its four neighbours (some across the cell's boundary) with a
    normal force 2 N along x and 1 N along y: by hand, sigma_xx = 16 * 2 * 1 / 16 = 2 Pa,
    sigma_yy = 1 Pa, sigma_xy = 0 (t = 1 m), and the fabric tensor diag(1/2, 1/2)."""
    n = 4
    grid = np.array([[x + 0.5, y + 0.5] for y in range(n) for x in range(n)], float)
    grid[:, 0] += grid[:, 1] / n * tilt  # the lattice follows the cell's tilt
    cell = cells.restricted_cell([0, 0], [n, n], tilt)
    position = cells.wrap(grid + np.asarray(shift), [0, 0], cell, [1, 1])
    i, j, normal, fn = [], [], [], []
    for p in range(n * n):
        x, y = p % n, p // n
        for q, force, unit in (((x + 1) % n + y * n, 2.0, [1.0, 0.0]),
                               (x + ((y + 1) % n) * n, 1.0, [tilt / n, 1.0])):
            a, b = (p, q) if p < q else (q, p)
            sign = 1.0 if p < q else -1.0
            u = np.asarray(unit) / np.linalg.norm(unit)
            i.append(a), j.append(b), normal.append(sign * u), fn.append(force)
    contacts = dict(i=i, j=j, normal=normal, fn=fn)
    return grainview.make_dataset(radius=np.full(n * n, 0.55), position=position, contacts=[contacts],
                                  box_min=[0, 0], box_max=[n, n], periodic=[1, 1], cell=cell)


def test_a_periodic_lattice_by_hand():
    ds = lattice()
    grainview.validate(ds)
    branch = ds["branch"].values[0, :int(ds["contact_count"][0])]
    np.testing.assert_allclose(np.linalg.norm(branch, axis=-1), 1.0)  # never the size of the box
    sigma = ds.grain.stress_tensor().isel(time=0).values
    np.testing.assert_allclose(sigma, [[2.0, 0.0], [0.0, 1.0]], atol=1e-15)
    fabric = ds.grain.fabric_tensor().isel(time=0).values
    np.testing.assert_allclose(fabric, [[0.5, 0.0], [0.0, 0.5]], atol=1e-15)
    assert float(ds.grain.coordination()["z"].isel(time=0)) == pytest.approx(4.0)
    assert ds.attrs["grainview_schema_version"] == "3.0"
    assert ds.attrs["cell_positions"] == "wrapped"


def test_a_sheared_lattice_by_hand():
    """The lattice in a cell tilted by 1 (gamma = 1/4): the vertical bonds are (1/4, 1), carrying
    1 N along themselves; sigma = (1/V) sum f (x) l from the two bond vectors alone."""
    ds = lattice(tilt=1.0)
    grainview.validate(ds)
    bond_y = np.array([0.25, 1.0])
    f_y = 1.0 * bond_y / np.linalg.norm(bond_y)
    by_hand = (16 * np.outer([2.0, 0.0], [1.0, 0.0]) + 16 * np.outer(f_y, bond_y)) / 16.0
    np.testing.assert_allclose(ds.grain.stress_tensor().isel(time=0).values, by_hand, atol=1e-15)


def test_the_same_sample_shifted_across_the_cell_gives_the_same_analysis():
    rng = np.random.default_rng(11)
    for tilt in (0.0, 1.3):
        base = lattice(tilt)
        shifted = lattice(tilt, shift=rng.uniform(-20, 20, 2))
        for name in ("stress_tensor", "fabric_tensor"):
            np.testing.assert_allclose(getattr(shifted.grain, name)().values, getattr(base.grain, name)().values,
                                       rtol=1e-12, atol=1e-14)
        assert float(shifted.grain.coordination()["z"][0]) == float(base.grain.coordination()["z"][0]) == 4.0


def test_a_periodic_file_round_trips_and_an_older_grainview_refuses_it(tmp_path, monkeypatch):
    ds = lattice(tilt=0.5)
    path = tmp_path / "periodic.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds))
    back = grainview.open_dataset(path)
    grainview.validate(back)
    np.testing.assert_array_equal(back["cell"].values, ds["cell"].values)
    np.testing.assert_array_equal(back["periodic"].values, [1, 1])
    assert list(back["cell_vector"].values) == ["a", "b"]
    from grainview.contract import file_checks

    monkeypatch.setattr(file_checks, "SCHEMA_VERSION", "2.0")  # a grainview from before the cell
    with pytest.raises(SchemaError, match="newer than this grainview"):
        grainview.open_dataset(path)


def test_the_snapshot_writer_writes_the_cell(tmp_path):
    ds = lattice(tilt=0.25)
    path = tmp_path / "written.nc"
    n = ds.sizes["particle"]
    count = int(ds["contact_count"][0])
    contacts = {name: ds[name].values[0, :count] for name in grainview.contract.schema.CONTACT_VARIABLES}
    with grainview.SnapshotWriter.create(path, radius=ds["radius"].values, n_vertices=np.zeros(n, "i4"),
                                         mass=ds["mass"].values, inertia=ds["inertia"].values,
                                         periodic=[1, 1]) as writer:
        for k in range(2):
            writer.append(time=float(k), position=ds["position"].values[0], angle=np.zeros(n), contacts=contacts,
                          box_min=[0.0, 0.0], box_max=[4.0, 4.0], cell=ds["cell"].values[0])
    back = grainview.open_dataset(path)
    grainview.validate(back)
    assert back.attrs["grainview_schema_version"] == "3.0"
    np.testing.assert_array_equal(back["cell"].values[1], ds["cell"].values[0])
    np.testing.assert_allclose(back.grain.stress_tensor().values[1], ds.grain.stress_tensor().values[0], rtol=1e-15)


def test_files_without_a_cell_keep_their_version():
    ds = grainview.make_dataset(radius=[1.0, 1.0], position=[[0.0, 0.0], [2.0, 0.0]],
                                contacts=[dict(i=[0], j=[1], normal=[[1.0, 0.0]], fn=[1.0])],
                                box_min=[-1, -1], box_max=[3, 1])
    assert ds.attrs["grainview_schema_version"] == "1.0"
    assert "cell" not in ds.variables and "cell_vector" not in ds.dims


def test_validation_finds_a_branch_across_the_box():
    ds = lattice()
    branch = ds["branch"].values.copy()
    branch[0, 0] = [-3.0, 0.0]  # x_j - x_i without the minimum image: the size of the box
    ds["branch"] = (ds["branch"].dims, branch, ds["branch"].attrs)
    with pytest.raises(SchemaError) as err:
        grainview.validate(ds)
    assert "not the minimum image" in str(err.value) and "longer than the particles allow" in str(err.value)


def test_validation_finds_a_cell_that_is_not_the_box_and_positions_outside_it():
    ds = lattice()
    cell = ds["cell"].values.copy()
    cell[0, 0, 1] = 0.5  # a tilted along y: not the restricted form
    ds["cell"] = (ds["cell"].dims, cell, ds["cell"].attrs)
    position = ds["position"].values.copy()
    position[0, 3] += [8.0, 0.0]
    ds["position"] = (ds["position"].dims, position, ds["position"].attrs)
    with pytest.raises(SchemaError) as err:
        grainview.validate(ds)
    text = str(err.value)
    assert "are not a = (l, 0), b = (tilt, h)" in text
    assert "outside the periodic cell" in text


def test_validation_names_a_cell_without_its_periodic_flags_and_bad_flags():
    ds = lattice()
    with pytest.raises(SchemaError, match="'cell' without 'periodic'"):
        grainview.validate(ds.drop_vars("periodic"))
    ds["periodic"] = (("cell_vector",), np.array([0, 0], "i1"))
    with pytest.raises(SchemaError, match="no cell vector is periodic"):
        grainview.validate(ds)


def test_make_dataset_and_the_writer_refuse_what_is_not_a_cell(tmp_path):
    with pytest.raises(ParameterError, match="cell given without periodic"):
        grainview.make_dataset(radius=[1.0], position=[[0.0, 0.0]], contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)),
                                                                                   fn=[])],
                               box_min=[-1, -1], box_max=[1, 1], cell=np.eye(2))
    with pytest.raises(ParameterError, match="expected 0 or 1"):
        grainview.SnapshotWriter.create(tmp_path / "x.nc", radius=[1.0], n_vertices=[0], mass=[1.0], inertia=[1.0],
                                        periodic=[2, 1])
    assert not (tmp_path / "x.nc").exists()


def test_info_describes_the_cell_and_its_shear(tmp_path, capsys):
    from grainview.app.cli import main

    first, second = lattice(tilt=0.0), lattice(tilt=1.0)
    ds = grainview.make_dataset(radius=first["radius"].values,
                                position=np.stack([first["position"].values[0], second["position"].values[0]]),
                                contacts=[{name: snap[name].values[0, :32] for name in ("i", "j", "normal", "fn")}
                                          for snap in (first, second)],
                                box_min=[0, 0], box_max=[4, 4], periodic=[1, 1],
                                cell=np.stack([first["cell"].values[0], second["cell"].values[0]]))
    path = tmp_path / "sheared.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds))
    assert main(["info", "--check", str(path)]) == 0
    out = capsys.readouterr().out
    assert ("periodic cell: repeats along x and along the cell's second vector (biperiodic); tilt 0 .. 1 m, "
            "shear gamma 0.25 at the last snapshot; positions wrapped") in out
