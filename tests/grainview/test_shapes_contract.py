"""Shapes in the contract (grainview/contract/shapes.py, docs/schema.md "Shapes"): each function
against cases worked out by hand (a 3-4-5 right triangle, a rectangle, a regular pentagon's
closed forms, a disk), every fault shape_problems names, irregular polygons through the
writer, make_dataset, validate, ``grainview info``, the solid fraction, the maps and the VTK
export, and files of the layout without ``vertices`` (regular polygons) as before."""

from __future__ import annotations

import math

import netCDF4
import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import PolyCollection

import grainview
import grainview.plot as gp
from grainview.app.cli import main
from grainview.contract.dataset import make_dataset
from grainview.contract.errors import ParameterError, SchemaError
from grainview.contract.shapes import (body_vertices, body_vertices_of, inertia_per_mass, particle_area,
                                       particle_area_of, polygon_properties, regular_polygons, regular_vertices,
                                       shape_problems, vertex_phases, world_vertices)
from grainview.contract.validation import validate
from grainview.contract.writer import SnapshotWriter
from grainview.export import write_vtk
from grainview.app.file_summary import describe_file, read_facts

from .test_export import read_vtp

# --- the hand-made shapes ----------------------------------------------------------------------

TRIANGLE = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]])  # legs 3 and 4, hypotenuse 5, counter-clockwise
TRIANGLE_CENTROID = np.array([1.0, 4.0 / 3.0])  # the mean of the vertices
A, B = 2.0, 1.0  # the rectangle's half sides
RECTANGLE = np.array([[-A, -B], [A, -B], [A, B], [-A, B]])
R5 = 1.5  # the pentagon's circumscribed radius


def padded(*polygons, width=None):
    """(P, V, 2) own-frame vertices, NaN after each polygon's count (None: a disk)."""
    width = width or max(len(p) for p in polygons if p is not None)
    out = np.full((len(polygons), width, 2), np.nan)
    for k, p in enumerate(polygons):
        if p is not None:
            out[k, :len(p)] = p
    return out


# --- contract/shapes.py against hand values ---------------------------------------------------

def test_right_triangle_by_hand():
    """Area a b / 2 = 6; centroid (a/3, b/3); I/m about the centroid (a^2 + b^2 + c^2)/36 =
    50/36; farthest vertex (0, 4): sqrt(1 + (8/3)^2) = sqrt(73)/3; the nearest edge line to the
    centroid is the hypotenuse 4x + 3y = 12, at |4 + 4 - 12| / 5 = 0.8."""
    props = polygon_properties(TRIANGLE[None])
    assert props["area"][0] == pytest.approx(6.0, rel=1e-15)
    np.testing.assert_allclose(props["centroid"][0], TRIANGLE_CENTROID, rtol=1e-15)
    centred = polygon_properties((TRIANGLE - TRIANGLE_CENTROID)[None])
    np.testing.assert_allclose(centred["centroid"][0], 0.0, atol=1e-15)
    assert centred["inertia_per_mass"][0] == pytest.approx(50 / 36, rel=1e-14)
    assert centred["radius"][0] == pytest.approx(math.sqrt(73) / 3, rel=1e-15)
    assert centred["inradius"][0] == pytest.approx(0.8, rel=1e-14)


def test_rectangle_by_hand():
    """A 2a x 2b rectangle: area 4ab, I/m (a^2 + b^2)/3, farthest vertex sqrt(a^2 + b^2),
    inradius min(a, b)."""
    props = polygon_properties(RECTANGLE[None])
    assert props["area"][0] == 4 * A * B
    np.testing.assert_array_equal(props["centroid"][0], [0.0, 0.0])
    assert props["inertia_per_mass"][0] == pytest.approx((A ** 2 + B ** 2) / 3, rel=1e-15)
    assert props["radius"][0] == pytest.approx(math.hypot(A, B), rel=1e-15)
    assert props["inradius"][0] == pytest.approx(min(A, B), rel=1e-15)


