"""Coarse-grained fields: the kernels against direct numpy sums and quadratures, the exact
integrals (Love-Weber stress, mass, particle area), lattices by hand, the limit of a vanishing
width, eager against chunked under a scheduler that raises on compute."""

import numpy as np
import pytest
import xarray as xr

from grainview.analysis import sample
from grainview.analysis._kernels.coarse_graining import spread_points, spread_segments
from grainview.analysis._kernels.records import Grid, Points, Segments
from grainview.analysis.arrays.stress import stress_tensor as love_weber
from grainview.analysis.coarse_graining import coarse_grained, field_invariants, interior, profile, scalar_field
from grainview.contract.dataset import make_dataset
from grainview.contract.errors import ParameterError
from grainview.analysis.fabric import fabric_tensor
from grainview.analysis.stress import stress_tensor

from . import builders
from .builders import R
from .conftest import raise_if_dask_computes

A = 2 * R  # lattice spacing of the builders' lattices, m


def phi(dx, dy, w, c):
    """The truncated, renormalised Gaussian, evaluated directly (m^-2)."""
    r2 = dx ** 2 + dy ** 2
    norm = 2 * np.pi * w ** 2 * (1 - np.exp(-c ** 2 / (2 * w ** 2)))
    return np.where(r2 < c ** 2, np.exp(-r2 / (2 * w ** 2)) / norm, 0.0)


def grid_around(lo, hi, spacing, margin):
    """Nodes every ``spacing`` from ``lo - margin`` to ``hi + margin`` (m), so every kernel fits."""
    x = np.arange(lo[0] - margin, hi[0] + margin + spacing / 2, spacing)
    y = np.arange(lo[1] - margin, hi[1] + margin + spacing / 2, spacing)
    return x, y


# -- the kernels against direct sums ---------------------------------------------------------

