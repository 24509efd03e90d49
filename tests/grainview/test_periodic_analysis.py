"""Every analysis in a periodic cell (issue 46, item 3): strains from the cell, coarse-grained
fields around the torus, force chains and cycles across the boundary, contacts that keep
their identity when they cross it, maps that draw the cell."""

from __future__ import annotations

import numpy as np
import pytest

import grainview
import grainview.analysis.coarse_graining
import grainview.analysis.strain
import grainview.export
from grainview.contract import cell as cells


def sheared_series(tilts, width=4.0, height=2.0):
    """Two disks in contact along x in a cell of l x h whose tilt is ``tilts`` at times 0, 1, ..."""
    tilts = np.asarray(tilts, float)
    t = tilts.size
    cell = cells.restricted_cell(np.zeros((t, 2)), np.tile([width, height], (t, 1)), tilts)
    position = np.tile([[0.5, 1.0], [1.5, 1.0]], (t, 1, 1))
    contacts = [dict(i=[0], j=[1], normal=[[1.0, 0.0]], fn=[1.0])] * t
    return grainview.make_dataset(radius=[0.5, 0.5], position=position, contacts=contacts,
                                  box_min=np.zeros((t, 2)), box_max=np.tile([width, height], (t, 1)),
                                  time=np.arange(t, dtype=float), periodic=[1, 1], cell=cell)


def test_strains_of_a_sheared_cell_by_hand(prepare):
    """A 4 x 2 cell sheared by 0.4 m per snapshot from a tilt of 0.2: LAMMPS flips the tilt
    back by l = 4 once it passes l/2 = 2 (at 2.2 and 2.6); gamma = (tilt - 0.2)/2 by hand."""
    stored = np.array([0.2, 0.6, 1.0, 1.4, 1.8, 2.2 - 4.0, 2.6 - 4.0])
    ds = prepare(sheared_series(stored))
    eps = ds.grain.strains().compute()
    np.testing.assert_allclose(eps["gamma"].values, (0.2 + 0.4 * np.arange(7) - 0.2) / 2.0, rtol=0, atol=1e-15)
    for name in ("eps_1", "eps_2", "eps_p", "eps_q"):  # the widths do not change: no biaxial strain
        np.testing.assert_array_equal(eps[name].values, 0.0)
    f = ds.grain.deformation_gradient().values
    assert ds.grain.deformation_gradient().attrs["units"] == "1"
    np.testing.assert_allclose(f[:, 0, 1], eps["gamma"].values, atol=1e-15)
    np.testing.assert_allclose(f[:, [0, 1, 1], [0, 0, 1]], np.tile([1.0, 0.0, 1.0], (7, 1)), atol=1e-15)


def test_deformation_gradient_maps_the_reference_cell_onto_each_cell():
    """A cell stretched along x, compressed along y and sheared at once: F a0 = a, F b0 = b."""
    t = 3
    box_max = np.array([[4.0, 2.0], [4.4, 1.8], [5.0, 1.5]])
    tilt = np.array([0.3, -0.5, 1.1])
    ds = grainview.make_dataset(radius=[0.5, 0.5], position=np.tile([[0.5, 0.7], [1.5, 0.7]], (t, 1, 1)),
                                contacts=[dict(i=[0], j=[1], normal=[[1.0, 0.0]], fn=[1.0])] * t,
                                box_min=np.zeros((t, 2)), box_max=box_max, time=np.arange(t, dtype=float),
                                periodic=[1, 1], cell=cells.restricted_cell(np.zeros((t, 2)), box_max, tilt))
    f = grainview.analysis.strain.deformation_gradient(ds, reference=0).values
    c = ds["cell"].values
    for k in range(t):
        np.testing.assert_allclose(f[k] @ c[0, 0], c[k, 0], atol=1e-14)
        np.testing.assert_allclose(f[k] @ c[0, 1], c[k, 1], atol=1e-14)
    eps = ds.grain.strains()
    np.testing.assert_allclose(eps["gamma"].values, (tilt - 0.3 * box_max[:, 0] / 4.0) / 2.0, atol=1e-15)
    np.testing.assert_allclose(eps["eps_1"].values, np.log(1 + (2.0 - box_max[:, 1]) / 2.0), atol=1e-15)


