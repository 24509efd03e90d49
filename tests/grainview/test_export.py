"""VTK and CSV export, read back: the VTK files parsed as XML (their structure, what OVITO's
readers require of it, and every value decoded), the CSV with pandas. The same VTK files loaded
by VTK's and OVITO's own readers: test_export_clients.py."""

import base64
import os
import xml.etree.ElementTree as ElementTree

import grainview
import numpy as np
import pandas as pd
import pytest

from grainview.contract.errors import ParameterError
from grainview.export import write_csv, write_vtk

from .test_lifetimes import SERIES
from .test_persistence import N, S, sequence_dataset


def polygons_and_disks():
    """SERIES (a wall contact at every snapshot) on two pentagons, a disk, a triangle and a
    pentagon at random places and angles, with tangential forces fn / 4 and velocities."""
    ds = sequence_dataset(SERIES)
    ds["n_vertices"] = ("particle", np.array([5, 5, 0, 3, 5], dtype=ds["n_vertices"].dtype))
    rng = np.random.default_rng(0)
    ds["position"] = (("time", "particle", "xy"), rng.uniform(0, 1, ds["position"].shape))
    ds["angle"] = (("time", "particle"), rng.uniform(0, 6, ds["angle"].shape))
    ds["ft"] = ds["fn"] / 4
    ds["velocity"] = (("time", "particle", "xy"), rng.uniform(-1, 1, ds["position"].shape))
    return ds


def read_vtp(path):
    """A PolyData file as (VTKFile attributes, Piece attributes, arrays by section and name),
    each binary DataArray decoded by hand: base64 of a little-endian UInt64 byte count, then
    the values."""
    root = ElementTree.parse(path).getroot()
    piece = root.find("PolyData/Piece")
    arrays = {}
    for section in piece:
        arrays[section.tag] = {}
        for element in section.iter("DataArray"):
            assert element.get("format") == "binary"
            raw = base64.b64decode(element.text)
            size = int(np.frombuffer(raw[:8], "<u8")[0])
            assert len(raw) == 8 + size  # the count is the values' bytes
            values = np.frombuffer(raw[8:], {"Float64": "<f8", "Int64": "<i8"}[element.get("type")])
            components = int(element.get("NumberOfComponents", 1))
            arrays[section.tag][element.get("Name")] = values.reshape(-1, components) if components > 1 else values
    return root.attrib, piece.attrib, arrays