def test_regular_pentagon_against_its_closed_forms():
    """Vertex k at R (cos 2 pi k/5, sin 2 pi k/5); area (5/2) R^2 sin 72 deg, I/m R^2 (2 + cos 72
    deg)/6, inradius R cos 36 deg; the closed forms without vertices equal the shoelace sums of
    the vertices."""
    np.testing.assert_allclose(vertex_phases(4), [0, np.pi / 2, np.pi, 3 * np.pi / 2], rtol=1e-15)
    v = regular_vertices(R5, 5)
    np.testing.assert_allclose(v[1], [R5 * math.cos(0.4 * math.pi), R5 * math.sin(0.4 * math.pi)], rtol=1e-15)
    area = 2.5 * R5 ** 2 * math.sin(0.4 * math.pi)
    polar = R5 ** 2 * (2 + math.cos(0.4 * math.pi)) / 6
    props = polygon_properties(v[None])
    assert props["area"][0] == pytest.approx(area, rel=1e-14)
    assert props["inertia_per_mass"][0] == pytest.approx(polar, rel=1e-14)
    assert props["inradius"][0] == pytest.approx(R5 * math.cos(0.2 * math.pi), rel=1e-14)
    assert particle_area([R5], [5])[0] == pytest.approx(area, rel=1e-15)
    assert inertia_per_mass([R5], [5])[0] == pytest.approx(polar, rel=1e-15)
    np.testing.assert_allclose(particle_area([R5], [5], v[None]), [area], rtol=1e-14)
    np.testing.assert_allclose(inertia_per_mass([R5], [5], v[None]), [polar], rtol=1e-14)
    np.testing.assert_array_equal(body_vertices([R5], [5])[0], v)


def test_disks_and_padding():
    """A disk: pi R^2 and R^2/2, all-NaN rows; a padded triangle gives the values of the bare one."""
    radius = [1.0, 2.0]
    assert body_vertices(radius, [0, 0]).shape == (2, 0, 2)
    np.testing.assert_allclose(particle_area(radius, [0, 0]), [np.pi, 4 * np.pi], rtol=1e-15)
    np.testing.assert_allclose(inertia_per_mass(radius, [0, 0]), [0.5, 2.0], rtol=1e-15)
    triangle = TRIANGLE - TRIANGLE_CENTROID
    v = padded(triangle, RECTANGLE, None)
    r = [math.sqrt(73) / 3, math.hypot(A, B), 0.7]
    np.testing.assert_allclose(particle_area(r, [3, 4, 0], v), [6.0, 4 * A * B, np.pi * 0.49], rtol=1e-14)
    np.testing.assert_allclose(inertia_per_mass(r, [3, 4, 0], v), [50 / 36, (A ** 2 + B ** 2) / 3, 0.245], rtol=1e-14)
    body = body_vertices(r, [3, 4, 0], v)
    assert np.isnan(body[0, 3]).all() and np.isnan(body[2]).all()
    np.testing.assert_array_equal(body[1], RECTANGLE)


def test_world_vertices_by_hand():
    """Rot(pi/2) (x, y) = (-y, x): the rectangle at (10, 20) turned a quarter turn has its
    vertex (a, -b) at (10 + b, 20 + a)."""
    world = world_vertices(np.array([[10.0, 20.0]]), np.array([np.pi / 2]), RECTANGLE[None])
    np.testing.assert_allclose(world[0], [[10 + B, 20 - A], [10 + B, 20 + A], [10 - B, 20 + A], [10 - B, 20 - A]],
                               rtol=0, atol=1e-14)
    # batched over time: (T, P, 2) positions and (T, P) angles
    many = world_vertices(np.zeros((3, 1, 2)), np.zeros((3, 1)), RECTANGLE[None])
    assert many.shape == (3, 1, 4, 2)


def test_which_polygons_are_regular():
    """A regular pentagon turned in its own frame and a square are regular; a rectangle, a
    triangle, a disk are not; without vertices every polygon is."""
    turned = R5 * np.stack([np.cos(0.3 + vertex_phases(5)), np.sin(0.3 + vertex_phases(5))], -1)
    square = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    v = padded(turned, square, RECTANGLE, TRIANGLE - TRIANGLE_CENTROID, None)
    r = [R5, 1.0, math.hypot(A, B), math.sqrt(73) / 3, 1.0]
    np.testing.assert_array_equal(regular_polygons(r, [5, 4, 4, 3, 0], v), [True, True, False, False, False])
    np.testing.assert_array_equal(regular_polygons(r, [5, 4, 4, 3, 0]), [True, True, True, True, False])