def test_deformation_gradient_without_a_cell_is_that_of_the_box():
    ds = grainview.make_dataset(radius=[0.5, 0.5], position=np.tile([[0.5, 0.7], [1.5, 0.7]], (2, 1, 1)),
                                contacts=[dict(i=[0], j=[1], normal=[[1.0, 0.0]], fn=[1.0])] * 2,
                                box_min=np.zeros((2, 2)), box_max=[[4.0, 2.0], [5.0, 1.0]], time=[0.0, 1.0])
    f = grainview.analysis.strain.deformation_gradient(ds).values
    np.testing.assert_allclose(f[1], [[1.25, 0.0], [0.0, 0.5]])
    assert "gamma" not in ds.grain.strains()


def chain_across(shift=(0.0, 0.0), tilt=0.0):
    """A straight row of 6 disks (radius 0.5) along x at y = 5 in a 10 x 10 periodic cell, three
    each side of the boundary x = 0 (centres 7.5 ... 9.5 and 0.5 ... 1.5), pushed along the row
    by 10 N; and five weakly loaded vertical pairs elsewhere (1 N). The row is one chain of 6
    particles (even its ends, loaded on one side, are above the mean sigma_1): its contact at the
    boundary is the minimum image (branch (1, 0))."""
    row = np.array([[7.5 + k, 5.0] for k in range(6)])
    pairs = np.array([[x, y + dy] for x, y in ((3.0, 1.0), (4.5, 1.0), (6.0, 1.0), (3.0, 7.0), (4.5, 7.0))
                      for dy in (0.0, 1.0)])
    centres = np.concatenate([row, pairs])
    cell = cells.restricted_cell([0, 0], [10, 10], tilt)
    position = cells.wrap(centres + np.asarray(shift), [0, 0], cell, [1, 1])
    i = [0, 1, 2, 3, 4] + list(range(6, 16, 2))
    j = [1, 2, 3, 4, 5] + list(range(7, 16, 2))
    normal = [[1.0, 0.0]] * 5 + [[0.0, 1.0]] * 5
    fn = [10.0] * 5 + [1.0] * 5
    return grainview.make_dataset(radius=np.full(16, 0.5), position=position,
                                  contacts=[dict(i=i, j=j, normal=normal, fn=fn)], box_min=[0, 0], box_max=[10, 10],
                                  periodic=[1, 1], cell=cell)


def test_a_straight_chain_across_the_boundary_is_one_chain(prepare):
    ds = chain_across()
    assert abs(ds["position"].values[0, 2, 0] - ds["position"].values[0, 3, 0]) > 8  # stored a cell apart
    chains = prepare(ds).grain.force_chains().compute()
    chain = chains["chain"].values[0]
    assert int(chains["n_chains"][0]) == 1
    np.testing.assert_array_equal(chain, [0] * 6 + [-1] * 10)
    # every row particle carries 10 N over a lever of 0.5 on each loaded side: sigma_xx = 10 / (pi/4)
    ends = 10 * 0.5 / (np.pi * 0.25)
    np.testing.assert_allclose(chains["sigma_1"].values[0, :6], [ends, 2 * ends, 2 * ends, 2 * ends, 2 * ends, ends],
                               rtol=1e-12)
    # the particle stresses add up to the sample's
    volume = np.pi * 0.25
    total = chains["sigma_1"].values[0] * volume + chains["sigma_2"].values[0] * volume
    sigma = ds.grain.stress_tensor().values[0]
    assert total.sum() == pytest.approx(np.trace(sigma) * 100, rel=1e-12)


def test_force_chains_do_not_move_with_the_sample_across_the_cell():
    rng = np.random.default_rng(5)
    for tilt in (0.0, 2.7):
        base = chain_across(tilt=tilt).grain.force_chains()
        for _ in range(3):
            moved = chain_across(shift=rng.uniform(-30, 30, 2), tilt=tilt).grain.force_chains()
            np.testing.assert_array_equal(moved["chain"].values, base["chain"].values)
            np.testing.assert_allclose(moved["sigma_1"].values, base["sigma_1"].values, rtol=1e-12)
            np.testing.assert_allclose(moved["sigma_2"].values, base["sigma_2"].values, rtol=1e-12, atol=1e-12)