def test_vtk_files_hold_the_snapshots(tmp_path):
    ds = polygons_and_disks()
    paths = write_vtk(ds, tmp_path, every=2)
    # snapshots 0, 2, 4 and the last (5): 4 x (4 .vtp + 1 .vtm) files and the two collections
    assert len(paths) == 22 and all(os.path.exists(p) for p in paths)
    assert [os.path.basename(p) for p in paths[-2:]] == ["snapshots.pvd", "polygons.pvd"]
    k = 2
    position, angle = ds.position.values[k], ds.angle.values[k]

    # particles: one point and one vertex cell each, the names OVITO maps (id, radius, v)
    header, piece, arrays = read_vtp(tmp_path / f"particles_{k:05d}.vtp")
    assert header == {"type": "PolyData", "version": "1.0", "byte_order": "LittleEndian", "header_type": "UInt64"}
    assert piece == {"NumberOfPoints": "5", "NumberOfVerts": "5"}  # no line or polygon counted
    np.testing.assert_array_equal(arrays["Points"]["Points"], np.column_stack([position, np.zeros(5)]))
    np.testing.assert_array_equal(arrays["Verts"]["offsets"], [1, 2, 3, 4, 5])
    data = arrays["PointData"]
    np.testing.assert_array_equal(data["id"], np.arange(5))
    np.testing.assert_array_equal(data["radius"], np.full(5, 0.01))
    np.testing.assert_array_equal(data["n_vertices"], [5, 5, 0, 3, 5])
    np.testing.assert_array_equal(data["angle"], angle)
    np.testing.assert_array_equal(data["v"], np.column_stack([ds.velocity.values[k], np.zeros(5)]))
    fields = ds.grain.particle_fields().isel(time=k)
    # c by hand from SERIES[2]: (0,1) (1,2) (2,3) and the wall contact of 4
    np.testing.assert_array_equal(data["c"], [1, 2, 2, 1, 1])
    np.testing.assert_array_equal(data["rattler"], fields.rattler.values.astype(int))

    # polygons: the 4 outlines, vertex m of polygon p at x_p + R (cos(angle_p + 2 pi m / n), sin(...))
    _, piece, arrays = read_vtp(tmp_path / f"polygons_{k:05d}.vtp")
    assert piece == {"NumberOfPoints": str(5 + 5 + 3 + 5), "NumberOfPolys": "4"}
    ids = arrays["CellData"]["id"]
    sizes = np.diff(arrays["Polys"]["offsets"], prepend=0)
    assert sorted(ids) == [0, 1, 3, 4] and list(sizes) == [{0: 5, 1: 5, 3: 3, 4: 5}[p] for p in ids]
    points = np.split(arrays["Points"]["Points"][arrays["Polys"]["connectivity"]], np.cumsum(sizes)[:-1])
    for p, n, outline in zip(ids, sizes, points):
        phase = angle[p] + 2 * np.pi * np.arange(n) / n
        np.testing.assert_allclose(outline[:, :2], position[p] + 0.01 * np.column_stack([np.cos(phase), np.sin(phase)]),
                                   rtol=0, atol=1e-15)
    np.testing.assert_array_equal(arrays["CellData"]["n_vertices"], sizes)

    # particle pairs: a line from the centre of i along the branch vector, id1/id2 = i/j
    _, piece, arrays = read_vtp(tmp_path / f"contacts_{k:05d}.vtp")
    pairs = [(i, j, fn) for i, j, _, fn in SERIES[k] if j < N]
    assert piece == {"NumberOfPoints": str(2 * len(pairs)), "NumberOfLines": str(len(pairs))}
    cells = arrays["CellData"]
    got = sorted(zip(cells["id1"], cells["id2"], cells["fn"], cells["ft"]))
    assert got == sorted((i, j, fn, fn / 4) for i, j, fn in pairs)
    ends = arrays["Points"]["Points"][:, :2].reshape(-1, 2, 2)
    np.testing.assert_array_equal(ends[:, 0], position[cells["id1"]])
    np.testing.assert_allclose(ends[:, 1], position[cells["id1"]] + [0.02, 0.0], rtol=0, atol=1e-15)  # SERIES' branch
    # kind, and force class against <f_n> = (6 + 1 + 3 + 1) / 4 N over the pairs and the wall
    # contact: 6 and 3 N strong (3), 1 N weak (2: between 0.1 and 1 <f_n>); (0,1) is double
    by_pair = {(i, j): (kind, cls) for i, j, kind, cls in zip(cells["id1"], cells["id2"], cells["kind"], cells["force_class"])}
    assert by_pair == {(0, 1): (2, 3), (1, 2): (1, 2), (2, 3): (1, 3)}

    # particle-wall contacts: particle_id, wall_id (the wall's index, j - N)
    _, piece, arrays = read_vtp(tmp_path / f"wall_contacts_{k:05d}.vtp")
    assert piece == {"NumberOfPoints": "2", "NumberOfLines": "1"}
    cells = arrays["CellData"]
    assert (cells["particle_id"].tolist(), cells["wall_id"].tolist(), cells["fn"].tolist()) == ([4], [0], [1.0])
    assert (cells["ft"].tolist(), cells["kind"].tolist(), cells["force_class"].tolist()) == ([0.25], [1], [2])

    # the snapshot's blocks (the polygons apart) and the time collections
    blocks = [(e.get("name"), e.get("file")) for e in ElementTree.parse(tmp_path / f"snapshot_{k:05d}.vtm").iter("DataSet")]
    assert blocks == [(b, f"{b}_{k:05d}.vtp") for b in ("particles", "contacts", "wall_contacts")]
    for name, stem in (("snapshots", "snapshot_{:05d}.vtm"), ("polygons", "polygons_{:05d}.vtp")):
        entries = [(float(e.get("timestep")), e.get("file")) for e in ElementTree.parse(tmp_path / f"{name}.pvd").iter("DataSet")]
        assert entries == [(float(t), stem.format(t)) for t in (0, 2, 4, 5)]