# --- shape_problems: each fault named, with its first particle -------------------------------

def _sound():
    """A disk, the centred triangle and the rectangle: radius, n_vertices, vertices."""
    return ([0.5, math.sqrt(73) / 3, math.hypot(A, B)], np.array([0, 3, 4]),
            padded(None, TRIANGLE - TRIANGLE_CENTROID, RECTANGLE))


def test_sound_shapes_have_no_problem():
    assert shape_problems(*_sound()) == []


@pytest.mark.parametrize("fault,expected", [
    ("two vertices", "n_vertices: 1 particle(s) with a count other than 0 (disk) or 3 .. 4 (the vertex dimension), "
                     "first particle 1"),
    ("more than the dimension", "n_vertices: 1 particle(s) with a count other than 0 (disk) or 3 .. 4"),
    ("a NaN vertex", "vertices: 1 particle(s) whose first n_vertices rows are not all finite or whose other rows "
                     "are not NaN, first particle 2"),
    ("a vertex after the count", "vertices: 1 particle(s) whose first n_vertices rows are not all finite"),
    ("a disk with vertices", "vertices: 1 particle(s) whose first n_vertices rows are not all finite or whose "
                             "other rows are not NaN, first particle 0"),
    ("clockwise", "vertices: 1 polygon(s) not convex with counter-clockwise vertices, first particle 2"),
    ("concave", "vertices: 1 polygon(s) not convex with counter-clockwise vertices, first particle 2"),
    ("off centre", "vertices: 1 polygon(s) whose centroid is not at the origin of their own frame, first particle 1"),
    ("radius", "radius: 1 polygon(s) whose radius is not their farthest vertex's distance from the centroid, "
               "first particle 2"),
])
def test_each_shape_fault_is_one_line(fault, expected):
    radius, n, v = _sound()
    radius = list(radius)
    if fault == "two vertices":
        n[1] = 2
    elif fault == "more than the dimension":
        n[1] = 5
    elif fault == "a NaN vertex":
        v[2, 1] = np.nan
    elif fault == "a vertex after the count":
        v[1, 3] = [0.1, 0.1]
    elif fault == "a disk with vertices":
        v[0, :3] = TRIANGLE
    elif fault == "clockwise":
        v[2] = RECTANGLE[::-1]
    elif fault == "concave":  # a dart: (0, b/2) pulled in between (a, b) and (-a, b)
        v[2] = [[-A, -B], [A, -B], [A, B], [0.0, -0.5 * B]]
        radius[2] = math.hypot(A, B)
    elif fault == "off centre":
        v[1, :3] = TRIANGLE
        radius[1] = 4.0
    elif fault == "radius":
        radius[2] *= 1.001
    problems = shape_problems(radius, n, v)
    assert len(problems) == 1 and problems[0].startswith(expected), problems


def test_a_star_polygon_is_not_convex():
    """The pentagram (a regular pentagon's vertices taken every second one) turns left at every
    vertex, has its centroid at the origin and its farthest vertex at R, yet winds twice around
    its centre: it is no convex polygon. The pentagon itself, same vertices in order, is."""
    pentagon = regular_vertices(R5, 5)
    assert shape_problems([R5], [5], pentagon[None]) == []
    problems = shape_problems([R5], [5], pentagon[[0, 2, 4, 1, 3]][None])
    assert problems == ["vertices: 1 polygon(s) not convex with counter-clockwise vertices, first particle 0"]


# --- through the writer, make_dataset, validate and info ---------------------------------------