def random_periodic(shift=(0.0, 0.0), tilt=0.0, seed=2, n=40, size=(6.0, 5.0), snapshots=1, reach=0.75):
    """Disks of radius 0.3 at random centres in a periodic cell, with random velocities and a
    contact (random normal and tangential forces, along the minimum image) between every pair
    whose minimum-image distance is below ``reach``: many across the boundary. ``shift`` moves the
    whole sample (wrapped back into the cell)."""
    rng = np.random.default_rng(seed)
    box_max = np.tile(size, (snapshots, 1))
    tilts = tilt + 0.05 * np.arange(snapshots)
    cell = cells.restricted_cell(np.zeros((snapshots, 2)), box_max, tilts)
    centres = cells.from_fractional(rng.uniform(0, 1, (n, 2)), cell[0])
    velocity = rng.normal(0, 1, (n, 2))
    contacts, positions = [], []
    for k in range(snapshots):
        position = cells.wrap(centres + np.asarray(shift), [0, 0], cell[k], [1, 1])
        d = cells.minimum_image(position[None, :] - position[:, None], cell[k], [1, 1])
        a, b = np.nonzero(np.triu(np.linalg.norm(d, axis=-1) < reach, 1))
        branch = d[a, b]
        contacts.append(dict(i=a, j=b, normal=branch / np.linalg.norm(branch, axis=-1)[:, None],
                             fn=rng.uniform(0.5, 2, a.size), ft=rng.uniform(-0.3, 0.3, a.size)))
        positions.append(position)
    return grainview.make_dataset(radius=np.full(n, 0.3), position=np.array(positions), contacts=contacts,
                                  velocity=np.tile(velocity, (snapshots, 1, 1)), box_min=np.zeros((snapshots, 2)),
                                  box_max=box_max, time=np.arange(snapshots, dtype=float), periodic=[1, 1], cell=cell,
                                  n_contact_slots=8 * n)


FIELDS = ("density", "solid_fraction", "momentum", "velocity", "kinetic_stress", "contact_stress", "fabric")


@pytest.mark.parametrize("tilt", [0.0, 1.7, -2.9])
def test_coarse_grained_fields_move_with_the_sample_across_the_cell(tilt):
    """The sample moved by a random vector (wrapped back into the cell) has the same fields on
    the grid moved by that vector, to round-off: the fields are those of the periodic packing."""
    rng = np.random.default_rng(8)
    base = random_periodic(tilt=tilt)
    n_across = int(base["contact_count"][0])
    x, y = np.arange(-1.0, 7.5, 0.25), np.arange(-0.5, 6.0, 0.25)
    fields = grainview.analysis.coarse_graining.coarse_grained(base, width=0.4, x=x, y=y)
    for _ in range(3):
        shift = rng.uniform(-10, 10, 2)
        moved = random_periodic(shift=shift, tilt=tilt)
        assert int(moved["contact_count"][0]) == n_across
        again = grainview.analysis.coarse_graining.coarse_grained(moved, width=0.4, x=x + shift[0], y=y + shift[1])
        for name in FIELDS:
            want = fields[name].values
            assert np.isfinite(want).mean() > 0.5, name
            np.testing.assert_allclose(again[name].values, want, rtol=1e-9, atol=1e-9 * np.nanmax(np.abs(want)),
                                       err_msg=name)


