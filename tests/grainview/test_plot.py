"""Figures of grainview.plot: each test draws on a small dataset and checks what was drawn
against the analysis functions (the plotted numbers), against hand-computed values on lattices
whose answers are known, and checks the labels (units) and the saved files."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import EllipseCollection, PolyCollection  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

import grainview  # noqa: E402
from grainview import plot as gp  # noqa: E402
from grainview.analysis.connectivity import connectivity_pdf, coordination, joint_connectivity_pdf  # noqa: E402
from grainview.contract.errors import ParameterError  # noqa: E402
from grainview.analysis.fabric import fabric_anisotropy, orientation_pdf  # noqa: E402
from grainview.analysis.forces import force_anisotropies, harmonic_prediction  # noqa: E402
from grainview.plot import PlotAccessor, save_figure  # noqa: E402
from grainview.analysis.snapshots import select_snapshots  # noqa: E402
from grainview.plot.maps import CLASS_COLOURS, KIND_COLOURS, contact_collection, newtons, per_metre  # noqa: E402
from grainview.analysis.strain import friction_and_dilatancy, strains  # noqa: E402
from grainview.analysis.stress import stress_invariants  # noqa: E402
from grainview.datasets import harmonic_series  # noqa: E402

from . import builders  # noqa: E402

R = builders.R


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def series():
    return harmonic_series(n_snapshots=4, n_contacts=300, seed=3)


@pytest.fixture(scope="module")
def other_series():
    return harmonic_series(n_snapshots=5, n_contacts=200, anisotropy=(0.1, 0.2, 0.1), seed=4)


def pentagon_grid(nx=5, ny=4, seed=0):
    """Pentagons (n_vertices=5) on an nx-by-ny grid, each horizontal and vertical neighbour
    pair in contact with a random kind and exponential normal force; one contact carries
    f_n = 0 (not force bearing) and particle 0 touches the bottom wall (f_n = 0.7 N)."""
    rng = np.random.default_rng(seed)
    a = 1.9 * R
    ix, iy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    ids = ix * ny + iy
    pos = np.stack([ix.ravel() * a, iy.ravel() * a], -1).astype(float)
    i = np.concatenate([ids[:-1, :].ravel(), ids[:, :-1].ravel()])
    j = np.concatenate([ids[1:, :].ravel(), ids[:, 1:].ravel()])
    normal = (pos[j] - pos[i]) / a
    c = i.size
    fn = rng.exponential(1.0, c)
    fn[3] = 0.0
    kind = rng.integers(1, 3, c)
    n = nx * ny
    contacts = dict(i=np.append(i, 0), j=np.append(j, n), kind=np.append(kind, 1),
                    normal=np.vstack([normal, [[0.0, -1.0]]]), fn=np.append(fn, 0.7), ft=np.zeros(c + 1),
                    branch=np.vstack([pos[j] - pos[i], [[0.0, -R]]]),
                    point=np.vstack([pos[i] + normal * R, [[0.0, -R]]]))
    angle = rng.uniform(0, 2 * np.pi, (1, n))
    return grainview.make_dataset(radius=np.full(n, R), position=pos, n_vertices=5, angle=angle,
                                  contacts=[contacts], box_min=[-R, -R], box_max=[(nx - 1) * a + R, (ny - 1) * a + R],
                                  n_walls=1, wall_names=["bottom"])


def legend_texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


# -- evolutions against eps_q -----------------------------------------------------------------

EVOLUTIONS = {
    "q_over_p": (gp.plot_q_over_p, {}, "$q/p$", lambda ds: [stress_invariants(ds)["q_over_p"]]),
    "eps_p": (gp.plot_volumetric_strain, {}, r"$\varepsilon_p$", lambda ds: [strains(ds)["eps_p"]]),
    "harmonic": (gp.plot_harmonic_prediction, {}, "$q/p$ and its predictions",
                 lambda ds: [harmonic_prediction(ds)[v] for v in ("q_over_p", "prediction", "prediction_cross_term")]),
    "partial_q": (gp.plot_partial_q_over_p, {}, "$q_s/p$, $q_d/p$, $q/p$",
                  lambda ds: [stress_invariants(ds, k)["q_over_p"] for k in ("simple", "double", "all")]),
    "z": (gp.plot_coordination, {}, "$z$", lambda ds: [coordination(ds)["z"]]),
    "a_prime": (gp.plot_fabric_anisotropy, {}, "$a'$", lambda ds: [fabric_anisotropy(ds)["a_prime"]]),
    "partial_a": (gp.plot_partial_fabric_anisotropy, {}, "$a'_s$, $a'_d$",
                  lambda ds: [fabric_anisotropy(ds, k)["a_prime"] for k in ("simple", "double")]),
    "a_n": (gp.plot_force_anisotropy, {"component": "a_n"}, "$a_n$", lambda ds: [force_anisotropies(ds)["a_n"]]),
    "a_t": (gp.plot_force_anisotropy, {"component": "a_t"}, "$a_t$", lambda ds: [force_anisotropies(ds)["a_t"]]),
}


@pytest.mark.parametrize("name", list(EVOLUTIONS))
def test_evolution_lines_hold_the_analysis_values(name, series, other_series):
    func, kw, ylabel, expected = EVOLUTIONS[name]
    ax = func({"pentagons": series, "disks": other_series}, **kw)
    per_sample = [expected(ds) for ds in (series, other_series)]
    n_curves = len(per_sample[0])
    assert len(ax.lines) == 2 * n_curves
    for s, ds in enumerate((series, other_series)):
        for k, want in enumerate(per_sample[s]):
            line = ax.lines[s * n_curves + k]
            np.testing.assert_allclose(line.get_xdata(), strains(ds)["eps_q"].values)
            np.testing.assert_allclose(line.get_ydata(), want.values, equal_nan=True)
        colours = {ax.lines[s * n_curves + k].get_color() for k in range(n_curves)}
        assert len(colours) == 1  # one colour per sample
    assert ax.lines[0].get_color() != ax.lines[n_curves].get_color()
    assert ax.get_xlabel() == r"$\varepsilon_q$" and ax.get_ylabel() == ylabel
    assert all(text.startswith(("pentagons", "disks")) for text in legend_texts(ax))
    assert len(legend_texts(ax)) == 2 * n_curves
    if 2 * n_curves > 3:  # a long legend sits beside the axes, over no curve
        assert ax.get_legend().get_bbox_to_anchor().transformed(ax.transAxes.inverted()).x0 >= 1.0


def test_q_over_p_of_a_square_lattice_is_the_hand_value():
    # 4 x 3 grid: 9 horizontal contacts of 2 N and 8 vertical of 5 N, all with branch 2R:
    # sigma_xx V = 9 * 2 * 2R, sigma_yy V = 8 * 5 * 2R, so q/p = (40 - 18)/(40 + 18).
    ax = gp.plot_q_over_p(builders.square_lattice(4, 3, fx=2.0, fy=5.0))
    np.testing.assert_allclose(ax.lines[0].get_ydata(), [22 / 58])
    np.testing.assert_allclose(ax.lines[0].get_xdata(), [0.0])
    assert ax.get_legend() is None  # one unlabelled sample: no legend


def test_successive_calls_on_one_axes_compare_samples(series, other_series):
    ax = gp.plot_q_over_p(series, label="pentagons")
    PlotAccessor(other_series).q_over_p(ax=ax, label="disks")
    assert len(ax.lines) == 2
    assert ax.lines[0].get_color() != ax.lines[1].get_color()
    assert legend_texts(ax) == ["pentagons", "disks"]
    np.testing.assert_allclose(ax.lines[1].get_ydata(), stress_invariants(other_series)["q_over_p"].values)


def test_stress_dilatancy_draws_psi_against_phi_in_rad(series):
    ax = gp.plot_stress_dilatancy([("a", series)], min_strain=0.0)
    angles = friction_and_dilatancy(series)
    np.testing.assert_allclose(ax.lines[0].get_xdata(), angles["phi"].values)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), angles["psi"].values, equal_nan=True)
    assert ax.get_xlabel() == r"$\varphi$ (rad)" and ax.get_ylabel() == r"$\psi$ (rad)"
    # Taylor's line phi = phi_0 + psi: slope 1, phi_0 the median offset of the points
    phi, psi = angles["phi"].values, angles["psi"].values
    ok = np.isfinite(phi) & np.isfinite(psi)
    x, y = ax.lines[1].get_xdata(), ax.lines[1].get_ydata()
    assert (y[1] - y[0]) / (x[1] - x[0]) == pytest.approx(1.0)
    assert x[0] - y[0] == pytest.approx(np.median(phi[ok] - psi[ok]))
    assert len(ax.lines) == 2  # no phi = psi line: it runs through the origin, off both paths
    ax = gp.plot_stress_dilatancy(series, incremental=True, min_strain=0.0)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), angles["psi_incremental"].values, equal_nan=True)


def test_stress_dilatancy_leaves_out_the_early_snapshots_and_labels_its_guides_as_guides(series):
    eps = strains(series)["eps_q"].values
    cut = float(np.sort(eps)[2]) + 1e-9  # the three smallest strains fall below it
    ax = gp.plot_stress_dilatancy({"pentagons": series}, min_strain=cut)
    angles = friction_and_dilatancy(series)
    y = ax.lines[0].get_ydata()
    assert np.isnan(y[eps < cut]).all() and (eps < cut).sum() == 3
    np.testing.assert_allclose(y[eps >= cut], angles["psi"].values[eps >= cut])
    # phi_0: the median of phi - psi over the snapshots drawn, the same number as the headline's
    phi, psi = angles["phi"].values[eps >= cut], angles["psi"].values[eps >= cut]
    phi_0 = float(np.median(phi - psi))
    assert series.grain.friction_offset(min_strain=cut) == pytest.approx(phi_0)
    x, g = ax.lines[1].get_xdata(), ax.lines[1].get_ydata()
    np.testing.assert_allclose(x - g, phi_0)
    assert "not a fit" in legend_texts(ax)[1] and f"{phi_0:.2f} rad" in legend_texts(ax)[1]
    # every point drawn lies within the axes (the early transient no longer sets the range)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for line in ax.lines:
        xs, ys = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        ok = np.isfinite(xs) & np.isfinite(ys)
        assert ((xs[ok] >= x0) & (xs[ok] <= x1) & (ys[ok] >= y0) & (ys[ok] <= y1)).all()
    assert any(f"< {cut:g}$ not drawn" in t.get_text() for t in ax.texts)  # the panel says so


def test_force_anisotropies_figure_has_a_n_and_a_t_panels(series):
    fig = gp.plot_force_anisotropies(series)
    assert len(fig.axes) == 2
    got = force_anisotropies(series)
    np.testing.assert_allclose(fig.axes[0].lines[0].get_ydata(), got["a_n"].values)
    np.testing.assert_allclose(fig.axes[1].lines[0].get_ydata(), got["a_t"].values)


# -- distributions ----------------------------------------------------------------------------

def test_residual_state_is_the_last_snapshots(series):
    eps = strains(series)["eps_q"].values
    # the synthetic series stops at eps_q ~0.14, short of the residual window eps_q >= 0.3:
    # the last 30% of its shear strain are used instead, and the figure is told so
    assert eps.max() < 0.3
    chosen = select_snapshots(series, "residual")
    kept = chosen["time"].values
    np.testing.assert_array_equal(kept, series["time"].values[eps >= 0.7 * eps.max()])
    assert 0 < kept.size < series.sizes["time"]
    assert "NOT reached" in chosen.attrs["window"]
    # a window the run reaches: eps_q >= 0.05
    reached = select_snapshots(series, "residual", residual_strain=0.05)
    np.testing.assert_array_equal(reached["time"].values, series["time"].values[eps >= 0.05])
    assert reached.attrs["window"].startswith("residual: eps_q >= 0.05")
    np.testing.assert_array_equal(select_snapshots(series, -1)["time"].values, series["time"].values[-1:])
    with pytest.raises(ParameterError, match="time"):
        select_snapshots(series, 7)


def test_connectivity_pdf_of_a_square_lattice():
    # 4 x 3 grid: 4 corners with 2 contacts, 6 border particles with 3, 2 interior with 4.
    ax = gp.plot_connectivity_pdf(builders.square_lattice(4, 3), max_c=6)
    np.testing.assert_allclose(ax.lines[0].get_xdata(), np.arange(1, 7))  # P(0) = 0 by definition: not drawn
    np.testing.assert_allclose(ax.lines[0].get_ydata(), [0, 4 / 12, 6 / 12, 2 / 12, 0, 0], atol=1e-15)
    assert ax.lines[0].get_linestyle() == "None"  # a discrete distribution: markers only
    assert ax.get_xlabel() == "$c$" and ax.get_ylabel() == "$P(c)$"


def test_connectivity_pdf_averages_the_residual_snapshots(series, other_series):
    ax = gp.plot_connectivity_pdf({"a": series, "b": other_series})
    assert len(ax.lines) == 2
    for line, ds in zip(ax.lines, (series, other_series)):
        want = connectivity_pdf(select_snapshots(ds, "residual")).mean("time").sel(c=slice(1, None))
        np.testing.assert_allclose(line.get_ydata(), want.values)


def test_orientation_pdf_polar_of_a_square_lattice():
    # 9 contacts at theta = 0 and 8 at pi/2; 4 sectors of width pi/4 centred on k pi/4.
    ax = gp.plot_orientation_pdf(builders.square_lattice(4, 3), bins=4, time=0)
    assert ax.name == "polar"
    line = ax.lines[0]
    p0, p2 = 9 / 17 / (np.pi / 4), 8 / 17 / (np.pi / 4)
    np.testing.assert_allclose(line.get_xdata(), np.arange(9) * np.pi / 4)
    np.testing.assert_allclose(line.get_ydata(), [p0, 0, p2, 0, p0, 0, p2, 0, p0], atol=1e-12)
    assert ax.get_xlabel() == r"$\theta$ (rad)"
    assert ax.get_title() == r"$P(\theta)$ (rad$^{-1}$)"


def test_orientation_pdf_of_series_matches_the_analysis(series):
    ax = gp.plot_orientation_pdf(series, bins=12)
    want = orientation_pdf(select_snapshots(series, "residual"), bins=12).mean("time").values
    np.testing.assert_allclose(ax.lines[0].get_ydata(), np.concatenate([want, want, want[:1]]))


def test_joint_connectivity_map_is_p_ms_md():
    # horizontal contacts double, vertical simple on the 4 x 3 grid: m_d is the number of
    # horizontal neighbours (1 or 2), m_s the vertical ones (1 or 2)
    kinds = [2] * 9 + [1] * 8
    ds = builders.square_lattice(4, 3, kinds=kinds)
    ax = gp.plot_joint_connectivity(ds, max_m=3, time=0)
    image = np.asarray(ax.images[0].get_array())
    want = joint_connectivity_pdf(ds, max_m=3).isel(time=0).values.T
    np.testing.assert_allclose(image, want)
    # corners: m_s = 1, m_d = 1 (4); top/bottom borders: m_s = 1, m_d = 2 (4);
    # left/right: m_s = 2, m_d = 1 (2); interior: m_s = 2, m_d = 2 (2)
    assert image[1, 1] == pytest.approx(4 / 12) and image[2, 1] == pytest.approx(4 / 12)
    assert image[1, 2] == pytest.approx(2 / 12) and image[2, 2] == pytest.approx(2 / 12)
    assert ax.get_xlabel() == "$m_s$" and ax.get_ylabel() == "$m_d$"
    with pytest.raises(ParameterError, match="one sample"):
        gp.plot_joint_connectivity({"a": ds, "b": ds})


def test_polar_forces_of_a_square_lattice():
    ds = builders.square_lattice(4, 3, fx=2.0, fy=5.0)
    mean = (9 * 2.0 + 8 * 5.0) / 17
    ax = gp.plot_normal_force_polar(ds, bins=4, time=0)
    np.testing.assert_allclose(ax.lines[0].get_ydata(),
                               [2 / mean, np.nan, 5 / mean, np.nan, 2 / mean, np.nan, 5 / mean, np.nan, 2 / mean])
    assert ax.get_title() == r"$\langle f_n\rangle(\theta)/\langle f_n\rangle$"
    ax = gp.plot_normal_force_polar(ds, bins=4, time=0, normalise=False)
    np.testing.assert_allclose(ax.lines[0].get_ydata()[[0, 2]], [2.0, 5.0])
    assert ax.get_title() == r"$\langle f_n\rangle(\theta)$ (N)"


def test_polar_tangential_force_is_its_magnitude():
    ds = builders.two_disks(force=3.0, tangential=-1.5)
    ax = gp.plot_tangential_force_polar(ds, bins=4, time=0)
    np.testing.assert_allclose(ax.lines[0].get_ydata()[[0, 4, 8]], [0.5, 0.5, 0.5])
    fig = gp.plot_angular_forces({"a": ds, "b": ds}, bins=4, time=0)
    assert len(fig.axes) == 2 and all(ax.name == "rectilinear" for ax in fig.axes)
    assert len(fig.axes[0].lines) == 3 and len(fig.axes[1].lines) == 3  # two samples and the line at 1 or 0
    assert [t.get_text() for ax in fig.axes for t in ax.texts] == ["(a)", "(b)"]
    with pytest.raises(ParameterError, match="polar"):
        gp.plot_tangential_force_polar(ds, ax=plt.subplots()[1])


def test_tangential_force_keeps_its_sign():
    ds = builders.two_disks(force=3.0, tangential=-1.5)
    ax = gp.plot_tangential_force(ds, bins=4, time=0)
    y = ax.lines[0].get_ydata()
    assert np.nanmin(y) == pytest.approx(-0.5) and np.all(np.isnan(y) | (y <= 0))
    assert ax.get_xlim() == pytest.approx((0.0, np.pi))


# -- maps -------------------------------------------------------------------------------------

def test_particles_are_drawn_as_regular_pentagons():
    ds = pentagon_grid()
    ax = gp.plot_particles(ds)
    polys = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(polys) == 1 and len(polys[0].get_paths()) == 20
    p = 7
    x, a = ds["position"].values[0, p], ds["angle"].values[0, p]
    phase = a + 2 * np.pi * np.arange(5) / 5
    want = x + R * np.stack([np.cos(phase), np.sin(phase)], -1)
    np.testing.assert_allclose(polys[0].get_paths()[p].vertices[:5], want)
    assert ax.get_xlabel() == "$x$ (m)" and ax.get_ylabel() == "$y$ (m)"


def test_disks_are_one_ellipse_collection_of_their_diameters():
    ax = gp.plot_particles(builders.square_lattice(4, 3))
    (disks,) = [c for c in ax.collections if isinstance(c, EllipseCollection)]
    np.testing.assert_allclose(disks.get_offsets(), builders.square_lattice(4, 3)["position"].values[0])
    np.testing.assert_allclose(disks._widths, np.full(12, R))  # matplotlib stores half widths


def test_force_chain_widths_are_proportional_to_fn():
    ds = pentagon_grid()
    ax = gp.plot_force_chains(ds, max_linewidth=4.0)
    lines = contact_collection(ax)
    c = int(ds["contact_count"][0])
    fn = ds["fn"].values[0, :c]
    n = ds.sizes["particle"]
    kept = (fn > 0) & (ds["j"].values[0, :c] < n)  # force-bearing particle pairs
    segments = np.asarray(lines.get_segments())
    assert len(segments) == kept.sum() == c - 2
    widths = np.asarray(lines.get_linewidths())
    np.testing.assert_allclose(widths, 4.0 * fn[kept] / fn[kept].max())
    pos = ds["position"].values[0]
    i, j = ds["i"].values[0, :c][kept], ds["j"].values[0, :c][kept]
    np.testing.assert_allclose(segments[:, 0], pos[i])
    np.testing.assert_allclose(segments[:, 1], pos[j])
    # with walls, the wall contact runs from particle 0 to its contact point
    ax = gp.plot_force_chains(ds, walls=True)
    segments = np.asarray(contact_collection(ax).get_segments())
    assert len(segments) == c - 1
    np.testing.assert_allclose(segments[-1], [pos[0], pos[0] + [0.0, -R]])


def test_kind_map_colours_simple_and_double_as_every_figure_does():
    ds = pentagon_grid()
    ax = gp.plot_contact_kinds(ds)
    lines = contact_collection(ax)
    c = int(ds["contact_count"][0])
    fn, kind = ds["fn"].values[0, :c], ds["kind"].values[0, :c]
    kept = (fn > 0) & (ds["j"].values[0, :c] < ds.sizes["particle"])
    colours = np.asarray(lines.get_colors())
    want = np.array([to_rgba(KIND_COLOURS[1]) if k == 1 else to_rgba(KIND_COLOURS[2]) for k in kind[kept]])
    np.testing.assert_allclose(colours, want)
    np.testing.assert_allclose(lines.get_linewidths(), 3.0 * fn[kept] / fn[kept].max())
    top, mean = fn[kept].max(), fn[kept].mean()
    names = {mean: r"mean $\langle f_n\rangle$", top / 2: "half the widest", top: "widest line"}
    assert legend_texts(ax) == ["simple (s)", "double (d)", *(f"{per_metre(f)}: {names[f]}" for f in sorted(names))]


def test_map_legends_sit_beside_the_packing_with_a_key_of_line_widths_per_metre():
    ds = pentagon_grid()
    ax = gp.plot_force_chains(ds, max_linewidth=4.0)
    c = int(ds["contact_count"][0])
    fn = ds["fn"].values[0, :c]
    fn = fn[(fn > 0) & (ds["j"].values[0, :c] < ds.sizes["particle"])]
    legend = ax.get_legend()
    handles = legend.legend_handles
    forces = sorted({fn.mean(), fn.max() / 2, fn.max()})
    # each sample width says which force it is, the thinnest the mean, in the unit its title names
    assert legend_texts(ax) == [f"{per_metre(fn.mean())}: mean " + r"$\langle f_n\rangle$",
                                f"{per_metre(fn.max() / 2)}: half the widest", f"{per_metre(fn.max())}: widest line"]
    assert all(" N/m: " in text for text in legend_texts(ax))
    assert fn.mean() < fn.max() / 2  # the order above is the order of the forces
    assert legend.get_title().get_text().endswith("(forces per m of thickness, N/m)")
    assert newtons(1376.4) == "1376 N" and newtons(0.01234) == "0.0123 N" and newtons(3.6) == "3.6 N"
    assert newtons(1.4) != newtons(1.2)
    # a file's forces act on its slab: per metre, a 0.1 m slab's 137.64 N is 1376.4 N/m
    assert per_metre(1376.4) == "1376 N/m" and per_metre(137.64, 0.1) == "1376 N/m"
    thin = gp.plot_force_chains(ds.assign_attrs(thickness_m=0.5), max_linewidth=4.0)
    assert legend_texts(thin)[-1] == f"{per_metre(2 * fn.max())}: widest line"
    from grainview.app.report import common_force_scale  # Fig. 13's scale line, in the same unit

    assert common_force_scale({"a": ds}, time=0) == (
        fn.max(), f"line widths on one scale for a: the widest line is {per_metre(fn.max())} (forces per m of "
                  "thickness, N/m)")
    np.testing.assert_allclose([h.get_linewidth() for h in handles], [4.0 * f / fn.max() for f in forces])
    anchor = legend.get_bbox_to_anchor().transformed(ax.transAxes.inverted())
    assert anchor.x0 >= 1.0  # outside the axes: it covers no particle


def test_map_takes_one_sample_and_one_snapshot(series):
    with pytest.raises(ParameterError, match="one sample"):
        gp.plot_force_chains([("a", series), ("b", series)])
    with pytest.raises(ParameterError, match="time"):
        gp.plot_force_chains(series, time=10)
    ax = gp.plot_force_chains(series, time=1, particles=False)
    assert len(contact_collection(ax).get_segments()) == int(series["contact_count"][1])
    assert not any(isinstance(c, (PolyCollection, EllipseCollection)) for c in ax.collections)


# -- figures of the force-network modules -----------------------------------------------------

def test_tricolor_map_colours_match_force_classes():
    force_networks = pytest.importorskip("grainview.analysis.force_networks")
    ds = pentagon_grid(seed=2)
    ax = gp.plot_force_classes(ds)
    classes = force_networks.force_class(ds).values[0]
    c = int(ds["contact_count"][0])
    particle_pairs = ds["j"].values[0, :c] < ds.sizes["particle"]
    labels = classes[:c][particle_pairs]
    colours = [tuple(col) for col in np.asarray(contact_collection(ax).get_colors())]
    for code in (1, 2, 3):
        assert colours.count(to_rgba(CLASS_COLOURS[code])) == np.count_nonzero(labels == code)
    assert len(set(CLASS_COLOURS.values())) == 3
    assert len(colours) == np.count_nonzero(labels > 0)
    assert legend_texts(ax) == [r"very weak, $f_n < 0.1\langle f_n\rangle$",
                                r"weak, $0.1\langle f_n\rangle \leq f_n \leq 1\langle f_n\rangle$",
                                r"strong, $f_n > 1\langle f_n\rangle$"]  # the thresholds are stated
    ax = gp.plot_force_classes(ds, very_weak=0.05, strong=1.5)
    assert legend_texts(ax)[0].endswith(r"$f_n < 0.05\langle f_n\rangle$")
    assert legend_texts(ax)[2].endswith(r"$f_n > 1.5\langle f_n\rangle$")


def test_force_pdf_log_linear_with_exponential_fit(series, other_series):
    force_pdf = pytest.importorskip("grainview.analysis.force_pdf")
    ax = gp.plot_force_pdf({"a": series, "b": other_series}, bins=30)
    assert len(ax.lines) == 4  # pdf and fit per sample
    want = force_pdf.pooled_force_pdf(select_snapshots(series, "residual"), bins=30, scale="linear",
                                      range=(0.0, 6.0))
    p = want["pdf"].values if "time" not in want["pdf"].dims else want["pdf"].mean("time").values
    keep = p > 0
    np.testing.assert_allclose(ax.lines[0].get_ydata(), p[keep])
    np.testing.assert_allclose(ax.lines[0].get_xdata(), want["f_over_mean"].values[keep])
    # counting error bars: sigma = P / sqrt(n); a bin of one contact gets no lower bar
    bars = [c for c in ax.collections if c.get_segments()][0].get_segments()
    lower, upper = np.array([seg[0][1] for seg in bars]), np.array([seg[1][1] for seg in bars])
    n = want["count"].values[keep]
    np.testing.assert_allclose(upper, p[keep] * (1 + 1 / np.sqrt(n)))
    np.testing.assert_allclose(lower, np.where(n > 1, p[keep] * (1 - 1 / np.sqrt(n)), p[keep]))
    assert (n == 1).any() and (n > 1).any()  # both kinds of bin are exercised
    alpha = float(force_pdf.strong_force_exponent(want))
    x, y = ax.lines[1].get_xdata(), ax.lines[1].get_ydata()
    assert (x > 1).all()
    assert x.max() <= want["f_over_mean"].values[keep].max()  # never drawn past the data
    np.testing.assert_allclose(np.diff(np.log(y)) / np.diff(x), -alpha)  # exp(-alpha x)
    assert f"{alpha:.2f}" in legend_texts(ax)[1]
    assert ax.get_yscale() == "log" and ax.get_xscale() == "linear"
    assert ax.get_xlabel() == r"$f_n/\langle f_n\rangle$" and ax.get_ylabel() == "$P$"


def test_force_pdf_figures_log_log_and_per_kind(series):
    pytest.importorskip("grainview.analysis.force_pdf")
    fig = gp.plot_force_pdfs(series, bins=20)
    assert [a.get_xscale() for a in fig.axes] == ["linear", "log"]
    assert len(fig.axes[1].lines) == 1  # no fit in log-log
    fig = gp.plot_force_pdfs_by_kind({"a": series}, bins=20)
    ax = fig.axes[0]
    assert len(ax.lines) == 2 and legend_texts(ax) == ["a, s", "a, d"]
    from grainview.analysis.force_pdf import pooled_force_pdf
    want = pooled_force_pdf(select_snapshots(series, "residual"), bins=20, scale="linear", range=(0.0, 6.0),
                            kind="double")
    p = want["pdf"].values if "time" not in want["pdf"].dims else want["pdf"].mean("time").values
    np.testing.assert_allclose(ax.lines[1].get_ydata(), p[p > 0])


@pytest.mark.parametrize("func, name, ylabel", [(gp.plot_xi_stress, "q_over_p", r"$q(\xi)/p$"),
                                                 (gp.plot_xi_anisotropy, "a_prime", r"$a'(\xi)$")])
def test_xi_network_curves(series, func, name, ylabel):
    xi_network = pytest.importorskip("grainview.analysis.xi_network")
    xi = np.array([0.5, 1.0, 2.0, 4.0])
    ax = func(series, xi=xi)
    want = xi_network.xi_network(select_snapshots(series, "residual"), xi=xi)[name].mean("time")
    np.testing.assert_allclose(ax.lines[0].get_xdata(), xi)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), want.values, equal_nan=True)
    assert ax.get_xlabel() == r"$\xi$" and ax.get_ylabel() == ylabel
    # cutoffs whose network is too small to mean anything are left out
    count = xi_network.xi_network(select_snapshots(series, "residual"), xi=xi)["count"].mean("time").values
    threshold = count[1] + 0.5
    ax = func(series, xi=xi, min_contacts=threshold)
    np.testing.assert_allclose(ax.lines[0].get_xdata(), xi[count >= threshold])


def test_proportion_curves(series):
    force_networks = pytest.importorskip("grainview.analysis.force_networks")
    want = force_networks.contact_proportions(series)
    ax = gp.plot_contact_proportions(series)
    assert len(ax.lines) == 4
    for line, name in zip(ax.lines, ["k_s", "k_d", "f_s", "f_d"]):
        np.testing.assert_allclose(line.get_ydata(), want[name].values)
        np.testing.assert_allclose(line.get_xdata(), strains(series)["eps_q"].values)
    # Fig. 25: the strong network in (a), the weak one in (b), s against d in each
    fig = gp.plot_strong_weak_proportions(series)
    for ax, names in zip(fig.axes, (["k_s_strong", "k_d_strong"], ["k_s_weak", "k_d_weak"])):
        assert len(ax.lines) == 2
        for line, name in zip(ax.lines, names):
            np.testing.assert_allclose(line.get_ydata(), want[name].values)
    assert [ax.get_ylabel().split(",")[1].split()[0] for ax in fig.axes] == ["strong", "weak"]
    with pytest.raises(ParameterError, match="network"):
        gp.plot_strong_weak_proportion(series, network="medium")


def test_persistence_and_transitions():
    persistence = pytest.importorskip("grainview.analysis.persistence")
    ds = builders.mixed_contacts(seed=1, t=3)  # random pairs and kinds: gamma falls below 1
    ax = gp.plot_persistence({"mixed": ds})
    gamma = persistence.persistence(ds).values
    np.testing.assert_allclose(ax.lines[0].get_ydata(), gamma)
    assert gamma[0] == 1.0 and gamma[-1] < 1.0
    assert ax.get_ylabel() == r"$\gamma$: share of the first snapshot's contacts present"
    ax = gp.plot_type_transitions(ds)
    want = persistence.type_transitions(ds)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), want["delta_gamma_s_to_d"].values)
    np.testing.assert_allclose(ax.lines[1].get_ydata(), want["delta_gamma_d_to_s"].values)
    np.testing.assert_allclose(ax.lines[1].get_xdata(), strains(ds)["eps_q"].values)
    assert ax.get_ylabel() == r"$\Delta\gamma$"


# -- accessor and saving ----------------------------------------------------------------------

def test_accessor_has_a_method_for_every_figure(series):
    acc = PlotAccessor(series)
    for func in gp.FIGURES.values():
        name = func.__name__.removeprefix("plot_")
        assert getattr(type(acc), name).__wrapped__ is func
    ax = acc.fabric_anisotropy()
    np.testing.assert_allclose(ax.lines[0].get_ydata(), fabric_anisotropy(series)["a_prime"].values)

    # the dataset accessor exposes the same figures as ds.grain.plot
    ax = series.grain.plot.q_over_p()
    np.testing.assert_allclose(ax.lines[0].get_ydata(), stress_invariants(series)["q_over_p"].values)


def test_the_accessors_list_only_their_user_facing_names(series):
    from grainview.accessor import GrainAccessor, _Delegate

    analyses = {name for name, value in vars(GrainAccessor).items() if isinstance(value, _Delegate)}
    assert {"stress_invariants", "force_chains", "coarse_grained"} <= analyses
    assert dir(series.grain) == sorted(analyses | {"validate", "plot"})
    assert "STRAIN_COORDS" not in dir(series.grain) and not any(n.startswith("_") for n in dir(series.grain))
    figures = {name for name, value in vars(PlotAccessor).items() if getattr(value, "__wrapped__", None)}
    assert {f.__name__.removeprefix("plot_") for f in gp.FIGURES.values()} <= figures
    assert dir(series.grain.plot) == sorted(figures)
    # the strains still come back as coordinates of the time series
    assert {"eps_1", "eps_p", "eps_q"} <= set(series.grain.stress_invariants().coords)
    # the docstring speaks of ds.grain.plot as it is, not as a plan
    assert "once" not in PlotAccessor.__doc__ and "ds.grain.plot.q_over_p(" in PlotAccessor.__doc__


def test_save_figure_writes_png_and_pdf(tmp_path, series):
    ax = gp.plot_q_over_p(series)
    paths = save_figure(ax.figure, tmp_path / "figs" / "fig03")
    assert [p.name for p in paths] == ["fig03.png", "fig03.pdf"]
    assert paths[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert paths[1].read_bytes()[:5] == b"%PDF-"
    paths = save_figure(ax, tmp_path / "fig03b.png")  # axes accepted, suffix replaced
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)


def test_bad_data_argument_is_a_parameter_error(series):
    with pytest.raises(ParameterError, match="data"):
        gp.plot_q_over_p([series])
    with pytest.raises(ParameterError, match="component"):
        gp.plot_force_anisotropy(series, component="a_x")


def test_dask_backed_dataset_draws_the_same_numbers(series):
    lazy = series.chunk({"time": 1})
    eager_ax = gp.plot_orientation_pdf(series, bins=12)
    lazy_ax = gp.plot_orientation_pdf(lazy, bins=12)
    np.testing.assert_allclose(lazy_ax.lines[0].get_ydata(), eager_ax.lines[0].get_ydata())
    ax = gp.plot_harmonic_prediction(lazy)
    np.testing.assert_allclose(ax.lines[1].get_ydata(), harmonic_prediction(series)["prediction"].values)
    ax = gp.plot_force_chains(lazy, particles=False)
    assert len(contact_collection(ax).get_segments()) == int(series["contact_count"][-1])


def _with_near_pairs(ds, near_m=1e-3, n_near=40, seed=5):
    """``ds`` with ``n_near`` of its contacts per snapshot turned into unloaded near pairs
    (f_n = f_t = 0, gap 0.5 near_m, normals along x) and the others touching (gap 0), and the
    file's attribute saying pairs within ``near_m`` are written."""
    rng = np.random.default_rng(seed)
    ds = ds.copy(deep=True)
    count = ds["contact_count"].values
    fn, ft, normal = ds["fn"].values, ds["ft"].values, ds["normal"].values
    gap = np.where(np.arange(fn.shape[1])[None, :] < count[:, None], 0.0, np.nan)
    for k in range(fn.shape[0]):
        pick = rng.choice(count[k], n_near, replace=False)
        fn[k, pick] = ft[k, pick] = 0.0
        normal[k, pick] = (1.0, 0.0)
        gap[k, pick] = 0.5 * near_m
    ds["fn"].values, ds["ft"].values, ds["normal"].values = fn, ft, normal
    ds["gap"] = (("time", "contact"), gap, {"units": "m"})
    ds.attrs["near_contacts_m"] = near_m
    return ds


