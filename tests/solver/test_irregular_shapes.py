"""Any convex polygon in the solver: the shape table from the contract's geometry, the family of
random convex polygons and files of vertex lists, a sample of them simulated, written, checked
and resumed bit for bit, and regular samples unchanged."""

import json
import warnings

import numpy as np
import pytest

import grainview
from grainview.app.cli import main
from grainview.contract import shapes as contract
from grainview.contract.errors import ConvergenceWarning, ParameterError
from grainview.contract.reader import ContractFile
from solver import Parameters, Simulation, Walls, biaxial_test, compaction_sample, isotropic_compaction
from solver.output import Recorder
from solver.restart import load_sample, load_state, resume
from solver.shape_families import (IRREGULAR, check_shape, random_convex_polygons, read_polygons, sample_shapes,
                                   shape_label)
from solver.preparation import preparation, prepare_sample
from solver.shapes import MAX_SLENDERNESS, Shapes, polygon_problem

from .conftest import EXACT, G

TABLES = ("radius", "n_vertices", "first_vertex", "vertex_radius", "vertex_angle", "normal_angle", "inradius", "area",
          "inertia_per_mass")


def _same_tables(a: Shapes, b: Shapes):
    for name in TABLES:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


# --- the geometry ----------------------------------------------------------------------------

def test_contract_inradius_closed_form_and_from_vertices():
    # regular n-gon: R cos(pi/n); disk: R; a 2 x 1 rectangle given by its vertices: 1/2
    radius, n = np.array([2.0, 2.0, 1.0]), np.array([4, 6, 0])
    np.testing.assert_allclose(contract.particle_inradius(radius, n), [np.sqrt(2.0), np.sqrt(3.0), 1.0], rtol=1e-15)
    np.testing.assert_allclose(contract.particle_inradius(radius, n, contract.body_vertices(radius, n)),
                               [np.sqrt(2.0), np.sqrt(3.0), 1.0], rtol=1e-14)
    rectangle = np.array([[[1.0, -0.5], [1.0, 0.5], [-1.0, 0.5], [-1.0, -0.5]]])
    assert contract.particle_inradius([np.sqrt(1.25)], [4], rectangle)[0] == pytest.approx(0.5, rel=1e-15)


def test_regular_tables_are_the_closed_forms_bit_for_bit():
    """The regular path's tables, now computed by the contract's functions, are the closed forms
    the solver always used, bit for bit (so regular trajectories are unchanged)."""
    rng = np.random.default_rng(7)
    radius = rng.uniform(0.01, 0.03, 12)
    n = np.array([5, 0, 3, 5, 6, 0, 4, 5, 3, 64, 7, 5], np.int32)
    table = Shapes.regular(radius, n)
    safe = np.where(n >= 3, n, 3).astype(np.float64)
    np.testing.assert_array_equal(table.area, np.where(n >= 3, 0.5 * safe * radius ** 2 * np.sin(2 * np.pi / safe),
                                                       np.pi * radius ** 2))
    np.testing.assert_array_equal(table.inertia_per_mass,
                                  np.where(n >= 3, radius ** 2 * (2.0 + np.cos(2.0 * np.pi / safe)) / 6.0,
                                           0.5 * radius ** 2))
    np.testing.assert_array_equal(table.inradius, np.where(n >= 3, radius * np.cos(np.pi / safe), radius))
    phase = np.concatenate([2.0 * np.pi * np.arange(k) / k for k in n if k])
    normal = np.concatenate([np.pi * (2 * np.arange(k) + 1) / k for k in n if k])
    np.testing.assert_array_equal(table.vertex_angle, phase)
    np.testing.assert_array_equal(table.normal_angle, normal)
    np.testing.assert_array_equal(table.vertex_radius, np.repeat(radius, n))
    assert table.vertex_xy is None
    # what a file stores for them reads back as the same regular table
    again = Shapes.of(radius, n, table.body_vertices())
    assert again.vertex_xy is None
    _same_tables(again, table)