def test_coarse_grained_fields_are_periodic_and_integrate_to_the_sample(prepare):
    """On the default grid of a periodic cell (the cell's bounds, nodes at the centres of cells
    of the spacing, which divides l and h): the contact stress integrates to the Love-Weber
    stress times the cell's area, the solid fraction to the particles' area, the density to
    their mass (the kernel cut at 6 widths: the grid quadrature exact to ~1e-9)."""
    ds = random_periodic(tilt=1.3, snapshots=2)
    out = prepare(ds).grain.coarse_grained(width=0.25, spacing=0.125, cutoff=6).compute()
    np.testing.assert_allclose(out.x.values, np.arange(0.0625, 6.0, 0.125))
    np.testing.assert_allclose(out.y.values, np.arange(0.0625, 5.0, 0.125))
    cell_area = 0.125 ** 2
    integral = out.contact_stress.sum(("x", "y")).values * cell_area
    expected = ds.grain.stress_tensor().values * 30.0
    np.testing.assert_allclose(integral, expected, rtol=0, atol=1e-8 * np.abs(expected).max())
    assert out.solid_fraction.sum(("x", "y")).values * cell_area == pytest.approx(np.full(2, 40 * np.pi * 0.09),
                                                                                   rel=1e-9)
    assert out.density.sum(("x", "y")).values * cell_area == pytest.approx(
        np.full(2, float(ds["mass"].sum())), rel=1e-9)
    inside = grainview.analysis.coarse_graining.interior(out)
    assert bool(inside.all())  # no walls: every node is in the bulk


def test_a_particle_near_one_edge_is_counted_near_the_opposite_one():
    cell = cells.restricted_cell([0, 0], [4, 4])
    ds = grainview.make_dataset(radius=[0.2, 0.2], position=[[0.1, 2.0], [2.0, 2.0]],
                                contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)), fn=[])],
                                box_min=[0, 0], box_max=[4, 4], periodic=[1, 1], cell=cell)
    out = grainview.analysis.coarse_graining.coarse_grained(ds, width=0.3, x=[0.3, 3.9], y=[2.0])
    np.testing.assert_allclose(out.density.values[0, 0, 0], out.density.values[0, 0, 1], rtol=1e-13)
    assert out.density.values[0, 0, 0] > 0


def test_images_across_a_sheared_cell_carry_the_shear_velocity():
    """Lees-Edwards: in a cell whose tilt grows at 0.5 m/s, a particle at rest near the bottom
    edge has an image above the top edge moving at 0.5 m/s along x."""
    box_max = np.tile([4.0, 4.0], (3, 1))
    cell = cells.restricted_cell(np.zeros((3, 2)), box_max, [0.0, 0.5, 1.0])
    ds = grainview.make_dataset(radius=[0.2], position=np.tile([[2.0, 0.05]], (3, 1, 1)),
                                contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)), fn=[])] * 3,
                                velocity=np.zeros((3, 1, 2)), box_min=np.zeros((3, 2)), box_max=box_max,
                                time=[0.0, 1.0, 2.0], periodic=[1, 1], cell=cell)
    out = grainview.analysis.coarse_graining.coarse_grained(ds, width=0.3, x=[2.0, 2.5], y=[0.1, 3.95])
    v = out.velocity.isel(time=1).values  # (y, x, xy)
    np.testing.assert_allclose(v[1, :, 0], 0.5, rtol=1e-12)  # by the top edge: the image
    np.testing.assert_allclose(v[0, :, 0], 0.0, atol=1e-12)  # by the particle itself


def square_lattice_on_the_torus(n=4, tilt=0.0, shift=(0.0, 0.0)):
    """The n x n square lattice of test_periodic_cell, forces 2 N along x and 1 N along y."""
    import importlib

    lattice = importlib.import_module("tests.grainview.test_periodic_cell").lattice
    return lattice(tilt=tilt, shift=shift)


@pytest.mark.parametrize("tilt", [0.0, 1.0])
def test_network_topology_of_a_lattice_on_the_torus_by_hand(prepare, tilt):
    """4 x 4 square lattice on the torus: V = 16, E = 32, no triangle: beta_0 = 1 and
    beta_1 = E - V + 1 = 17, of which 2 wind around the cell (the 16 squares give 15
    independent loops); the strong network (the 16 horizontal contacts of 2 N, xi = 4/3) is 4
    rows, each a loop around the cell along a: beta_0 = 4, beta_1 = 4, all winding."""
    ds = prepare(square_lattice_on_the_torus(tilt=tilt))
    top = ds.grain.network_persistence(xi=[0.0, 1.0, 1.5]).compute()
    np.testing.assert_array_equal(top["beta_0"].values[0], [1, 4, 0])
    np.testing.assert_array_equal(top["beta_1"].values[0], [17, 4, 0])
    np.testing.assert_array_equal(top["beta_1_winding"].values[0], [2, 4, 0])
    assert int(top["cycles_3"].sum()) == 0
    assert int(top["cycles_4"].sum()) == 24  # 16 squares, and the 4 rows and 4 columns around the cell