def test_xi_anisotropy_counts_near_pairs_when_asked_and_draws_the_papers_inset_as_a_panel(series):
    from grainview.analysis.xi_network import xi_network

    near = _with_near_pairs(series)
    xi = np.array([0.1, 0.5, 1.0, 2.0])
    ax = gp.plot_xi_anisotropy(near, xi=xi, near=1e-3, min_contacts=0)
    want = xi_network(select_snapshots(near, "residual"), xi=xi, near=1e-3)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), want["a_prime"].mean("time").values)
    force_bearing = xi_network(select_snapshots(near, "residual"), xi=xi)["a_prime"].mean("time").values
    assert not np.allclose(want["a_prime"].mean("time").values, force_bearing)  # the pairs change a'(xi)
    # the paper's inset is panel (b): the weak forces on a log axis, labelled, hiding nothing of (a)
    fig = gp.plot_xi_anisotropies(near, xi=xi, near=1e-3, min_contacts=0)
    whole, weak = fig.axes
    assert not whole.child_axes
    np.testing.assert_allclose(whole.lines[0].get_ydata(), want["a_prime"].mean("time").values)
    assert weak.get_xscale() == "log" and weak.get_xlim()[0] < 0.011 and weak.get_xlim()[1] > 0.9
    np.testing.assert_allclose(weak.lines[0].get_xdata(), gp.forces.WEAK_XI)
    assert weak.get_xlabel() == r"$\xi$" and weak.get_ylabel() == r"$a'(\xi)$"


