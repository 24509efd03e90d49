"""VTK and CSV export, read back: point and cell counts and field values equal the dataset's."""

import os
import xml.etree.ElementTree as ElementTree

import grainview
import numpy as np
import pandas as pd
import pytest

from grainview.errors import ParameterError
from grainview.export import write_csv, write_vtk

from .test_lifetimes import SERIES
from .test_persistence import N, sequence_dataset

meshio = pytest.importorskip("meshio")


def polygons_and_disks():
    ds = sequence_dataset(SERIES)
    ds["n_vertices"] = ("particle", np.array([5, 5, 0, 3, 5], dtype=ds["n_vertices"].dtype))
    rng = np.random.default_rng(0)
    ds["position"] = (("time", "particle", "xy"), rng.uniform(0, 1, ds["position"].shape))
    ds["angle"] = (("time", "particle"), rng.uniform(0, 6, ds["angle"].shape))
    return ds


def test_vtk_files_read_back(tmp_path):
    ds = polygons_and_disks()
    paths = write_vtk(ds, tmp_path, every=2)
    # snapshots 0, 2, 4 and the last (5): 4 x 2 files and 2 collections
    assert len(paths) == 10 and all(os.path.exists(p) for p in paths)
    k = 2
    particles = meshio.read(tmp_path / f"particles_{k:05d}.vtu")
    blocks = {block.type: block for block in particles.cells}
    assert blocks["vertex"].data.shape == (1, 1)  # the one disk
    polygon_cells = sum(len(b.data) for b in particles.cells if b.type == "polygon")
    assert polygon_cells == 4 and particles.points.shape == (1 + 3 * 5 + 3, 3)
    ids = np.concatenate(particles.cell_data["particle"])
    fields = ds.grain.particle_fields().isel(time=k)
    np.testing.assert_array_equal(np.concatenate(particles.cell_data["c"]), fields.c.values[ids])
    np.testing.assert_allclose(np.concatenate(particles.cell_data["radius"]), ds.radius.values[ids])
    # the disk's vertex cell sits at its centre; a pentagon's first vertex where the contract puts it
    disk = int(ids[0])
    np.testing.assert_allclose(particles.points[blocks["vertex"].data[0, 0], :2],
                               ds.position.isel(time=k).values[disk])
    contacts = meshio.read(tmp_path / f"contacts_{k:05d}.vtu")
    assert len(contacts.cells[0].data) == len(SERIES[k])
    got = sorted(zip(contacts.cell_data["i"][0], contacts.cell_data["j"][0], contacts.cell_data["fn"][0]))
    assert got == sorted((i, j, fn) for i, j, _, fn in SERIES[k])
    tree = ElementTree.parse(tmp_path / "contacts.pvd")
    entries = [(float(e.get("timestep")), e.get("file")) for e in tree.iter("DataSet")]
    assert entries == [(float(t), f"contacts_{t:05d}.vtu") for t in (0, 2, 4, 5)]


def test_existing_files_are_not_overwritten(tmp_path):
    ds = polygons_and_disks()
    write_vtk(ds, tmp_path, every=5)
    with pytest.raises(ParameterError, match="exists"):
        write_vtk(ds, tmp_path, every=5)
    write_vtk(ds, tmp_path, every=5, overwrite=True)
    assert not [f for f in os.listdir(tmp_path) if ".part" in f]


def test_one_existing_file_refuses_the_export_before_anything_is_written(tmp_path):
    ds = polygons_and_disks()
    last = ds.sizes["time"] - 1
    (tmp_path / f"contacts_{last:05d}.vtu").write_text("mine")  # a file of the user's, written last by the export
    with pytest.raises(ParameterError, match="exists"):
        write_vtk(ds, tmp_path, every=1)
    assert os.listdir(tmp_path) == [f"contacts_{last:05d}.vtu"]  # nothing else written
    assert (tmp_path / f"contacts_{last:05d}.vtu").read_text() == "mine"


def test_csv_is_the_tidy_table_of_every_snapshot(tmp_path):
    ds = sequence_dataset(SERIES)
    path = write_csv(ds, tmp_path)
    table = pd.read_csv(path)
    assert len(table) == sum(len(s) for s in SERIES)
    at = table[table.snapshot == 2]
    assert sorted(zip(at.i, at.j, at.fn_N)) == sorted((i, j, fn) for i, j, _, fn in SERIES[2])
    assert (at.time_s == 2.0).all()


def test_export_command(tmp_path, capsys):
    from grainview.cli import main

    ds = polygons_and_disks()
    source = tmp_path / "run.nc"
    ds.to_netcdf(source, **grainview.dataset.netcdf_options(ds))
    assert main(["export", str(source), "--to", "vtk", "--out", str(tmp_path / "vtk"), "--every", "3"]) == 0
    assert sorted(os.listdir(tmp_path / "vtk"))[:2] == ["contacts.pvd", "contacts_00000.vtu"]
    assert main(["export", str(source), "--to", "csv", "--out", str(tmp_path / "csv")]) == 0
    assert os.path.exists(tmp_path / "csv" / "contacts.csv")
    assert "wrote" in capsys.readouterr().out