def test_winding_loops_do_not_move_with_the_sample():
    rng = np.random.default_rng(4)
    base = random_periodic(tilt=0.8, n=40, size=(4.0, 4.0), reach=1.0)
    want = base.grain.network_persistence(xi=np.linspace(0, 3, 13))
    assert int(want["beta_1_winding"].max()) > 0
    for _ in range(3):
        moved = random_periodic(shift=rng.uniform(-9, 9, 2), tilt=0.8, n=40, size=(4.0, 4.0), reach=1.0)
        got = moved.grain.network_persistence(xi=np.linspace(0, 3, 13))
        for name in ("beta_0", "beta_1", "beta_1_winding"):
            np.testing.assert_array_equal(got[name].values, want[name].values)


def test_winding_ranks_of_two_strands_joined():
    """Two loops around the cell along a (rank 1 each: 2), joined by a contact (one component:
    the loop around the band between them winds zero times, 1); a loop along b makes it 2."""
    from grainview.analysis._kernels.network_topology import winding_ranks

    u = np.array([0, 1, 0, 0], np.int64)
    v = np.array([0, 1, 1, 1], np.int64)
    # self-loops stand for a strand around the cell: a particle touching its own image one cell along a
    shift = np.array([[1, 0], [1, 0], [0, 0], [0, 1]], np.int64)
    np.testing.assert_array_equal(winding_ranks(2, u, v, shift), [1, 2, 1, 2])


def test_displacement_of_a_particle_across_the_boundary(prepare):
    """A disk moving 0.3 m per snapshot along x through the right edge of a 2 x 2 cell (stored
    wrapped): its displacement grows 0.3 per snapshot, with no jump of a cell."""
    t = 6
    x = np.mod(1.2 + 0.3 * np.arange(t), 2.0)
    position = np.stack([np.stack([x, np.full(t, 1.0)], -1), np.tile([0.5, 0.3], (t, 1))], axis=1)
    ds = grainview.make_dataset(radius=[0.1, 0.1], position=position,
                                contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)), fn=[])] * t,
                                box_min=np.zeros((t, 2)), box_max=np.full((t, 2), 2.0), time=np.arange(t, dtype=float),
                                periodic=[1, 1], cell=cells.restricted_cell([0, 0], [2, 2]))
    assert ds.attrs["cell_positions"] == "wrapped"
    out = prepare(ds).grain.particle_fields().compute()
    np.testing.assert_allclose(out["displacement"].values[:, 0], 0.3 * np.arange(t), atol=1e-12)
    np.testing.assert_allclose(out["displacement"].values[:, 1], 0.0)
    later = prepare(ds).grain.particle_fields(reference=2).compute()
    np.testing.assert_allclose(later["displacement"].values[:, 0], 0.3 * np.abs(np.arange(t) - 2), atol=1e-12)