def test_spread_points_is_the_direct_sum():
    rng = np.random.default_rng(3)
    px, py = rng.uniform(0, 1, (2, 7)), rng.uniform(0, 1, (2, 7))
    active = rng.uniform(size=(2, 7)) < 0.8
    weights = rng.normal(size=(2, 7, 3))
    x, y = np.linspace(-0.3, 1.3, 41), np.linspace(-0.2, 1.2, 37)
    w, c = 0.15, 0.4
    out = np.zeros((2, y.size, x.size, 3))
    spread_points(Points(px, py, active, weights), Grid(x, y, w, c), out)
    X, Y = np.meshgrid(x, y)
    for b in range(2):
        expected = sum(phi(X - px[b, p], Y - py[b, p], w, c)[..., None] * weights[b, p]
                       for p in range(7) if active[b, p])
        np.testing.assert_allclose(out[b], expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("cutoff", [3.0, 12.0])
def test_spread_segments_is_the_line_integral(cutoff):
    """psi(r) = int_0^1 phi(r - s - u l) du, against a dense midpoint rule (cutoff 3: the
    integrand jumps where the line leaves the kernel's disk) and, for a kernel too wide to be
    cut, against 64-point Gauss-Legendre on a smooth integrand."""
    rng = np.random.default_rng(5)
    w = 0.1
    c = cutoff * w
    sx, sy = rng.uniform(0, 1, (2, 1, 6))
    lx, ly = rng.uniform(-0.4, 0.4, (2, 1, 6))
    lx[0, 0], ly[0, 0] = 0.0, 0.0  # a point
    x, y = np.linspace(-0.6, 1.6, 23), np.linspace(-0.5, 1.5, 19)
    out = np.zeros((1, y.size, x.size, 1))
    spread_segments(Segments(sx, sy, lx, ly, np.ones((1, 6), bool), np.ones((1, 6, 1))), Grid(x, y, w, c), out)
    X, Y = np.meshgrid(x, y)
    if cutoff == 3.0:
        u = (np.arange(40_000) + 0.5) / 40_000
        weights = np.full(u.size, 1 / u.size)
        tolerance = 1e-5
    else:
        u, weights = np.polynomial.legendre.leggauss(64)
        u, weights = (u + 1) / 2, weights / 2
        tolerance = 1e-11
    expected = np.zeros_like(X)
    for k in range(6):
        for uk, wk in zip(u, weights):
            expected += wk * phi(X - sx[0, k] - uk * lx[0, k], Y - sy[0, k] - uk * ly[0, k], w, c)
    peak = 1 / (2 * np.pi * w ** 2)
    np.testing.assert_allclose(out[0, ..., 0], expected, rtol=0, atol=tolerance * peak)
    assert out[0, ..., 0].max() > 0.1 * peak


# -- exact integrals -------------------------------------------------------------------------

def test_contact_stress_integrates_to_the_love_weber_stress(prepare):
    """(1/A) sum_grid sigma^c dx dy = (1/V) sum_c f (x) l, wall contacts included, for random
    simple, double and wall contacts with tangential forces (a kernel cut at 6 widths, whose
    grid quadrature is exact to ~1e-9)."""
    eager = builders.mixed_contacts(seed=4, t=3)
    ds = prepare(eager)
    x, y = grid_around([0.0, 0.0], [0.2, 0.2], 0.004, 0.1)
    with raise_if_dask_computes():
        out = coarse_grained(ds, width=0.01, x=x, y=y, cutoff=6)
    out = out.compute()
    integral = out.contact_stress.sum(("x", "y")) * 0.004 ** 2
    expected = stress_tensor(eager) * sample.area(eager)
    scale = float(np.abs(expected).max())
    np.testing.assert_allclose(integral.values, expected.values, rtol=0, atol=1e-8 * scale)
    assert np.abs(expected.values[..., 0, 1] - expected.values[..., 1, 0]).max() > 1e-3 * scale  # not symmetric


def test_density_and_solid_fraction_integrate_to_mass_and_area(prepare):
    """int rho dA t = sum m_i (the file's masses), int nu dA = sum A_i (pentagons and disks)."""
    pos = np.array([[0.0, 0.0], [0.05, 0.01], [0.02, 0.06]])
    contacts = [dict(i=[0], j=[1], kind=[1], normal=[[1.0, 0.0]], fn=[1.0], ft=[0.0])]
    eager = make_dataset(radius=[0.01, 0.02, 0.015], position=pos, contacts=contacts, n_vertices=[5, 0, 3],
                         mass=[1.5, 2.0, 0.25], box_min=[-0.02, -0.02], box_max=[0.08, 0.08],
                         attrs={"thickness_m": 0.5})
    x, y = grid_around([-0.02, -0.02], [0.08, 0.08], 0.002, 0.05)
    out = coarse_grained(prepare(eager), width=0.008, x=x, y=y, cutoff=8).compute()
    cell = 0.002 ** 2
    assert float(out.density.sum() * cell * 0.5) == pytest.approx(3.75, rel=1e-9)
    areas = [2.5 * 0.01 ** 2 * np.sin(2 * np.pi / 5), np.pi * 0.02 ** 2, 1.5 * 0.015 ** 2 * np.sin(2 * np.pi / 3)]
    assert float(out.solid_fraction.sum() * cell) == pytest.approx(sum(areas), rel=1e-9)
    assert out.density.attrs["units"] == "kg m-3" and out.x.attrs["units"] == "m"
    # per unit volume too: t int sigma^c dA = sum_c f (x) l, here f = (1, 0) N, l = (0.05, 0.01) m
    love_weber = out.contact_stress.isel(time=0).sum(("x", "y")).values * cell * 0.5
    np.testing.assert_allclose(love_weber, [[0.05, 0.01], [0.0, 0.0]], rtol=1e-9, atol=1e-12)


def test_default_cutoff_quadrature():
    """At the default cutoff (3 widths) the kernel's jump at its edge limits the grid
    quadrature: within 0.5% at a spacing of one width, 1e-4 at a quarter width."""
    ds = builders.mixed_contacts(seed=4, t=1)
    expected = (stress_tensor(ds) * sample.area(ds)).values
    for spacing, tolerance in ((0.01, 5e-3), (0.0025, 1e-4)):
        x, y = grid_around([0.0, 0.0], [0.2, 0.2], spacing, 0.05)
        out = coarse_grained(ds, width=0.01, x=x, y=y)
        integral = (out.contact_stress.sum(("x", "y")) * spacing ** 2).values
        assert np.abs(integral - expected).max() < tolerance * np.abs(expected).max()


# -- lattices by hand ------------------------------------------------------------------------

def test_square_lattice_gives_uniform_fields_by_hand(prepare):
    """20 x 20 disks on a square grid of spacing a = 2R, horizontal contacts 2 N, vertical 5 N:
    one particle and one contact of each direction per cell a^2, so away from the edges
    sigma^c = diag(2 N a, 5 N a)/a^2 = diag(100, 250) Pa, rho = m/a^2, nu = pi/4, F = I/2,
    p = 175 Pa, q = 75 Pa."""
    eager = builders.square_lattice(20, 20, fx=2.0, fy=5.0)
    ds = prepare(eager)
    x = y = np.linspace(0, 19 * A, 39)
    with raise_if_dask_computes():
        out = coarse_grained(ds, width=1.5 * A, x=x, y=y, cutoff=8)
        inv = field_invariants(out)
    out, inv = out.compute(), inv.compute()
    inner = dict(x=slice(9 * A - 1e-9, 10 * A + 1e-9), y=slice(9 * A - 1e-9, 10 * A + 1e-9))  # 6 widths from the edges
    core = out.sel(**inner).isel(time=0)
    assert core.sizes["x"] * core.sizes["y"] >= 9
    rtol = 1e-6
    np.testing.assert_allclose(core.contact_stress.values, np.broadcast_to([[100.0, 0], [0, 250.0]],
                                                                           core.contact_stress.shape),
                               rtol=rtol, atol=rtol * 250)
    mass = float(eager.mass[0])
    np.testing.assert_allclose(core.density.values, mass / A ** 2, rtol=rtol)
    np.testing.assert_allclose(core.solid_fraction.values, np.pi / 4, rtol=rtol)
    np.testing.assert_allclose(core.fabric.values, np.broadcast_to(np.eye(2) / 2, core.fabric.shape), atol=rtol)
    np.testing.assert_allclose(inv.sel(**inner).p.values, 175.0, rtol=rtol)
    np.testing.assert_allclose(inv.sel(**inner).q_over_p.values, 75.0 / 175.0, rtol=rtol)
    np.testing.assert_allclose(inv.sel(**inner).theta_sigma.values, np.pi / 2, rtol=rtol)
    # near the edges the field falls off: the lattice ends there
    assert float(out.density.isel(time=0, x=0, y=0)) < 0.5 * mass / A ** 2


def test_hexagonal_lattice_is_uniform_and_isotropic():
    """A triangular lattice of spacing a, force f on every contact: per particle 3 contacts of
    f a n (x) n with sum n (x) n = (3/2) I over the 3 directions, in a cell of area (sqrt 3/2) a^2:
    sigma^c = sqrt(3) f / a I away from the edges; nu = pi/(2 sqrt 3)."""
    ds = builders.hexagonal_lattice(24, 24, force=1.0)
    x = np.linspace(9 * A, 14 * A, 11)
    y = np.linspace(8 * A, 12 * A, 9)
    out = coarse_grained(ds, width=A, x=x, y=y, cutoff=6).isel(time=0)
    sigma = np.sqrt(3) * 1.0 / A
    np.testing.assert_allclose(out.contact_stress.values, np.broadcast_to(sigma * np.eye(2), out.contact_stress.shape),
                               rtol=0, atol=1e-7 * sigma)
    np.testing.assert_allclose(out.solid_fraction.values, np.pi / (2 * np.sqrt(3)), rtol=1e-7)
    # the default cutoff leaves a ripple of the lattice below 1%
    default = coarse_grained(ds, width=A, x=x, y=y).isel(time=0)
    np.testing.assert_allclose(default.contact_stress.values[..., 0, 0], sigma, rtol=1e-2)


def test_velocity_and_kinetic_stress_by_hand():
    """A square lattice moving at v0 has V = v0 and no kinetic stress (exactly, wherever rho > 0);
    particles alternating +-u along x in a checkerboard have V = 0 and sigma^k_xx = rho u^2,
    sigma^k_yy = 0 away from the edges."""
    base = builders.square_lattice(16, 16)
    n = base.sizes["particle"]
    pos = base.position.values[0]
    x, y = np.linspace(6 * A, 9 * A, 7), np.linspace(6 * A, 9 * A, 7)
    contacts = [dict(i=[0], j=[1], kind=[1], normal=[[0.0, 1.0]], fn=[1.0], ft=[0.0])]
    args = dict(radius=np.full(n, R), position=pos, contacts=contacts, box_min=[-R, -R], box_max=[15.5 * A, 15.5 * A])
    uniform = coarse_grained(make_dataset(velocity=np.tile([0.3, -0.2], (1, n, 1)), **args),
                             width=1.5 * A, x=x, y=y, cutoff=6).isel(time=0)
    np.testing.assert_allclose(uniform.velocity.values, np.broadcast_to([0.3, -0.2], uniform.velocity.shape),
                               rtol=1e-12)
    rho_v2 = (uniform.density * 0.09).values
    assert np.abs(uniform.kinetic_stress.values).max() < 1e-12 * rho_v2.max()
    sign = np.where(np.rint(pos[:, 0] / A + pos[:, 1] / A) % 2 == 0, 1.0, -1.0)
    velocity = np.stack([0.5 * sign, np.zeros(n)], axis=-1)[None]
    mixed = coarse_grained(make_dataset(velocity=velocity, **args), width=1.5 * A, x=x, y=y, cutoff=6).isel(time=0)
    np.testing.assert_allclose(mixed.velocity.values, 0.0, atol=1e-8)
    np.testing.assert_allclose(mixed.kinetic_stress.values[..., 0, 0], mixed.density.values * 0.25, rtol=1e-8)
    np.testing.assert_allclose(mixed.kinetic_stress.values[..., 1, 1], 0.0, atol=1e-12)
    total = field_invariants(mixed, stress="kinetic")
    np.testing.assert_allclose(total.q_over_p.values, 1.0, rtol=1e-8)  # uniaxial: s2 = 0


def test_a_kernel_wider_than_the_sample_gives_the_sample_fabric():
    """F(r) = sum n (x) n psi / sum psi tends to the sample's fabric tensor (particle-particle
    contacts, wall contacts left out) when psi is the same for every contact."""
    ds = builders.mixed_contacts(seed=9, t=2)
    out = coarse_grained(ds, width=200.0, x=[0.05, 0.15], y=[0.1], cutoff=3)
    expected = fabric_tensor(ds).values[:, None, None]
    np.testing.assert_allclose(out.fabric.values, np.broadcast_to(expected, out.fabric.shape), rtol=1e-6)


def test_fields_converge_as_the_width_shrinks():
    """Over a fixed region Omega, as w -> 0: t int_Omega rho dA -> the mass of the particles inside,
    and t int_Omega sigma^c dA -> sum_c f (x) l |l in Omega|/|l| (each contact by the part of its
    branch inside). Both errors fall with w, to under 1e-3 at w = 0.5 mm (particles 2 cm across)."""
    ds = builders.mixed_contacts(seed=2, t=1, walls=False)
    pos = ds.position.values[0]
    lo, hi = np.array([0.035, 0.05]), np.array([0.145, 0.13])
    inside = np.all((pos >= lo) & (pos <= hi), axis=1)
    mass = float(ds.mass.values[inside].sum())
    count = int(ds.contact_count[0])
    i, j = ds.i.values[0, :count], ds.j.values[0, :count]
    u = (np.arange(100_000) + 0.5) / 100_000
    expected = np.zeros((2, 2))
    for c in range(count):
        line = pos[i[c]] + u[:, None] * (pos[j[c]] - pos[i[c]])
        share = np.all((line >= lo) & (line <= hi), axis=1).mean()
        expected += share * love_weber(ds.fn.values[0, c:c + 1], ds.ft.values[0, c:c + 1], ds.normal.values[0, c:c + 1],
                                       ds.branch.values[0, c:c + 1], [True], 1.0)
    errors = []
    for w in (0.008, 0.004, 0.002, 0.001, 0.0005):
        spacing = w / 4
        x = np.arange(lo[0] + spacing / 2, hi[0], spacing)
        y = np.arange(lo[1] + spacing / 2, hi[1], spacing)
        out = coarse_grained(ds, width=w, x=x, y=y, cutoff=6).isel(time=0)
        stress = out.contact_stress.sum(("x", "y")).values * spacing ** 2
        density = float(out.density.sum()) * spacing ** 2
        errors.append((abs(density - mass) / mass, np.abs(stress - expected).max() / np.abs(expected).max()))
    errors = np.array(errors)
    assert np.all(np.diff(errors, axis=0) < 0), errors
    assert np.all(errors[-1] < 1e-3), errors
    assert np.all(errors[0] > 100 * errors[-1]), errors


# -- laziness, grids, options ----------------------------------------------------------------

def test_chunked_equals_eager_and_stays_lazy():
    eager = builders.mixed_contacts(seed=1, t=4)
    velocity = np.random.default_rng(0).normal(size=(4, eager.sizes["particle"], 2))
    eager = eager.assign(velocity=(("time", "particle", "xy"), velocity, {"units": "m s-1"}))
    chunked = eager.chunk({"time": 2})
    with raise_if_dask_computes(max_computes=1) as scheduler:  # the grid reads the boxes once
        lazy = chunked.grain.coarse_grained(width=0.02, spacing=0.01)
        inv = field_invariants(lazy)
        cut = profile(inv.q_over_p, across="y")
    assert scheduler.total_computes == 1
    assert lazy.chunks["time"] == (2, 2) and set(lazy.data_vars) == {
        "density", "solid_fraction", "momentum", "velocity", "kinetic_stress", "contact_stress", "fabric"}
    direct = eager.grain.coarse_grained(width=0.02, spacing=0.01)
    xr.testing.assert_allclose(lazy.compute(), direct, rtol=1e-13, atol=0)
    xr.testing.assert_allclose(cut.compute(), profile(field_invariants(direct).q_over_p, across="y"))
    # the grid: cells of 1 cm covering the 0.2 m box widened by the kernel's radius 6 cm, nodes at their centres
    np.testing.assert_allclose(direct.x.values, -0.055 + 0.01 * np.arange(32))
    # which holds every kernel whole: its integrals are the Love-Weber stress and the mass
    integral = direct.contact_stress.sum(("x", "y")) * 0.01 ** 2
    expected = (stress_tensor(eager) * sample.area(eager)).values
    assert np.abs(integral.values - expected).max() < 5e-3 * np.abs(expected).max()  # the default cutoff's quadrature
    np.testing.assert_allclose(direct.density.sum(("x", "y")) * 0.01 ** 2, float(eager.mass.sum()), rtol=5e-3)
    assert "eps_q" in direct.coords and direct.attrs["width_m"] == 0.02


def test_without_velocities_there_are_no_kinetic_fields():
    out = coarse_grained(builders.two_disks(), width=0.01, spacing=0.005)
    assert set(out.data_vars) == {"density", "solid_fraction", "contact_stress", "fabric"}
    default = coarse_grained(builders.two_disks())  # width: the mean diameter 2 R; spacing: half of it
    assert default.attrs["width_m"] == 2 * R and default.attrs["spacing_m"] == pytest.approx([R, R])
    with pytest.raises(ParameterError, match="no kinetic stress"):
        field_invariants(out, stress="kinetic")


def test_profile_by_hand():
    field = xr.DataArray([[1.0, 2.0, np.nan], [3.0, 6.0, 5.0]], dims=("y", "x"), attrs={"units": "Pa"})
    np.testing.assert_array_equal(profile(field, "x").values, [2.0, 4.0, 5.0])
    np.testing.assert_array_equal(profile(field, "y").values, [1.5, 14 / 3])
    inside = xr.DataArray([[True, False, True], [True, True, True]], dims=("y", "x"))
    np.testing.assert_array_equal(profile(field, "x", inside=inside).values, [2.0, 6.0, 5.0])
    assert profile(field).attrs["units"] == "Pa"


@pytest.mark.parametrize("kwargs, match", [
    (dict(width=-1.0, spacing=0.01), "width=-1.0: expected a number > 0"),
    (dict(width=np.nan, spacing=0.01), "width=nan"),
    (dict(width="1", spacing=0.01), "width='1'"),
    (dict(width=0.01, spacing=0.0), "spacing=0.0"),
    (dict(width=0.01, spacing=(0.01, 0.01, 0.01)), "pair"),
    (dict(width=0.01, x=[0.0, 0.1]), "expected spacing="),
    (dict(width=0.01, spacing=0.01, x=[0.0], y=[0.0]), "not both"),
    (dict(width=0.01, x=[0.1, 0.0], y=[0.0]), "x: expected finite, strictly increasing"),
    (dict(width=0.01, x=[0.0], y=[[0.0]]), "y: expected a non-empty 1-D"),
    (dict(width=0.01, spacing=0.01, kernel="lucy"), "kernel='lucy': expected one of 'gaussian'"),
    (dict(width=0.01, spacing=0.01, cutoff=0), "cutoff=0"),
])
def test_bad_arguments_say_what_was_expected(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        coarse_grained(builders.two_disks(), **kwargs)
    with pytest.raises(ParameterError, match="across='z'"):
        profile(xr.DataArray(np.zeros((2, 2)), dims=("y", "x")), across="z")
    with pytest.raises(ParameterError, match="stress='all'"):
        field_invariants(xr.Dataset(), stress="all")


# -- derived fields and figures --------------------------------------------------------------

def test_scalar_fields_by_hand():
    """On the square lattice (sigma = diag(100, 250) Pa inside): sigma_yy 250, sigma_xy 0, p 175,
    q/p 3/7; with a uniform velocity, speed |v0| and no shear rate; the fabric anisotropy 0."""
    base = builders.square_lattice(20, 20, fx=2.0, fy=5.0)
    ds = base.assign(velocity=(("time", "particle", "xy"), np.tile([0.3, 0.4], (1, 400, 1)), {"units": "m s-1"}))
    x = y = np.linspace(9 * A, 10 * A, 3)
    out = coarse_grained(ds, width=1.5 * A, x=x, y=y, cutoff=8)
    expected = {"sigma_yy": 250.0, "sigma_xx": 100.0, "p": 175.0, "q": 75.0, "q_over_p": 75 / 175, "speed": 0.5}
    for name, value in expected.items():
        np.testing.assert_allclose(scalar_field(out, name).values, value, rtol=1e-6)
    assert scalar_field(out, "sigma_yy").attrs["units"] == "Pa"
    for name in ("sigma_xy", "fabric_anisotropy", "shear_rate"):
        np.testing.assert_allclose(scalar_field(out, name).values, 0.0, atol=1e-6 * {"sigma_xy": 250}.get(name, 1))
    np.testing.assert_allclose(scalar_field(out, "sigma_yy", stress="contact").values, 250.0, rtol=1e-6)
    with pytest.raises(ParameterError, match="name='tau'"):
        scalar_field(out, "tau")


def test_shear_rate_of_a_simple_shear_by_hand():
    """Velocities v = (g y, 0) on a square lattice: dVx/dy = g, so gamma_dot = g inside (the
    coarse-grained velocity of a linear field is linear where the kernel is whole)."""
    base = builders.square_lattice(20, 20)
    g = 2.0
    velocity = np.stack([g * base.position.values[..., 1], np.zeros((1, 400))], axis=-1)
    ds = base.assign(velocity=(("time", "particle", "xy"), velocity, {"units": "m s-1"}))
    x = y = np.linspace(8 * A, 11 * A, 7)
    rate = scalar_field(coarse_grained(ds, width=1.5 * A, x=x, y=y, cutoff=8), "shear_rate")
    np.testing.assert_allclose(rate.values, g, rtol=1e-6)
    assert rate.attrs["units"] == "s-1"


def test_interior_leaves_out_the_walls_layer():
    ds = builders.square_lattice(10, 10)  # box [-R, 19 R] on both axes
    out = coarse_grained(ds, width=R, x=[-R, 0.5 * R, 9 * R, 17.5 * R, 19 * R], y=[9 * R])
    inside = interior(out)  # 2 widths from the edges: [R, 17 R]
    assert inside.isel(time=0, y=0).values.tolist() == [False, False, True, False, False]
    assert interior(out, margin=0.0).isel(time=0, y=0).values.tolist() == [True] * 5
    with pytest.raises(ParameterError, match="margin=-1"):
        interior(out, margin=-1)


def test_field_figures_draw_the_fields_with_units():
    import matplotlib

    matplotlib.use("Agg")
    from grainview.plot import plot_field_maps, plot_field_profiles

    ds = builders.square_lattice(12, 12, fx=2.0, fy=5.0)
    fig = ds.grain.plot.field_maps(width=1.5 * A, spacing=A / 2)
    assert len(fig.axes) == 6  # three maps and their colour bars
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels[:3] == ["$y$ (m)"] * 3 and fig.axes[0].get_xlabel() == "$x$ (m)"
    assert labels[3:] == [r"$\sigma_{yy}$ (Pa)", "$q/p$", r"$\nu$"]
    fields = coarse_grained(ds, width=1.5 * A, spacing=A / 2)
    fig = plot_field_profiles(ds, fields=fields, names=["sigma_yy"], across="y", margin=0.0)
    line = fig.axes[0].lines[0]
    expected = profile(scalar_field(fields, "sigma_yy"), across="y", inside=interior(fields, margin=0.0)).isel(time=0)
    np.testing.assert_allclose(line.get_ydata(), expected)
    assert np.isnan(expected[0]) and np.isfinite(expected).sum() == 24  # the nodes in the 24 R box: 24 of 2 R/2
    assert fig.axes[0].get_xlabel() == "$y$ (m)" and fig.axes[0].get_ylabel() == r"$\sigma_{yy}$ (Pa)"
    with pytest.raises(ParameterError, match="names="):
        plot_field_maps(ds, names=["tau"], width=A)
    with pytest.raises(ParameterError, match="fields has 1 snapshots, the dataset 2"):
        plot_field_maps(ds.isel(time=[0, 0]), fields=fields)
    matplotlib.pyplot.close("all")


def test_solid_fraction_of_polygons_given_by_their_vertices(prepare):
    """A rectangle 4 cm x 1 cm (vertices in its own frame) and a disk: int nu dA = 4e-4 + pi R^2."""
    rect = np.array([[0.02, -0.005], [0.02, 0.005], [-0.02, 0.005], [-0.02, -0.005]])
    vertices = np.full((2, 4, 2), np.nan)
    vertices[0] = rect
    radius = [float(np.hypot(0.02, 0.005)), 0.01]
    contacts = [dict(i=[0], j=[1], kind=[1], normal=[[1.0, 0.0]], fn=[1.0], ft=[0.0])]
    eager = make_dataset(radius=radius, n_vertices=[4, 0], vertices=vertices, position=[[0.0, 0.0], [0.05, 0.0]],
                         contacts=contacts, box_min=[-0.03, -0.02], box_max=[0.07, 0.02])
    x, y = grid_around([-0.03, -0.02], [0.07, 0.02], 0.002, 0.06)
    out = coarse_grained(prepare(eager), width=0.008, x=x, y=y, cutoff=8).compute()
    assert float(out.solid_fraction.sum()) * 0.002 ** 2 == pytest.approx(4e-4 + np.pi * 1e-4, rel=1e-9)