def test_the_report_counts_near_pairs_in_fig16_only_when_every_file_holds_them(series):
    from grainview.app.report import NEAR_FRACTION, xi_contacts

    near = _with_near_pairs(series, near_m=1.0)
    gap, line = xi_contacts({"a": near, "b": near})
    assert gap == pytest.approx(NEAR_FRACTION * 2 * float(series["radius"].min()))
    assert f"pairs within {gap * 1e3:.2g} mm" in line
    gap, line = xi_contacts({"a": near, "b": series})  # one file without near pairs: none counted
    assert gap is None and "force-bearing only" in line


# -- one palette, layouts, captions (the report's figures as a reader sees them) --------------

@pytest.fixture(scope="module")
def pentagons(other_series):
    """The second synthetic series with pentagons for particles (its contacts unchanged)."""
    return other_series.assign(n_vertices=other_series["n_vertices"] * 0 + 5)


def test_one_palette_pentagons_blue_disks_orange_whatever_the_order(series, pentagons):
    from grainview.plot._style import PALETTE

    blue, orange = to_rgba(PALETTE["pentagons"]), to_rgba(PALETTE["disks"])
    assert blue != orange
    for runs in ({"pentagons": pentagons, "disks": series}, {"disks": series, "pentagons": pentagons}):
        want = [blue if label == "pentagons" else orange for label in runs]
        drawn = {"q/p": gp.plot_q_over_p(runs).lines[:2], "P(c)": gp.plot_connectivity_pdf(runs).lines[:2],
                 "P(theta)": gp.plot_orientation_pdf(runs).lines[:2], "q(xi)": gp.plot_xi_stress(runs).lines[:2],
                 "<f_n>(theta)": gp.plot_angular_forces(runs).axes[0].lines[:2],
                 "pdf": gp.plot_force_pdf(runs).lines[0::2],  # the pdf of each sample, then its fit
                 "phi, psi": gp.plot_stress_dilatancy(runs, min_strain=0.0).lines[0::2]}
        for name, lines in drawn.items():
            assert [to_rgba(line.get_color()) for line in lines] == want, name
    # the ensemble figures: the groups come sorted ("disk" first), the colours stay with the shapes
    import xarray as xr

    from grainview.plot.ensemble import seed_bands
    stats = xr.Dataset({"mean": (("group", "eps_q_bin"), [[0.2, 0.3], [0.4, 0.5]]),
                        "std": (("group", "eps_q_bin"), [[0.01, 0.02], [0.01, 0.02]]),
                        "n": (("group", "eps_q_bin"), [[3, 3], [3, 3]])},
                       coords={"group": ["disk", "pentagon"], "eps_q_bin": [0.1, 0.2]})
    ax = seed_bands(stats, label="q/p")
    assert [to_rgba(line.get_color()) for line in ax.lines] == [orange, blue]
    # a second sample of one shape gets a colour of neither shape nor contact kind
    ax = gp.plot_q_over_p({"a": series, "b": series})
    second = to_rgba(ax.lines[1].get_color())
    assert second not in {to_rgba(c) for c in PALETTE.values()}