def test_unwrapped_positions_in_a_sheared_cell_follow_the_tilt(prepare):
    """A 4 x 4 cell sheared by 0.4 m of tilt per snapshot, with a flip past l/2 = 2 (LAMMPS sets the
    tilt back by l); a disk at rest in the lab at x = 1 rising 0.3 m per snapshot from y = 3.5
    through the top edge. Stored wrapped, after the crossing it sits at y - 4 and x - tilt_k
    (mod 4): the image across the top edge moves with the tilt. Unwrapped, it is back at
    (1, 3.5 + 0.3 k) in every snapshot, by hand; a sum of the wrapped steps' minimum images would
    drift by the tilt's growth since the crossing (0.4 m per snapshot)."""
    t = 8
    tilt = 0.4 * np.arange(t)
    stored_tilt = np.where(tilt > 2.0, tilt - 4.0, tilt)  # flipped
    true = np.stack([np.ones(t), 3.5 + 0.3 * np.arange(t)], axis=-1)
    crossed = true[:, 1] >= 4.0
    wrapped = true - crossed[:, None] * np.stack([tilt, np.full(t, 4.0)], axis=-1)
    cell = cells.restricted_cell(np.zeros((t, 2)), np.full((t, 2), 4.0), stored_tilt)
    wrapped = cells.wrap(wrapped, np.zeros(2), cell, [1, 1])
    position = np.stack([wrapped, np.tile([2.0, 2.0], (t, 1))], axis=1)
    ds = grainview.make_dataset(radius=[0.1, 0.1], position=position,
                                contacts=[dict(i=[], j=[], normal=np.zeros((0, 2)), fn=[])] * t,
                                box_min=np.zeros((t, 2)), box_max=np.full((t, 2), 4.0),
                                time=np.arange(t, dtype=float), periodic=[1, 1], cell=cell)
    from grainview.analysis.particle_fields import unwrapped_positions

    u = unwrapped_positions(prepare(ds)).values
    np.testing.assert_allclose(u[:, 0], true, atol=1e-12)
    displacement = prepare(ds).grain.particle_fields().compute()["displacement"].values[:, 0]
    np.testing.assert_allclose(displacement, 0.3 * np.arange(t), atol=1e-12)


def test_a_contact_keeps_its_identity_across_the_boundary():
    """Two disks in contact drifting together across the right edge (the pair stored a cell
    apart in the middle snapshots): one life, from the first snapshot to the last."""
    t = 5
    x0 = 1.5 + 0.2 * np.arange(t)
    centres = np.stack([np.stack([x0, np.ones(t)], -1), np.stack([x0 + 0.2, np.ones(t)], -1)], axis=1)
    cell = cells.restricted_cell([0, 0], [2, 2])
    position = cells.wrap(centres, [0, 0], cell, [1, 1])
    ds = grainview.make_dataset(radius=[0.1, 0.1], position=position,
                                contacts=[dict(i=[0], j=[1], normal=[[1.0, 0.0]], fn=[1.0])] * t,
                                box_min=np.zeros((t, 2)), box_max=np.full((t, 2), 2.0), time=np.arange(t, dtype=float),
                                periodic=[1, 1], cell=cell)
    grainview.validate(ds)
    events = ds.grain.contact_events()
    assert events.sizes["contact_event"] == 1
    assert bool(events["censored"][0]) and float(events["lifetime"][0]) == 4.0


def test_lifetimes_in_the_cells_shear_strain():
    ds = sheared_series([0.2, 0.6, 1.0, 1.4, 1.8 - 4.0])
    events = ds.grain.contact_events()
    assert float(events["lifetime_gamma"][0]) == pytest.approx(0.8)
    assert float(events["lifetime_eps_q"][0]) == 0.0
    survival = ds.grain.lifetime_survival(unit="gamma")
    assert survival["lifetime"].attrs["units"] == "1"