def test_a_right_triangle_against_a_hand_computation():
    # legs a (x) and b (y): area ab/2, centroid (a/3, b/3), I/m about it (a^2 + b^2)/18,
    # circumradius: the farthest vertex from the centroid, (2a/3, -b/3) for a > b
    a, b = 0.04, 0.03
    local = np.array([[0.0, 0.0], [a, 0.0], [0.0, b]]) - [a / 3, b / 3]
    table = Shapes.convex([local])
    assert table.area[0] == pytest.approx(a * b / 2, rel=1e-14)
    assert table.inertia_per_mass[0] == pytest.approx((a ** 2 + b ** 2) / 18, rel=1e-13)
    assert table.radius[0] == pytest.approx(np.hypot(2 * a / 3, b / 3), rel=1e-15)
    # distances from the centroid to the legs b/3, a/3 and to the hypotenuse ab / (3 sqrt(a^2 + b^2))
    assert table.inradius[0] == pytest.approx(a * b / (3 * np.hypot(a, b)), rel=1e-13)
    mass, inertia = table.mass_and_inertia(2000.0, thickness=0.1)
    assert mass[0] == pytest.approx(2000.0 * 0.1 * a * b / 2, rel=1e-14)
    assert inertia[0] == pytest.approx(mass[0] * (a ** 2 + b ** 2) / 18, rel=1e-13)
    np.testing.assert_array_equal(table.body_vertices()[0], local)  # kept exactly as given


def test_a_rectangle_from_a_file_scaled_to_a_particle(tmp_path):
    """A file's 3 x 1 rectangle scaled to a circumscribed radius R: its half-diagonal is R, so
    its sides are a = 6R/sqrt(10), b = 2R/sqrt(10), its area a b and I/m = (a^2 + b^2)/12 =
    (2R)^2/12 = R^2/3."""
    shapes, angle = sample_shapes(_write(tmp_path, [[[0, 0], [3, 0], [3, 1], [0, 1]]]), [0.02, 0.01], seed=4)
    a, b = 2 * 0.02 * 3 / np.sqrt(10), 2 * 0.02 / np.sqrt(10)
    assert shapes.n_vertices.tolist() == [4, 4]
    np.testing.assert_allclose(shapes.radius, [0.02, 0.01], rtol=1e-15)
    np.testing.assert_allclose(shapes.inertia_per_mass, np.array([0.02, 0.01]) ** 2 / 3, rtol=1e-14)
    assert shapes.area[0] == pytest.approx(a * b, rel=1e-14)
    assert angle.shape == (2,) and np.all((0 <= angle) & (angle < 2 * np.pi)) and angle[0] != angle[1]


@pytest.mark.parametrize("vertices, words", [
    ([[0, 0], [1, 0]], "2 vertices, expected at least 3"),
    ([[0, 0], [0, 1], [1, 0]], "clockwise"),
    ([[0, 0], [2, 0], [1, 0.2], [1, 2]], "not convex"),
    ([[0, 0], [1, 0], [2, 0], [1, 1]], "not convex"),  # a straight corner
    ([[0, 0], [1, 0], [1, 0], [0, 1]], "equal"),
    ([[np.cos(a), np.sin(a)] for a in 4 * np.pi * np.arange(5) / 5], "not convex"),  # a pentagram turns left
    ([[0, 0], [np.nan, 0], [0, 1]], "not finite"),
])
def test_polygon_problems_are_named(vertices, words):
    assert words in polygon_problem(vertices)
    with pytest.raises(ParameterError, match=words):
        Shapes.convex([vertices])


def _rectangle(aspect):
    """A rectangle ``aspect`` x 1 about its centroid: R/r = hypot(aspect, 1) (r = 1/2)."""
    a = aspect / 2
    return [[-a, -0.5], [a, -0.5], [a, 0.5], [-a, 0.5]]