def test_contact_kinds_have_their_own_colours_in_every_figure(pentagons):
    from grainview.plot._style import PALETTE

    simple, double, every = (to_rgba(PALETTE[k]) for k in ("simple", "double", "all"))
    samples = {to_rgba(PALETTE["pentagons"]), to_rgba(PALETTE["disks"])}
    assert not {simple, double, every} & samples  # orange means disks, never double contacts
    colours = {
        "18": gp.plot_partial_q_over_p(pentagons).lines,
        "19": gp.plot_contact_proportions(pentagons).lines,
        "22": gp.plot_partial_fabric_anisotropy(pentagons).lines,
        "23": gp.plot_force_pdfs_by_kind(pentagons).axes[0].lines,
        "25a": gp.plot_strong_weak_proportions(pentagons).axes[0].lines,
    }
    want = {"18": [simple, double, every], "19": [simple, double, simple, double], "22": [simple, double],
            "23": [simple, double], "25a": [simple, double]}
    for name, lines in colours.items():
        assert [to_rgba(line.get_color()) for line in lines] == want[name], name
    assert [to_rgba(c) for c in (KIND_COLOURS[1], KIND_COLOURS[2])] == [simple, double]  # Fig. 24's map


@pytest.mark.parametrize("func", [gp.plot_force_pdfs, gp.plot_force_pdfs_by_kind, gp.plot_angular_forces,
                                  gp.plot_xi_anisotropies, gp.plot_strong_weak_proportions,
                                  gp.plot_force_anisotropies])