def irregular_sample():
    """Four particles in a 20 x 10 m box: the centred 3-4-5 triangle at (3, 3) turned by 0.4 rad,
    the rectangle at (9, 4) turned by -1.1 rad, the regular pentagon of radius 1.5 at (14, 5)
    turned by 0.2 rad, a disk of radius 0.5 at (18, 8); two snapshots, one contact."""
    radius, n = np.array([math.sqrt(73) / 3, math.hypot(A, B), R5, 0.5]), np.array([3, 4, 5, 0])
    v = padded(TRIANGLE - TRIANGLE_CENTROID, RECTANGLE, regular_vertices(R5, 5), None)
    position = np.array([[3.0, 3.0], [9.0, 4.0], [14.0, 5.0], [18.0, 8.0]])
    angle = np.array([0.4, -1.1, 0.2, 0.0])
    contacts = dict(i=[0], j=[1], kind=[1], normal=[[1.0, 0.0]], fn=[2.0], ft=[0.5], point=[[6.0, 3.5]],
                    branch=[[6.0, 1.0]])
    return radius, n, v, position, angle, contacts


AREA = 6.0 + 4 * A * B + 2.5 * R5 ** 2 * math.sin(0.4 * math.pi) + math.pi * 0.25  # the four shapes, by hand
BOX = 20.0 * 10.0


def write_irregular(path, vertices=True):
    radius, n, v, position, angle, contacts = irregular_sample()
    mass = 1000 * particle_area(radius, n, v)
    inertia = mass * inertia_per_mass(radius, n, v)
    with SnapshotWriter.create(path, radius=radius, n_vertices=n, mass=mass, inertia=inertia,
                               vertices=v if vertices else None) as writer:
        for k in range(2):
            writer.append(time=float(k), position=position + 0.1 * k, angle=angle + 0.05 * k, contacts=contacts,
                          box_min=[0.0, 0.0], box_max=[20.0, 10.0])
    return v


def test_the_writer_round_trips_irregular_polygons_and_info_says_so(tmp_path):
    path = tmp_path / "irregular.nc"
    v = write_irregular(path)
    with grainview.open_dataset(path) as ds:
        np.testing.assert_array_equal(ds["vertices"].values, v)  # NaN padding included
        assert ds["vertices"].attrs["units"] == "m"
        validate(ds)  # the NaN padding is not a non-finite value
        np.testing.assert_allclose(ds.grain.solid_fraction().values, AREA / BOX, rtol=1e-14)
        np.testing.assert_array_equal(body_vertices_of(ds), v)
        np.testing.assert_allclose(particle_area_of(ds), [6.0, 8.0, 2.5 * R5 ** 2 * math.sin(0.4 * math.pi),
                                                          math.pi * 0.25], rtol=1e-14)
    facts, _ = read_facts(path)
    np.testing.assert_allclose(facts["solid_fraction"], AREA / BOX, rtol=1e-14)
    lines, _ = describe_file(path)
    assert lines[0] == ("4 particles (1 disks, 1 5-gons, 2 irregular convex polygons with 3-4 vertices), "
                        "0 walls, 6 contact slots")
    assert main(["info", str(path), "--check"]) == 0


def test_the_writer_refuses_bad_vertices_and_leaves_nothing(tmp_path):
    radius, n, v, *_ = irregular_sample()
    v[1, :4] = v[1, 3::-1]  # the rectangle clockwise
    with pytest.raises(ParameterError, match="not convex with counter-clockwise vertices, first particle 1"):
        SnapshotWriter.create(tmp_path / "bad.nc", radius=radius, n_vertices=n, mass=np.ones(4), inertia=np.ones(4),
                              vertices=v)
    assert list(tmp_path.iterdir()) == []