def test_slender_polygons_are_refused_beyond_the_limit():
    # rectangle a x 1: R = hypot(a, 1)/2 and r = 1/2 about the centroid, so R/r = hypot(a, 1);
    # isosceles triangle of base b and height 1: r = 1/3 (to the base), R = hypot(b/2, 1/3)
    fine = np.sqrt(MAX_SLENDERNESS ** 2 - 1) * (1 - 1e-9)
    assert polygon_problem(_rectangle(fine)) is None
    too = np.sqrt(MAX_SLENDERNESS ** 2 - 1) * (1 + 1e-9)
    assert "too slender" in polygon_problem(_rectangle(too))
    assert f"{np.hypot(50, 1):.3g} times its inradius" in polygon_problem(_rectangle(50))
    sliver = [[-25, 0], [25, 0], [0, 1]]  # the review's 50:1 sliver: R/r = 3 hypot(25, 1/3) = 75
    assert "is 75 times its inradius" in polygon_problem(sliver) and "expected at most 10 " in polygon_problem(sliver)
    with pytest.raises(ParameterError, match="polygon 1: too slender"):
        Shapes.convex([0.01, np.array(sliver) - [0, 1 / 3]])


@pytest.mark.parametrize("vertices", [
    [[0, 0], [1, 0], [1, 1], [0, 1]],
    [[0, 0], [2, 0], [1, 0.2], [1, 2]],
    [[0, 0], [1, 0], [2, 0], [1, 1]],
    [[np.cos(a), np.sin(a)] for a in 4 * np.pi * np.arange(5) / 5],
    [[0, 0], [4, 0], [4.5, 0.5], [4, 1], [0, 1]],
    [[0, 0], [4, 0], [3.5, 0.5], [4, 1], [0, 1]],
])
def test_the_solver_and_the_contract_agree_on_convexity(vertices):
    v = np.array(vertices, float)
    v = v - contract.polygon_properties(v[None])["centroid"][0]
    radius = contract.polygon_properties(v[None])["radius"]
    assert (polygon_problem(v) is None) == (contract.shape_problems(radius, [len(v)], v[None]) == [])


def test_a_too_slender_file_is_refused_before_anything_runs(tmp_path):
    path = _write(tmp_path, [_rectangle(20)])
    with pytest.raises(ParameterError, match=r"shapes.json: polygon 0: too slender: .* 20 times its inradius"):
        prepare_sample(preparation("fast", shape=path, particles=10))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shapes.json"]


def test_a_slender_but_accepted_rectangle_compacts_without_crossing(tmp_path):
    # 9 x 1 rectangles (R/r = 9.06): the compaction keeps every grain inside the box and every
    # interpenetration far below the inradius
    shape = _write(tmp_path, [_rectangle(9)])
    with warnings.catch_warnings():
        # slender grains jammed by the fast route: some steps end at the sweep cap, one warning
        # each, how many depending on the trajectory; this test checks the geometry, and the
        # warning itself is tested in test_unconverged_counts and test_physics
        warnings.simplefilter("ignore", ConvergenceWarning)
        sim = prepare_sample(preparation("fast", shape=shape, particles=12, max_steps=1500))
    assert sim.compaction_steps > 0
    n, points = sim.n_particles, sim.detect()
    inner = sim.shapes.inradius
    np.testing.assert_allclose(sim.radius / inner, np.hypot(9, 1), rtol=1e-12)
    depth = -points.gap / inner[points.body_i]
    assert depth.max() < 0.01
    low, high = sim.walls.point.min(0), sim.walls.point.max(0)
    assert np.all((sim.position > low) & (sim.position < high))


