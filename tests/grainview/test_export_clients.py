"""The VTK export opened by the programs it is written for: VTK's own XML readers (the ``vtk``
wheel, what ParaView reads with) and OVITO (the ``ovito`` wheel). Both are optional (the
``clients`` extra, ``pip install -e ".[clients]"``); without them these tests are skipped.

Counts of particles, polygons and contacts, and positions, radii, per-particle fields and
contact forces read back by each client, against the dataset."""

import os
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

from grainview.export import write_vtk

from .test_export import polygons_and_disks
from .test_lifetimes import SERIES
from .test_persistence import N, S, sequence_dataset

EVERY = 2
SNAPSHOTS = (0, 2, 4, 5)  # every second snapshot of SERIES and the last


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    ds = polygons_and_disks()
    out = tmp_path_factory.mktemp("vtk")
    write_vtk(ds, out, every=EVERY)
    return ds, out


def pairs(k):
    """SERIES' particle pairs at snapshot k as sorted (i, j, fn)."""
    return sorted((i, j, fn) for i, j, _, fn in SERIES[k] if j < N)


def vtk_arrays(data):
    from vtk.util.numpy_support import vtk_to_numpy

    return {data.GetArrayName(a): vtk_to_numpy(data.GetArray(a)) for a in range(data.GetNumberOfArrays())}


def test_vtk_reads_every_block(exported):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    ds, out = exported
    fields = ds.grain.particle_fields()
    for k in SNAPSHOTS:
        reader = vtk.vtkXMLMultiBlockDataReader()
        reader.SetFileName(str(out / f"snapshot_{k:05d}.vtm"))
        reader.Update()
        blocks = reader.GetOutput()
        names = [blocks.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME()) for b in range(blocks.GetNumberOfBlocks())]
        assert names == ["particles", "contacts", "wall_contacts"]
        particles, contacts, walls = (blocks.GetBlock(b) for b in range(3))

        assert (particles.GetNumberOfPoints(), particles.GetNumberOfVerts()) == (5, 5)
        np.testing.assert_array_equal(vtk_to_numpy(particles.GetPoints().GetData())[:, :2], ds.position.values[k])
        data = vtk_arrays(particles.GetPointData())
        np.testing.assert_array_equal(data["radius"], ds.radius.values)
        np.testing.assert_array_equal(data["c"], fields.c.values[k])
        np.testing.assert_array_equal(data["v"][:, :2], ds.velocity.values[k])

        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(str(out / f"polygons_{k:05d}.vtp"))
        reader.Update()
        polygons = reader.GetOutput()
        assert (polygons.GetNumberOfPolys(), polygons.GetNumberOfPoints()) == (4, 5 + 5 + 3 + 5)
        assert sorted(vtk_arrays(polygons.GetCellData())["id"]) == [0, 1, 3, 4]

        assert contacts.GetNumberOfLines() == len(pairs(k))
        cells = vtk_arrays(contacts.GetCellData())
        assert sorted(zip(cells["id1"], cells["id2"], cells["fn"])) == pairs(k)
        np.testing.assert_array_equal(cells["ft"], cells["fn"] / 4)

        assert walls.GetNumberOfLines() == 1
        cells = vtk_arrays(walls.GetCellData())
        assert (cells["particle_id"][0], cells["wall_id"][0], cells["fn"][0]) == (4, 0, 1.0)


def test_ovito_reads_particles_and_contacts_on_the_time_axis(exported):
    pytest.importorskip("ovito")
    from ovito.io import import_file

    ds, out = exported
    fields = ds.grain.particle_fields()
    pipeline = import_file(str(out / "snapshots.pvd"))
    assert pipeline.num_frames == len(SNAPSHOTS)
    for frame, k in enumerate(SNAPSHOTS):
        data = pipeline.compute(frame)
        assert data.attributes["Time"] == float(ds.time.values[k])
        particles = data.particles
        assert particles.count == 5
        np.testing.assert_array_equal(particles.identifiers[...], np.arange(5))
        np.testing.assert_array_equal(particles.positions[...][:, :2], ds.position.values[k])
        np.testing.assert_allclose(particles["Radius"][...], 0.01, rtol=1e-7)  # OVITO keeps radii in float32
        np.testing.assert_array_equal(particles["c"][...], fields.c.values[k])
        np.testing.assert_array_equal(particles.velocities[...][:, :2], ds.velocity.values[k])

        # lines: two points per contact, each row holding the contact's data
        lines = data.lines["particle-particle-contacts"]
        assert lines.count == 2 * len(pairs(k))
        rows = slice(0, None, 2)
        got = zip(lines["Particle Identifier 1"][rows], lines["Particle Identifier 2"][rows], lines["fn"][rows])
        assert sorted(got) == pairs(k)
        np.testing.assert_array_equal(lines["ft"][rows], lines["fn"][rows] / 4)
        np.testing.assert_array_equal(lines.positions[rows][:, :2], ds.position.values[k][lines["Particle Identifier 1"][rows]])

        walls = data.lines["particle-wall-contacts"]
        assert walls.count == 2
        assert (walls["Particle Identifier"][0], walls["Wall Identifier"][0], walls["fn"][0]) == (4, 0, 1.0)


def test_ovito_opens_a_snapshot_without_particle_pairs(tmp_path):
    pytest.importorskip("ovito")
    from ovito.io import import_file

    ds = sequence_dataset([[(4, N, S, 1.0)], [(0, 1, S, 2.0), (4, N, S, 1.0)]])
    write_vtk(ds, tmp_path)
    assert "contacts_00000.vtp" not in os.listdir(tmp_path)
    assert [e.get("file") for e in ElementTree.parse(tmp_path / "snapshot_00000.vtm").iter("DataSet")][1] is None
    data = import_file(str(tmp_path / "snapshot_00000.vtm")).compute()
    assert data.particles.count == 5
    assert "particle-particle-contacts" not in data.lines
    assert data.lines["particle-wall-contacts"].count == 2