def test_make_dataset_round_trips_irregular_polygons():
    """Default masses density x shoelace area, inertia mass x I/m of the vertices."""
    radius, n, v, position, angle, contacts = irregular_sample()
    ds = make_dataset(radius=radius, n_vertices=n, position=position, angle=angle, contacts=[contacts],
                      box_min=[0.0, 0.0], box_max=[20.0, 10.0], vertices=v, density=2.0)
    np.testing.assert_array_equal(ds["vertices"].values, v)
    np.testing.assert_allclose(ds["mass"].values, 2.0 * np.array([6.0, 8.0, 2.5 * R5 ** 2 * math.sin(0.4 * math.pi),
                                                                  math.pi * 0.25]), rtol=1e-14)
    polar = [50 / 36, (A ** 2 + B ** 2) / 3, R5 ** 2 * (2 + math.cos(0.4 * math.pi)) / 6, 0.125]
    np.testing.assert_allclose(ds["inertia"].values / ds["mass"].values, polar, rtol=1e-14)
    validate(ds)
    np.testing.assert_allclose(ds.grain.solid_fraction().values, AREA / BOX, rtol=1e-14)
    v[0, :3] = TRIANGLE  # off centre
    with pytest.raises(ParameterError, match="centroid is not at the origin"):
        make_dataset(radius=radius, n_vertices=n, position=position, contacts=[contacts], box_min=[0.0, 0.0],
                     box_max=[20.0, 10.0], vertices=v)


def test_validate_and_info_name_a_damaged_vertex_list(tmp_path, capsys):
    """A file whose rectangle was made concave after it was written: validate, info and
    info --check each name it in one line."""
    path = tmp_path / "damaged.nc"
    write_irregular(path)
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["vertices"][1, 3] = [0.0, -0.5 * B]
    expected = "vertices: 1 polygon(s) not convex with counter-clockwise vertices, first particle 1"
    with grainview.open_dataset(path, validate=False) as ds, pytest.raises(SchemaError) as info:
        validate(ds)
    assert info.value.problems == [expected]
    with pytest.raises(SchemaError, match="not convex"):
        read_facts(path)
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1
    assert main(["info", str(path), "--check"]) == 2
    assert capsys.readouterr().err.count("not convex") == 1  # once, though both checks find it


def test_a_file_without_vertices_holds_regular_polygons(tmp_path):
    """The layout of every file written before ``vertices`` existed: the same sample without
    them opens, validates and is summed as regular polygons (closed-form areas)."""
    path = tmp_path / "old.nc"
    write_irregular(path, vertices=False)
    with netCDF4.Dataset(path) as nc:
        assert "vertices" not in nc.variables and "vertex" not in nc.dimensions
    with grainview.open_dataset(path) as ds:
        validate(ds)
        radius, n = ds["radius"].values, ds["n_vertices"].values
        np.testing.assert_array_equal(body_vertices_of(ds), body_vertices(radius, n))
        regular = 0.5 * n[:3] * radius[:3] ** 2 * np.sin(2 * np.pi / n[:3])
        hand = (regular.sum() + np.pi * 0.25) / BOX
        np.testing.assert_allclose(ds.grain.solid_fraction().values, hand, rtol=1e-14)
    lines, _ = describe_file(path)
    assert lines[0].startswith("4 particles (1 disks, 1 3-gons, 1 4-gons, 1 5-gons), ")
    assert main(["info", str(path), "--check"]) == 0


# --- maps and VTK export of irregular polygons ---------------------------------------------------

def _hand_world(k=1):
    """World vertices of the irregular sample's snapshot k, by the rotation written out."""
    radius, n, v, position, angle, _ = irregular_sample()
    out = []
    for p in range(3):
        c, s = math.cos(angle[p] + 0.05 * k), math.sin(angle[p] + 0.05 * k)
        own = v[p, :n[p]]
        out.append(position[p] + 0.1 * k + np.column_stack([c * own[:, 0] - s * own[:, 1],
                                                            s * own[:, 0] + c * own[:, 1]]))
    return out


def test_maps_draw_each_polygon_at_its_own_vertices(tmp_path):
    path = tmp_path / "irregular.nc"
    write_irregular(path)
    with grainview.open_dataset(path) as ds:
        ax = gp.plot_particles(ds, time=1)
    polys = [c for c in ax.collections if isinstance(c, PolyCollection)]
    drawn = [path.vertices for collection in polys for path in collection.get_paths()]
    assert len(drawn) == 3
    for outline, want in zip(drawn, _hand_world()):
        np.testing.assert_allclose(outline[:len(want)], want, rtol=0, atol=1e-12)