def test_a_snapshot_without_particle_pairs_has_an_empty_contacts_block(tmp_path):
    ds = sequence_dataset([[(4, N, S, 1.0)], [(0, 1, S, 2.0), (4, N, S, 1.0)]])  # disks only
    paths = write_vtk(ds, tmp_path)
    names = sorted(os.listdir(tmp_path))
    assert names == sorted(os.path.basename(p) for p in paths)
    assert "contacts_00000.vtp" not in names and "contacts_00001.vtp" in names
    assert not [n for n in names if n.startswith("polygons")]  # no polygon in the file, no outlines
    blocks = [(e.get("name"), e.get("file")) for e in ElementTree.parse(tmp_path / "snapshot_00000.vtm").iter("DataSet")]
    assert blocks == [("particles", "particles_00000.vtp"), ("contacts", None), ("wall_contacts", "wall_contacts_00000.vtp")]
    _, piece, arrays = read_vtp(tmp_path / "wall_contacts_00000.vtp")
    assert piece == {"NumberOfPoints": "2", "NumberOfLines": "1"} and arrays["CellData"]["wall_id"].tolist() == [0]
    # a contacts file of an earlier export at that snapshot is not left beside the new files
    (tmp_path / "contacts_00000.vtp").write_text("old")
    write_vtk(ds, tmp_path, overwrite=True)
    assert "contacts_00000.vtp" not in os.listdir(tmp_path)


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
    (tmp_path / f"snapshot_{last:05d}.vtm").write_text("mine")  # a file of the user's, written late by the export
    with pytest.raises(ParameterError, match="exists"):
        write_vtk(ds, tmp_path, every=1)
    assert os.listdir(tmp_path) == [f"snapshot_{last:05d}.vtm"]  # nothing else written
    assert (tmp_path / f"snapshot_{last:05d}.vtm").read_text() == "mine"


def test_csv_is_the_tidy_table_of_every_snapshot(tmp_path):
    ds = sequence_dataset(SERIES)
    path = write_csv(ds, tmp_path)
    table = pd.read_csv(path)
    assert len(table) == sum(len(s) for s in SERIES)
    at = table[table.snapshot == 2]
    assert sorted(zip(at.i, at.j, at.fn_N)) == sorted((i, j, fn) for i, j, _, fn in SERIES[2])
    assert (at.time_s == 2.0).all()


@pytest.mark.parametrize("every", [1, 2])
def test_csv_in_blocks_is_the_snapshots_tables_one_after_the_other(tmp_path, monkeypatch, capsys, every):
    """The table read a block of snapshots at a time, whatever the block, is the tables of the
    snapshots one by one, concatenated (the per-snapshot way, rebuilt here), with a progress
    bar over the snapshots when asked for."""
    import grainview.export.contacts_csv as export
    from grainview.analysis.snapshots import snapshot_indices
    from grainview.analysis.tables import contacts_table

    ds = polygons_and_disks()
    chosen = snapshot_indices(ds, every)
    frames = []
    for k in chosen:
        table = contacts_table(ds, time=int(k))
        table.insert(0, "time_s", table.attrs["time"])
        table.insert(0, "snapshot", int(k))
        table.insert(table.columns.get_loc("fn"), "loaded", table["fn"] > 0)
        table["kind"] = table["kind"].map({1: "simple", 2: "double"})
        frames.append(table.rename(columns={"fn": "fn_N", "ft": "ft_N", "point_x": "point_x_m",
                                            "point_y": "point_y_m", "branch_x": "branch_x_m",
                                            "branch_y": "branch_y_m", "gap": "gap_m"}))
    expected = pd.concat(frames, ignore_index=True).to_csv(index=False)
    whole = (tmp_path / "whole")
    with open(write_csv(ds, whole, every=every, progress=False)) as f:
        assert f.read() == expected
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(export, "CSV_BLOCK_SLOTS", 1)  # one snapshot a block
    with open(write_csv(ds, tmp_path / "blocks", every=every, progress=True)) as f:
        assert f.read() == expected
    bar = capsys.readouterr().err
    assert "CSV export" in bar and f"{len(chosen)}/{len(chosen)}" in bar and len(chosen) > 2


def test_export_command(tmp_path, capsys):
    from grainview.app.cli import main

    ds = polygons_and_disks()
    source = tmp_path / "run.nc"
    ds.to_netcdf(source, **grainview.contract.dataset.netcdf_options(ds))
    assert main(["export", str(source), "--to", "vtk", "--out", str(tmp_path / "vtk"), "--every", "3"]) == 0
    assert sorted(os.listdir(tmp_path / "vtk"))[:2] == ["contacts_00000.vtp", "contacts_00003.vtp"]
    assert "snapshots.pvd" in capsys.readouterr().out
    assert main(["export", str(source), "--to", "csv", "--out", str(tmp_path / "csv")]) == 0
    assert os.path.exists(tmp_path / "csv" / "contacts.csv")
    assert "wrote" in capsys.readouterr().out