def test_the_irregular_family_is_convex_centred_unit_and_seeded():
    polygons = random_convex_polygons(200, np.random.default_rng(3))
    counts = np.array([len(v) for v in polygons])
    assert counts.min() >= 3 and counts.max() <= IRREGULAR.max_vertices and len(set(counts)) >= 4
    assert (counts >= IRREGULAR.min_vertices).mean() > 0.9  # the hull rarely drops a vertex
    for v in polygons:
        assert polygon_problem(v) is None
    width = max(counts)
    padded = np.array([np.vstack([v, np.full((width - len(v), 2), np.nan)]) for v in polygons])
    assert contract.shape_problems(np.ones(200), counts, padded) == []  # centroid 0, farthest vertex 1
    props = contract.polygon_properties(padded)
    inner = props["inradius"]
    assert inner.min() > 0.3 and np.ptp(inner) > 0.2  # not slivers, and not all alike
    assert np.abs(props["centroid"]).max() < 1e-15
    again = random_convex_polygons(200, np.random.default_rng(3))
    assert all(np.array_equal(u, v) for u, v in zip(polygons, again))


def _write(folder, polygons, name="shapes.json"):
    path = folder / name
    path.write_text(json.dumps({"polygons": polygons}))
    return str(path)


@pytest.mark.parametrize("content, words", [
    ({"polygons": [[[0, 0], [0, 1], [1, 0]]]}, "polygon 0: the vertices run clockwise"),
    ({"polygons": [[[0, 0], [1, 0], [0, 1]], [[0, 0], [1, 0]]]}, "polygon 1: 2 vertices, expected at least 3"),
    ({"polygons": [[[0, 0], [2, 0], [1, 0.2], [1, 2]]]}, "polygon 0: not convex"),
    # 2 m wide, 1e-12 m high: R/r = 3e12 (the walls ran through such grains to an 8e12 m box)
    ({"polygons": [[[0, 0], [1, 0], [0, 1]], [[-1, 0], [1, 0], [0, 1e-12]]]}, "polygon 1: too slender"),
    ({"polygons": [[[0, 0], ["a", 0], [1, 1]]]}, "polygon 0 is not a list of [x, y] pairs"),
    ({"polygons": []}, "no list of polygons"),
    ({"shapes": 1}, "no list of polygons"),
    ("not json", "cannot read it"),
])
def test_bad_shape_files_are_one_line(tmp_path, capsys, content, words):
    path = tmp_path / "shapes.json"
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    with pytest.raises(ParameterError) as caught:
        read_polygons(path)
    assert words in str(caught.value) and str(path) in str(caught.value)
    out = tmp_path / "run.nc"
    assert main(["run", "--shape", str(path), "--particles", "10", "--out", str(out), "--progress", "off"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err and err.startswith("grainview: error: --shape")
    assert not out.exists()


def test_shape_names_files_and_labels(tmp_path):
    assert check_shape("irregular") == "irregular" and check_shape(5) == 5
    with pytest.raises(ParameterError, match="'hexagram': expected 'disk', 'pentagon'.*irregular.*json"):
        check_shape("hexagram")
    with pytest.raises(ParameterError, match="no such file"):
        check_shape(str(tmp_path / "missing.json"))
    assert shape_label(str(tmp_path / "grains.json")) == "grains" and shape_label("irregular") == "irregular"
    from grainview.app.ensemble import RunSpec

    path = _write(tmp_path, [[[0, 0], [1, 0], [0, 1]]], "triangles.json")
    assert RunSpec(shape=path, particles=40, strain=0.01).validate().name == "triangles_n40_s0"


# --- statics ---------------------------------------------------------------------------------

def test_a_triangle_resting_on_its_leg_splits_its_weight_by_the_lever_rule():
    """A right triangle (legs a along the floor, b up) under gravity: the floor carries its
    weight m g, at its two bottom corners; moments about the centroid (a/3 from the right
    angle) give 2/3 of it at the right angle and 1/3 at the other corner."""
    a, b = 0.04, 0.02
    local = np.array([[0.0, 0.0], [a, 0.0], [0.0, b]]) - [a / 3, b / 3]
    sim = Simulation([[0.1, b / 3]], [0.0], walls=Walls.floor(), shapes=Shapes.convex([local]),
                     parameters=Parameters(gravity=(0, -G), **EXACT))
    for _ in range(10):
        sim.step()
    weight = sim.mass[0] * G
    assert sim.mass[0] == pytest.approx(2600.0 * a * b / 2, rel=1e-14)
    force = sim.impulse[:, 0] / sim.parameters.time_step
    x = sim.points.point[:, 0]
    assert len(force) == 2 and np.all(sim.points.kind == 2)
    np.testing.assert_allclose(sorted(x), [0.1 - a / 3, 0.1 + 2 * a / 3], atol=1e-12)
    np.testing.assert_allclose(force[np.argsort(x)], [2 * weight / 3, weight / 3], rtol=1e-6)
    np.testing.assert_allclose(sim.wall_forces()[0], [0.0, -weight], rtol=1e-6)
    assert np.abs(sim.velocity[0]).max() < 1e-12 and abs(sim.angular_velocity[0]) < 1e-10


# --- a sample of random convex polygons, end to end ------------------------------------------

RUN = dict(n=30, seed=4, compaction_steps=1500, strain=0.0006, every=2)  # compaction settles in about 950 steps


def _irregular_run(path, stop_after=None):
    """The irregular sample deposited, compacted a little and sheared into ``path``; with
    ``stop_after``, stopped (as Ctrl-C would) right after that many snapshots."""
    sim = compaction_sample(RUN["n"], "irregular", seed=RUN["seed"], max_wall_speed=0.2)
    written = []
    write = Recorder.write

    def write_and_stop(recorder):
        write(recorder)
        written.append(1)
        if stop_after is not None and len(written) == stop_after:
            raise KeyboardInterrupt

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=RUN["compaction_steps"], progress=False)
        assert sim.settled
        Recorder.write = write_and_stop
        try:
            biaxial_test(sim, path, strain=RUN["strain"], every=RUN["every"], progress=False)
        except KeyboardInterrupt:
            pass
        finally:
            Recorder.write = write
    return sim


@pytest.fixture(scope="module")
def irregular_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("irregular") / "irregular.nc"
    return path, _irregular_run(path)


def test_irregular_deposit_overlaps_nothing():
    """The deposit places the circumscribed disks: however each polygon is turned, no two
    polygons (nor a polygon and a wall) overlap."""
    sim = compaction_sample(60, "irregular", seed=9)
    assert not np.all(sim.shapes.n_vertices == sim.shapes.n_vertices[0])  # irregular: counts differ
    sim.step_alert = 0.5 * float(sim.radius.min())
    points = sim.detect()
    assert len(points.gap) > 0 and points.gap.min() > 0.0
    lo, hi = sim.walls.box_bounds()
    world = sim.shapes.world_vertices(sim.position, sim.angle)
    assert np.nanmin(world[..., 0]) > lo[0] and np.nanmax(world[..., 0]) < hi[0] and np.nanmin(world[..., 1]) > lo[1]
    # positions and sizes are the regular deposit's (same seed); only shapes and angles differ
    pentagons = compaction_sample(60, "pentagon", seed=9)
    np.testing.assert_array_equal(sim.position, pentagons.position)
    np.testing.assert_allclose(sim.radius, pentagons.radius, rtol=1e-15)


def test_irregular_sample_is_written_and_validates(irregular_run, capsys):
    path, sim = irregular_run
    with grainview.open_dataset(path, validate=True, chunks=None) as ds:
        np.testing.assert_array_equal(ds.vertices.values, sim.shapes.body_vertices())
        np.testing.assert_array_equal(ds.n_vertices.values, sim.shapes.n_vertices)
        np.testing.assert_array_equal(ds.mass.values, sim.mass)
        assert ds.sizes["time"] == 1 + int(np.ceil(ds.attrs["biaxial_steps"] / RUN["every"]))
        # a packing of polygons: edge-to-edge (double) contacts and a contact network, whatever the
        # trajectory (tolerances from 14 seeds of this run: docs/reproducibility.md)
        assert int((ds.kind.values[-1] == 2).sum()) >= 5 and int(ds.contact_count[-1]) >= 0.7 * RUN["n"]
        # the contacts' stress holds the confining stress the right wall keeps
        sigma_xx = ds.grain.stress_tensor().sel(xy_a="x", xy_b="x").values
        np.testing.assert_allclose(sigma_xx, 1e4, rtol=0.2)
        assert float(ds.max_interpenetration.max()) < 2e-2 * 2 * sim.radius.min()
    assert main(["info", str(path), "--check"]) == 0
    assert "valid: every value checked" in capsys.readouterr().out


def test_irregular_sample_resumes_bit_for_bit(irregular_run, tmp_path):
    path, sim = irregular_run
    restored, test = load_state(path)
    assert restored.shapes.vertex_xy is not None  # rebuilt as convex polygons from the file's vertices
    _same_tables(restored.shapes, sim.shapes)
    np.testing.assert_array_equal(restored.mass, sim.mass)
    np.testing.assert_array_equal(restored.inertia, sim.inertia)
    stopped = tmp_path / "stopped.nc"
    _irregular_run(stopped, stop_after=4)
    with grainview.open_dataset(stopped, chunks=None) as ds:
        assert ds.sizes["time"] == 4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert resume(stopped, progress=False) == test["n_steps"] - 2 * 3
    assert stopped.read_bytes() == path.read_bytes()


def test_regular_samples_write_their_vertices_and_read_back_regular(tmp_path):
    sim = compaction_sample(12, "pentagon", seed=1)
    path = tmp_path / "pentagons.nc"
    with Recorder(path, sim, attrs={"scene": "isotropic"}) as recorder:
        recorder.write()
    with ContractFile(path) as ds:
        vertices = ds.static("vertices")
    np.testing.assert_array_equal(vertices, contract.body_vertices(sim.radius, np.full(12, 5)))
    loaded = load_sample(path)
    assert loaded.shapes.vertex_xy is None
    _same_tables(loaded.shapes, sim.shapes)
    disks = compaction_sample(12, "disk", seed=1)
    with Recorder(tmp_path / "disks.nc", disks, attrs={"scene": "isotropic"}) as recorder:
        recorder.write()
    with ContractFile(tmp_path / "disks.nc") as ds:
        assert "vertices" not in ds.variables


def test_a_file_of_disks_and_irregular_polygons_reads_back_as_both():
    """Shapes.of on a file's layout mixing a disk and a triangle: the disk's radius, area and
    I/m (pi r^2, r^2/2) and the triangle's from its vertices (legs a, b: ab/2, (a^2 + b^2)/18)."""
    a, b = 0.03, 0.02
    triangle = np.array([[0.0, 0.0], [a, 0.0], [0.0, b]]) - [a / 3, b / 3]
    vertices = np.full((2, 3, 2), np.nan)
    vertices[1] = triangle
    table = Shapes.of([0.01, np.hypot(2 * a / 3, b / 3)], [0, 3], vertices)
    assert table.n_vertices.tolist() == [0, 3] and table.first_vertex.tolist() == [0, 0, 3]
    np.testing.assert_allclose(table.area, [np.pi * 1e-4, a * b / 2], rtol=1e-14)
    np.testing.assert_allclose(table.inertia_per_mass, [0.5e-4, (a ** 2 + b ** 2) / 18], rtol=1e-13)
    np.testing.assert_array_equal(table.body_vertices(), vertices)


def test_simulation_takes_shapes_or_radii_not_both():
    shapes = Shapes.convex([[[0.01, -0.005], [0.01, 0.005], [-0.01, 0.005], [-0.01, -0.005]]])
    with pytest.raises(ParameterError, match="radius and n_vertices come from shapes"):
        Simulation([[0.0, 0.1]], [0.0], [0.01], [4], Walls.floor(), shapes=shapes)
    with pytest.raises(ParameterError, match="shapes: expected a solver.shapes.Shapes of the 2 particles"):
        Simulation([[0.0, 0.1], [0.1, 0.1]], [0.0, 0.0], walls=Walls.floor(), shapes=shapes)
    sim = Simulation([[0.0, 0.1]], [0.0], walls=Walls.floor(), shapes=shapes)
    assert sim.radius[0] == pytest.approx(np.hypot(0.01, 0.005)) and sim.n_vertices.tolist() == [4]


# --- the command line ------------------------------------------------------------------------

@pytest.mark.parametrize("shape", ["irregular", "file"])
def test_run_shape_irregular_or_a_file_from_the_command_line(tmp_path, capsys, shape):
    if shape == "file":
        shape = _write(tmp_path, [[[0, 0], [2, 0], [2, 1], [0, 1]], [[0, 0], [1, 0], [0, 1]]], "bricks.json")
    out = tmp_path / "run.nc"
    assert main(["run", "isotropic", "--shape", shape, "--particles", "12", "--preparation", "fast",
                 "--out", str(out), "--progress", "off"]) == 0
    printed = capsys.readouterr().out
    assert ("bricks: wrote" if shape.endswith(".json") else "irregular: wrote") in printed
    with grainview.open_dataset(out, validate=True, chunks=None) as ds:
        counts = ds.n_vertices.values
        vertices = ds.vertices.values
        assert ds.attrs["preparation_shape"] == shape
    if shape.endswith(".json"):  # particle k takes the file's polygon k mod 2
        assert counts.tolist() == [4, 3] * 6
        props = contract.polygon_properties(vertices)
        np.testing.assert_allclose(props["inertia_per_mass"][::2], ds.radius.values[::2] ** 2 / 3, rtol=1e-13)
    else:
        assert len(set(counts.tolist())) > 1 and counts.min() >= 3
    assert main(["info", str(out), "--check"]) == 0
    assert "valid: every value checked" in capsys.readouterr().out


def test_irregular_sample_goes_through_the_report_and_the_vtk_export(irregular_run, tmp_path, capsys):
    """The solver's irregular run, end to end on the analysis side: the report draws its
    figures, and the VTK export's polygon cells are the file's vertices turned and moved
    (p + Rot(angle) v_k), each cell's shoelace area the polygon's own."""
    from tests.grainview.test_export import read_vtp

    path, sim = irregular_run
    report = tmp_path / "report"
    assert main(["report", str(path), "--out", str(report)]) == 0
    figures = sorted(p.name for p in report.rglob("*.png"))
    assert len(figures) >= 10 and "irregular convex polygons" in (report / "index.md").read_text()
    assert main(["export", str(path), "--to", "vtk", "--out", str(tmp_path / "vtk")]) == 0
    capsys.readouterr()
    with grainview.open_dataset(path, chunks=None) as ds:
        k = ds.sizes["time"] - 1
        vertices, counts = ds.vertices.values, ds.n_vertices.values
        position, angle = ds.position.values[k], ds.angle.values[k]
    _, _, arrays = read_vtp(tmp_path / "vtk" / f"polygons_{k:05d}.vtp")
    points = arrays["Points"]["Points"][:, :2]
    offsets = arrays["Polys"]["offsets"]
    assert offsets.size == counts.size and offsets[-1] == counts.sum()
    ids = arrays["CellData"]["id"]
    start = np.concatenate([[0], offsets[:-1]])
    for cell, (first, last) in enumerate(zip(start, offsets)):
        b = int(ids[cell])
        own = vertices[b, :counts[b]]
        c, s = np.cos(angle[b]), np.sin(angle[b])
        expected = position[b] + own @ np.array([[c, s], [-s, c]])
        np.testing.assert_allclose(points[first:last], expected, rtol=0, atol=1e-12)
        x, y = points[first:last].T
        area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
        assert area == pytest.approx(sim.shapes.area[b], rel=1e-10)