def test_maps_draw_the_cell_and_contacts_across_it():
    """A contact across the boundary is drawn as its branch from each particle (two segments of
    the length of the branch, never one across the box), particles wrapped with their images, the
    cell a parallelogram."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from grainview.plot import maps

    ds = chain_across(tilt=2.0)
    segments, slots = maps.contact_segments(ds, 0, np.ones(ds.sizes["contact"], bool) & (
        np.arange(ds.sizes["contact"]) < int(ds["contact_count"][0])))
    lengths = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=-1)
    np.testing.assert_allclose(lengths, 1.0)  # every piece is a branch
    assert np.bincount(slots).max() == 2 and (np.bincount(slots) == 2).sum() == 1  # the one contact across x = 0
    ax = ds.grain.plot.force_chains()
    lines = [c for c in ax.collections if c.get_gid() == "contacts"][0]
    assert lines.get_clip_path() is not None
    outline = [p for p in ax.patches if p.get_gid() == "cell"][0]
    np.testing.assert_allclose(outline.get_xy()[:4], [[0, 0], [10, 0], [12, 10], [2, 10]])
    assert ax.get_xlim() == (0.0, 12.0)
    index, centres = maps._cell_images(ds, 0, ds["position"].values[0], ds["radius"].values)
    assert index.size > ds.sizes["particle"]  # the particles by the boundary have images
    plt.close("all")


def test_vtk_export_wraps_the_particles_and_writes_the_cell(tmp_path):
    """Stored unwrapped (a cell to the right), the particles are written inside the cell; the
    contact across the boundary is one line of its branch's length from the centre of i; the
    cell's outline is a closed line of its four corners."""
    from tests.grainview.test_export import read_vtp

    base = chain_across(tilt=2.0)
    position = base["position"].values.copy()
    position[0, :3] += [10.0, 0.0]  # three particles one cell along a: unwrapped
    ds = grainview.make_dataset(radius=base["radius"].values, position=position,
                                contacts=[dict(i=base["i"].values[0, :10], j=base["j"].values[0, :10],
                                               normal=base["normal"].values[0, :10], fn=base["fn"].values[0, :10],
                                               branch=base["branch"].values[0, :10])],
                                box_min=[0, 0], box_max=[10, 10], periodic=[1, 1], cell=base["cell"].values)
    assert ds.attrs["cell_positions"] == "unwrapped"
    written = grainview.export.write_vtk(ds, tmp_path)
    assert any(p.endswith("cell_00000.vtp") for p in written)

    def points(name):
        return read_vtp(tmp_path / name)[2]["Points"]["Points"][:, :2]

    centres = points("particles_00000.vtp")
    np.testing.assert_allclose(centres, base["position"].values[0], atol=1e-12)
    ends = points("contacts_00000.vtp").reshape(-1, 2, 2)
    np.testing.assert_allclose(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=-1), 1.0)
    np.testing.assert_allclose(points("cell_00000.vtp"), [[0, 0], [10, 0], [12, 10], [2, 10], [0, 0]])


def test_the_residual_window_of_a_sheared_cell_reads_gamma():
    ds = sheared_series(0.2 + 0.4 * np.arange(6))  # gamma 0, 0.2, ..., 1.0; eps_q 0 throughout
    window = grainview.analysis.strain.residual_window(ds, 0.5)
    np.testing.assert_array_equal(window.values, [False, False, False, True, True, True])
    assert "gamma" in window.attrs["long_name"]
    still = sheared_series(np.full(3, 0.7))  # a cell that is not sheared keeps eps_q's window
    assert "eps_q" in grainview.analysis.strain.residual_window(still).attrs["long_name"]


def test_inertia_number_of_a_sheared_cell_reads_the_shear_rate(prepare):
    """Two snapshots of a loaded 4 x 4 lattice, 2 s apart, the cell's tilt 0 then 1 m at a fixed
    height: gamma_dot = 1/4 / 2 s; I = gamma_dot sqrt(m / (p t)) by hand (the height's rate, zero,
    would give I = 0)."""
    from .test_periodic_cell import lattice

    first, second = lattice(0.0), lattice(1.0)
    ds = grainview.make_dataset(radius=first["radius"].values,
                                position=np.stack([first["position"].values[0], second["position"].values[0]]),
                                contacts=[{name: snap[name].values[0, :32] for name in ("i", "j", "normal", "fn")}
                                          for snap in (first, second)],
                                box_min=[0, 0], box_max=[4, 4], time=[0.0, 2.0], periodic=[1, 1],
                                cell=np.stack([first["cell"].values[0], second["cell"].values[0]]))
    sigma = ds.grain.stress_tensor().values
    p = (sigma[:, 0, 0] + sigma[:, 1, 1]) / 2
    mass = float(ds["mass"].sum())
    by_hand = 0.125 * np.sqrt(mass / p)
    np.testing.assert_allclose(prepare(ds).grain.inertia_number().values, by_hand, rtol=1e-12)