def test_two_panel_figures_have_panels_of_equal_width(func, series, pentagons):
    fig = func({"pentagons": pentagons, "disks": series})
    fig.canvas.draw()
    widths = [ax.get_position().width for ax in fig.axes]
    assert len(widths) == 2 and widths[0] == pytest.approx(widths[1], rel=0.01)
    for ax in fig.axes:  # no legend beside a panel, in the space of the panels' layout
        if ax.get_legend() is not None:
            frame, box = ax.get_window_extent(), ax.get_legend().get_window_extent()
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1


def test_a_note_in_a_panel_stays_inside_its_frame(series, pentagons):
    # a narrow range leaves many contacts outside it: the note names both samples
    runs = {"pentagons (S1-like)": pentagons, "disks (S2-like)": series}
    ax = gp.plot_force_pdfs(runs, range=(0.5, 2.0)).axes[1]  # the log-log panel of Fig. 14
    (note,) = [t for t in ax.texts if t.get_text().startswith("outside")]
    assert all(label in note.get_text() for label in runs)
    ax.figure.canvas.draw()
    frame, box = ax.get_window_extent(), note.get_window_extent()
    assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1


def test_angular_forces_share_theta_ticks_and_one_y_scale(series, pentagons):
    fig = gp.plot_angular_forces({"pentagons": pentagons, "disks": series})
    normal, tangential = fig.axes
    assert normal.get_xlim() == tangential.get_xlim() == pytest.approx((0.0, np.pi))
    labels = [[t.get_text() for t in ax.get_xticklabels()] for ax in fig.axes]
    assert labels[0] == labels[1] == ["0", r"$\pi/4$", r"$\pi/2$", r"$3\pi/4$", r"$\pi$"]
    assert np.diff(normal.get_ylim()) == pytest.approx(np.diff(tangential.get_ylim()))
    for ax in fig.axes:  # the data inside the limits
        lo, hi = ax.get_ylim()
        for line in ax.lines[:2]:
            y = np.asarray(line.get_ydata(), float)
            assert ((y[np.isfinite(y)] >= lo) & (y[np.isfinite(y)] <= hi)).all()
    assert tangential.get_legend() is None and normal.get_legend() is not None