def test_vtk_export_writes_the_true_polygons(tmp_path):
    path = tmp_path / "irregular.nc"
    write_irregular(path)
    with grainview.open_dataset(path) as ds:
        write_vtk(ds, tmp_path / "vtk")
    _, piece, arrays = read_vtp(tmp_path / "vtk" / "polygons_00001.vtp")
    assert piece == {"NumberOfPoints": str(3 + 4 + 5), "NumberOfPolys": "3"}
    sizes = np.diff(arrays["Polys"]["offsets"], prepend=0)
    np.testing.assert_array_equal(arrays["CellData"]["id"], [0, 1, 2])
    np.testing.assert_array_equal(sizes, [3, 4, 5])
    points = np.split(arrays["Points"]["Points"][arrays["Polys"]["connectivity"]], np.cumsum(sizes)[:-1])
    for outline, want in zip(points, _hand_world()):
        np.testing.assert_allclose(outline[:, :2], want, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(outline[:, 2], 0.0)


def test_only_regular_pentagons_are_the_papers_pentagons():
    """Five vertices are not enough: a sample of irregular pentagons (the regular one with a
    vertex pulled out, re-centred) is neither the paper's pentagons in the report's table nor
    in the palette, and its report row and captions say what it is."""
    from grainview.plot._style import shape_key
    from grainview.app.report import caption, describe_run, paper_sample
    from grainview.analysis.sample import shape_name

    kite = regular_vertices(1.0, 5)
    kite[0, 0] = 2.0
    kite -= polygon_properties(kite[None])["centroid"][0]
    grid = np.array([[3.0 * x, 3.0 * y] for x in range(2) for y in range(2)])
    common = dict(position=grid, contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)), fn=[])],
                  box_min=[-2.0, -2.0], box_max=[6.0, 6.0])
    regular = make_dataset(radius=np.ones(4), n_vertices=np.full(4, 5), **common)
    irregular = make_dataset(radius=np.full(4, np.hypot(*kite.T).max()), n_vertices=np.full(4, 5),
                             vertices=np.repeat(kite[None], 4, 0), **common)
    disks = make_dataset(radius=np.ones(4), **common)
    mixed = make_dataset(radius=np.ones(4), n_vertices=[0, 5, 5, 0], **common)
    assert [shape_name(ds) for ds in (regular, irregular, disks, mixed)] == [
        "5-gon", "irregular polygon", "disk", "mixed"]
    assert shape_name(make_dataset(radius=np.ones(4), n_vertices=[5, 6, 5, 6], **common)) == "mixed"
    assert [paper_sample(ds) for ds in (regular, irregular, disks, mixed)] == ["pentagons", None, "disks", None]
    assert [shape_key(ds=ds) for ds in (regular, irregular, disks, mixed)] == ["pentagons", None, "disks", None]
    window = xr.DataArray(np.zeros(1, bool), dims="time")
    assert describe_run(irregular, window, 0.3)["particles"] == "4 irregular convex polygons with 5 vertices"
    assert describe_run(regular, window, 0.3)["particles"] == "4 5-gons"
    assert caption("mixed", mixed, "map").startswith("mixed: 2 disks, 2 5-gons, seed ?")


def test_vertices_of_disks_only_are_not_written(tmp_path):
    """body_vertices of a sample of disks is (P, 0, 2): a vertex dimension of size 0 would be
    netCDF's unlimited one, a second beside time; the writer and make_dataset leave it out
    (nothing to store), and the file opens and validates as disks."""
    radius, n = [1.0, 1.0], [0, 0]
    empty = body_vertices(radius, n)
    assert empty.shape == (2, 0, 2)
    contacts = dict(i=[], j=[], kind=[], normal=np.zeros((0, 2)), fn=[], ft=[], point=np.zeros((0, 2)),
                    branch=np.zeros((0, 2)))
    path = tmp_path / "disks.nc"
    with SnapshotWriter.create(path, radius=radius, n_vertices=n, mass=[1.0, 1.0], inertia=[0.5, 0.5],
                               vertices=empty) as writer:
        writer.append(time=0.0, position=[[0.0, 0.0], [3.0, 0.0]], angle=[0.0, 0.0], contacts=contacts,
                      box_min=[-2.0, -2.0], box_max=[5.0, 2.0])
    with grainview.open_dataset(path, validate=True) as ds:
        assert "vertices" not in ds.variables
    ds = make_dataset(radius=radius, n_vertices=n, position=[[0.0, 0.0], [3.0, 0.0]], contacts=[contacts],
                      box_min=[-2.0, -2.0], box_max=[5.0, 2.0], vertices=empty)
    assert "vertices" not in ds.variables
    ds.to_netcdf(tmp_path / "made.nc", **grainview.contract.dataset.netcdf_options(ds))