def test_a_tall_map_is_saved_without_a_blank_margin_on_its_left(tmp_path):
    import matplotlib.image

    from grainview.plot._style import add_caption

    ds = builders.square_lattice(2, 12)  # a box six times taller than wide
    for name, func in (("particles", gp.plot_particles), ("chains", gp.plot_force_chains),
                       ("kinds", gp.plot_contact_kinds), ("classes", gp.plot_force_classes)):
        ax = func(ds)
        add_caption(ax.figure, ["a caption line, long enough to be wider than the map itself, as the report's are"])
        (png, _) = save_figure(ax.figure, tmp_path / name)
        image = matplotlib.image.imread(png)
        ink = (image[..., :3] < 0.9).any(axis=2)
        upper = ink[: ink.shape[0] // 2]  # the map, above the caption
        first = np.flatnonzero(upper.any(axis=0))[0]
        assert first / ink.shape[1] < 0.1, name  # the y label starts the image, not blank paper


def test_every_report_figure_says_what_it_plots_in_readable_type(series):
    from grainview.plot._style import CAPTION_FONTSIZE, add_caption
    from grainview.plot.captions import describe_figure

    for number in gp.FIGURES:
        assert len(describe_figure(number)) > 40, number
    assert CAPTION_FONTSIZE >= 8
    ax = gp.plot_q_over_p(series)
    add_caption(ax.figure, [describe_figure("03"), "provenance"])
    (text,) = ax.figure.texts
    assert text.get_fontsize() == CAPTION_FONTSIZE and text.get_text().startswith("Shear stress ratio q/p")


def test_the_strain_captions_name_eps_q_as_the_net_strain_and_say_where_it_decreases(series):
    from grainview.plot.captions import STRAIN_FIGURES, describe_figure, strain_note

    assert "against the shear strain eps_q = eps_1 - eps_2 since the first snapshot" in describe_figure("03")
    assert "it decreases where the sample narrows faster than it shortens" in describe_figure("03")
    assert {"03", "04", "20"} <= set(STRAIN_FIGURES) and "13" not in STRAIN_FIGURES
    assert strain_note("s", series) == ""  # the synthetic box shortens and widens: eps_q only grows
    # the last snapshot back to the first width: eps_2 = 0 there, so eps_q = eps_1 = ln(1 + 0.1)
    box_max = series["box_max"].values.copy()
    box_max[3, 0] = box_max[0, 0]
    narrowed = series.assign(box_max=(series["box_max"].dims, box_max))
    h, w = box_max[:, 1], box_max[:, 0]
    before = np.log(1 + (h[0] - h[2]) / h[0]) - np.log(1 + (w[0] - w[2]) / w[0])
    after = np.log(1 + (h[0] - h[3]) / h[0])
    assert after == pytest.approx(np.log(1.1)) and after < before
    assert strain_note("s", narrowed) == (
        f"s: eps_q decreases from one snapshot to the next, most from {before:.4f} to {after:.4f} (the sample narrowed "
        "faster than it shortened; eps_q is the net shear strain, not a path length), so curves against eps_q fold "
        "back there")
    assert "from 0.0984 to 0.0953" in strain_note("s", narrowed)
    # widened a lot, then narrowed twice: eps_q falls from snapshot 1 to 2 and from 2 to 3
    box_max = series["box_max"].values.copy()
    box_max[1:, 0] = [1.1, box_max[0, 0], 0.9]
    twice = series.assign(box_max=(series["box_max"].dims, box_max))
    assert (np.diff(strains(twice)["eps_q"].values) < 0).tolist() == [False, True, True]
    assert strain_note("s", twice).startswith("s: eps_q decreases between 2 pairs of successive snapshots, most from ")


def test_pooled_contacts_counts_different_pairs(series):
    from grainview.analysis.persistence import pooled_contacts
    from grainview.plot.captions import sampling_note

    # the synthetic series keeps the same 300 pairs in every snapshot: 300 different contacts
    assert pooled_contacts(series) == (300, 300.0)
    # random pairs: counted again by hand with a set of (min, max) pairs
    ds = builders.mixed_contacts(seed=2, t=4)
    n = ds.sizes["particle"]
    pairs, counts = set(), []
    for k in range(ds.sizes["time"]):
        c = int(ds["contact_count"][k])
        i, j, fn = ds["i"].values[k, :c], ds["j"].values[k, :c], ds["fn"].values[k, :c]
        keep = (fn > 0) & (j < n) & (i < n)
        pairs |= {(min(a, b), max(a, b)) for a, b in zip(i[keep], j[keep])}
        counts.append(int(keep.sum()))
    distinct, per_snapshot = pooled_contacts(ds)
    assert distinct == len(pairs) > max(counts) and per_snapshot == pytest.approx(np.mean(counts))
    assert "300 different contacts (1.0 times the 300 of one)" in sampling_note("s", series, residual_strain=0.0)


def test_the_transition_caption_gives_the_snapshot_interval(series):
    from grainview.plot.captions import interval_note

    # the synthetic series: snapshots at t = 0, 1, 2, 3 s, eps_q from strains()
    d_eps = float(np.median(np.diff(strains(series)["eps_q"].values)))
    note = interval_note("s", series)
    assert note.startswith(f"s: snapshots every 1 s, d eps_q = {d_eps:.2g};")
    every = series.assign_attrs(snapshot_every=200)
    assert "every 1 s (200 time steps)" in interval_note("s", every)


def test_the_headline_phi_0_is_fig5s_and_says_when_the_run_is_too_short(series):
    from grainview.analysis.strain import friction_offset
    from grainview.app.report import NOT_REACHED, PHI_0_ROW, run_summary

    angles = friction_and_dilatancy(series)
    eps = strains(series)["eps_q"].values
    kept = eps >= 0.02  # the first snapshot (eps_q = 0) is left out
    want = float(np.median(angles["phi"].values[kept] - angles["psi"].values[kept]))
    assert run_summary(series)[PHI_0_ROW] == pytest.approx(want) == friction_offset(series)
    assert np.isnan(friction_offset(series, min_strain=1.0))
    short = series.isel(time=[0])  # eps_q = 0 only: no phi_0, and the row says why
    assert run_summary(short)[PHI_0_ROW] == f"{NOT_REACHED}: eps_q < 0.02 throughout"