def test_vtk_itself_reads_the_irregular_polygons(tmp_path):
    """VTK's own reader (the optional clients extra): three polygon cells whose points are the
    hand-rotated vertices, and each cell's area (vtkCellSizeFilter) its shoelace area."""
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    path = tmp_path / "irregular.nc"
    write_irregular(path)
    with grainview.open_dataset(path) as ds:
        write_vtk(ds, tmp_path / "vtk")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "vtk" / "polygons_00001.vtp"))
    reader.Update()
    polygons = reader.GetOutput()
    assert (polygons.GetNumberOfPolys(), polygons.GetNumberOfPoints()) == (3, 12)
    points = vtk_to_numpy(polygons.GetPoints().GetData())
    ids = vtk.vtkIdList()
    cells = polygons.GetPolys()
    cells.InitTraversal()
    for want in _hand_world():
        assert cells.GetNextCell(ids)
        outline = points[[ids.GetId(m) for m in range(ids.GetNumberOfIds())]]
        np.testing.assert_allclose(outline[:, :2], want, rtol=0, atol=1e-12)
    quality = vtk.vtkCellSizeFilter()
    quality.SetInputData(polygons)
    quality.Update()
    area = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Area"))
    np.testing.assert_allclose(area, [6.0, 4 * A * B, 2.5 * R5 ** 2 * math.sin(0.4 * math.pi)], rtol=1e-12)


def test_a_file_of_irregular_polygons_is_version_2_and_older_readers_refuse_it(tmp_path, monkeypatch):
    """Version 2.0 is written only where the vertices change what a file means: an older
    grainview (major version 1) reads a polygon as the regular one of its radius and count, so
    it must refuse a file of irregular polygons, and may open one of regular polygons or disks."""
    import grainview.contract.file_checks as file_checks
    from grainview.contract.reader import ContractFile

    write_irregular(tmp_path / "irregular.nc")
    radius, n, v, position, angle, contacts = irregular_sample()
    regular = body_vertices(radius, n)  # the same particles, every polygon regular
    with SnapshotWriter.create(tmp_path / "regular.nc", radius=radius, n_vertices=n, mass=np.ones(4),
                               inertia=np.ones(4), vertices=regular) as writer:
        writer.append(time=0.0, position=position, angle=angle, contacts=contacts, box_min=[0.0, 0.0],
                      box_max=[20.0, 10.0])
    versions = {}
    for name in ("irregular", "regular"):
        with netCDF4.Dataset(tmp_path / f"{name}.nc") as nc:
            versions[name] = nc.grainview_schema_version
    assert versions == {"irregular": "2.0", "regular": "1.0"}
    assert make_dataset(radius=radius, n_vertices=n, vertices=v, position=position, contacts=[contacts],
                        box_min=[0.0, 0.0], box_max=[20.0, 10.0]).attrs["grainview_schema_version"] == "2.0"
    monkeypatch.setattr(file_checks, "SCHEMA_VERSION", "1.0")  # a grainview from before the vertices
    with pytest.raises(SchemaError, match="schema version 2.0, newer than this grainview understands"):
        grainview.open_dataset(tmp_path / "irregular.nc")
    with pytest.raises(SchemaError, match="newer than this grainview understands"):
        ContractFile(tmp_path / "irregular.nc")
    with grainview.open_dataset(tmp_path / "regular.nc") as ds:
        assert ds.sizes["particle"] == 4
