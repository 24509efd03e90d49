"""Shear bands: profiles along any direction by hand, and the band finder on hand-made velocity
fields with a known inclined band (simple shear localised in a strip), on a uniform shear (no
band) and through coarse_grained's shear rate."""

import numpy as np
import pytest
import xarray as xr

from grainview.analysis.coarse_graining import profile, scalar_field
from grainview.contract.errors import ParameterError
from grainview.analysis.shear_bands import find_shear_band, profile_along

H = 0.01  # grid spacing of the hand-made fields, m
GRID = np.round(np.arange(0.0, 1.0 + H / 2, H), 12)
CENTRE = np.array([0.5, 0.45])


def band_velocity(angle, width, rate_in, rate_out=0.0, grid=GRID):
    """The velocity field (y, x, xy) of a simple shear along lines at ``angle`` (deg), localised in
    the strip |s - s_c| <= width/2 about the line through CENTRE: v = t (rate_out s' + rate_in
    clip(s', -width/2, width/2)), s' = s - s_c, t = (cos, sin)(angle). Its shear rate is
    rate_in + rate_out inside the strip, rate_out outside."""
    t = np.radians(angle)
    X, Y = np.meshgrid(grid, grid)
    s = -(X - CENTRE[0]) * np.sin(t) + (Y - CENTRE[1]) * np.cos(t)  # across the lines, from CENTRE
    speed = rate_out * s + rate_in * np.clip(s, -width / 2, width / 2)
    v = np.stack([speed * np.cos(t), speed * np.sin(t)], axis=-1)
    return xr.Dataset({"velocity": (("y", "x", "xy"), v)}, coords={"x": grid, "y": grid, "xy": ["x", "y"]})


def rate_of(fields):
    return scalar_field(fields, "shear_rate")


# -- profiles along a direction ----------------------------------------------------------------

def test_profile_along_the_axes_is_the_axis_profile():
    rng = np.random.default_rng(1)
    field = xr.DataArray(rng.uniform(size=(2, 5, 7)), dims=("time", "y", "x"),
                         coords={"x": np.arange(7) * 0.1, "y": np.arange(5) * 0.1}, attrs={"units": "Pa"})
    field[0, 2, 3] = np.nan
    along_x = profile_along(field, 0.0)  # lines along x: the profile across y
    np.testing.assert_allclose(along_x.values, profile(field, "y").values)
    np.testing.assert_allclose(along_x["s"].values, field["y"].values, atol=1e-12)
    along_y = profile_along(field, 90.0)  # s = -x
    np.testing.assert_allclose(along_y.values, profile(field, "x").values[:, ::-1])
    np.testing.assert_allclose(along_y["s"].values, -field["x"].values[::-1], atol=1e-12)
    assert along_y.attrs["units"] == "Pa" and along_y["s"].attrs["units"] == "m"


def test_profile_along_the_diagonal_by_hand():
    """3 x 3 nodes 1 m apart, lines at 45 deg, bins of h = sqrt(2)/2: s = (y - x)/sqrt(2), so
    the bins k = y - x = -2..2 average the diagonals of the grid."""
    g = np.arange(9.0).reshape(3, 3)  # g[y, x]
    field = xr.DataArray(g, dims=("y", "x"), coords={"x": [0.0, 1.0, 2.0], "y": [0.0, 1.0, 2.0]})
    out = profile_along(field, 45.0, bin_width=np.sqrt(2) / 2)
    # k = y - x: -2 -> g[0,2]=2; -1 -> g[0,1], g[1,2] = 1, 5; 0 -> 0, 4, 8; 1 -> 3, 7; 2 -> 6
    np.testing.assert_allclose(out.values, [2.0, 3.0, 4.0, 5.0, 6.0])
    np.testing.assert_allclose(out["s"].values, np.arange(-2, 3) * np.sqrt(2) / 2)
    inside = field > 0.5  # leaves g = 0 out
    np.testing.assert_allclose(profile_along(field, 45.0, inside=inside, bin_width=np.sqrt(2) / 2).values,
                               [2.0, 3.0, 6.0, 5.0, 6.0])


def test_profile_along_is_lazy_on_dask():
    da = pytest.importorskip("dask.array")
    field = xr.DataArray(da.ones((4, 6, 8), chunks=(1, 6, 8)), dims=("time", "y", "x"),
                         coords={"x": np.arange(8) * 0.1, "y": np.arange(6) * 0.1})
    out = profile_along(field, 30.0)
    assert out.chunks is not None
    np.testing.assert_allclose(out.compute().values[np.isfinite(out.values)], 1.0)


# -- the band finder -----------------------------------------------------------------------

@pytest.mark.parametrize("angle", [30.0, 50.0, 130.0])
def test_a_localised_simple_shear_is_found_at_its_angle_and_width(angle):
    """A strip 0.12 m wide shearing at 5 s-1 in a sample shearing at 1 s-1: found at its angle
    (within the 1-degree search step) and offset, its width at half maximum within a grid cell;
    share and contrast those of the nodes in the strip, counted directly."""
    width = 0.12
    rate = rate_of(band_velocity(angle, width, rate_in=4.0, rate_out=1.0))
    inside = (rate.x >= 0.05) & (rate.x <= 0.95) & (rate.y >= 0.05) & (rate.y <= 0.95)  # off the one-sided edges
    band = find_shear_band(rate, inside=inside, width=width)
    assert bool(band.found)
    assert abs(float(band.angle) - angle) <= 1.0
    t = np.radians(angle)
    expected_offset = -CENTRE[0] * np.sin(t) + CENTRE[1] * np.cos(t)  # the centre line's distance from the origin
    assert abs(float(band.offset) - expected_offset) <= H
    assert abs(float(band.fwhm) - width) <= H
    np.testing.assert_allclose(band.edges.values, expected_offset + np.array([-width, width]) / 2, atol=H)
    # the strip's share and contrast, counted on the nodes of the exact band
    X, Y = np.meshgrid(GRID, GRID)
    in_band = np.abs(-X * np.sin(t) + Y * np.cos(t) - expected_offset) <= width / 2
    ok = inside.values
    exact = np.where(in_band, 5.0, 1.0)[ok]
    share = exact[in_band[ok]].sum() / exact.sum()
    assert float(band.share) == pytest.approx(share, abs=0.03)
    assert float(band.contrast) == pytest.approx(5.0, rel=0.2)  # the edges' central differences blur it a little
    assert float(band.outside_ratio) < 1 < float(band.inside_ratio)


def test_a_band_without_background_shear():
    """Shear only inside a 0.08 m strip at 50 deg: the rest does not shear, so the contrast is
    infinite (or huge) and the strip carries the whole rate."""
    rate = rate_of(band_velocity(50.0, 0.08, rate_in=2.0))
    band = find_shear_band(rate, width=0.08)
    assert bool(band.found) and abs(float(band.angle) - 50.0) <= 1.0
    assert abs(float(band.fwhm) - 0.08) <= H
    assert float(band.share) > 0.9


def test_a_uniform_shear_has_no_band():
    """v = (g y, 0): the same rate at every node, so every strip's share equals its area
    (excess 0), the contrast is 1, and the finder says: no band."""
    g = 3.0
    X, Y = np.meshgrid(GRID, GRID)
    v = np.stack([g * Y, np.zeros_like(Y)], axis=-1)
    fields = xr.Dataset({"velocity": (("y", "x", "xy"), v)}, coords={"x": GRID, "y": GRID, "xy": ["x", "y"]})
    rate = rate_of(fields)
    np.testing.assert_allclose(rate.values, g)
    band = find_shear_band(rate)
    assert not bool(band.found)
    assert float(band.contrast) == pytest.approx(1.0, abs=1e-9)
    assert float(band.excess) == pytest.approx(0.0, abs=1e-9)


def test_a_weak_band_is_below_the_contrast_criterion():
    """A strip shearing 1.5 times the rest is located, but is not a band at the default
    contrast of 2; it is at a contrast of 1.3."""
    rate = rate_of(band_velocity(30.0, 0.1, rate_in=0.5, rate_out=1.0))
    weak = find_shear_band(rate, width=0.1)
    assert abs(float(weak.angle) - 30.0) <= 1.0 and not bool(weak.found)
    assert float(weak.contrast) == pytest.approx(1.5, rel=0.1)
    assert bool(find_shear_band(rate, width=0.1, contrast=1.3).found)


def test_band_finder_refuses_what_it_cannot_read():
    rate = rate_of(band_velocity(30.0, 0.1, rate_in=1.0))
    with pytest.raises(ParameterError, match=r"rate over \('time', 'y', 'x'\): expected one map"):
        find_shear_band(rate.expand_dims(time=2))
    with pytest.raises(ParameterError, match="negative values"):
        find_shear_band(-rate)
    with pytest.raises(ParameterError, match="width=-0.1: expected a strip width > 0"):
        find_shear_band(rate, width=-0.1)
    with pytest.raises(ParameterError, match="contrast=0: expected a ratio > 0"):
        find_shear_band(rate, contrast=0)
    with pytest.raises(ParameterError, match="no node with a value"):
        find_shear_band(rate, inside=rate < 0)
    with pytest.raises(ParameterError, match="expected a field over the grid's"):
        profile_along(xr.DataArray(np.zeros(3), dims="s"), 10.0)
    with pytest.raises(ParameterError, match="angle='a'"):
        profile_along(rate, "a")


# -- the figure ---------------------------------------------------------------------------

def test_the_band_is_drawn_over_the_shear_rate_map():
    """plot_shear_band draws the band's two half-maximum lines: every point of each satisfies
    -x sin(angle) + y cos(angle) = its edge; plot_field_maps(band=True) draws the band the finder
    finds in the drawn snapshot's shear rate, and refuses band= without the shear-rate map."""
    import matplotlib

    matplotlib.use("Agg")
    from grainview.analysis.coarse_graining import coarse_grained, interior
    from grainview.plot import plot_field_maps, plot_shear_band

    from . import builders

    rate = rate_of(band_velocity(50.0, 0.12, rate_in=4.0, rate_out=1.0))
    band = find_shear_band(rate, width=0.12)
    fig = plot_shear_band(rate, band=band, box=([0.0, 0.0], [1.0, 1.0]))
    lines = [line for line in fig.axes[0].lines if line.get_xdata().size]
    assert len(lines) == 2
    t = np.radians(float(band.angle))
    for line, edge in zip(lines, band.edges.values):
        x, y = line.get_xdata(), line.get_ydata()
        np.testing.assert_allclose(-x * np.sin(t) + y * np.cos(t), edge, atol=1e-12)
    assert "band: 50" in fig.axes[0].get_legend().get_texts()[0].get_text()
    assert fig.axes[1].get_ylabel() == r"$\dot\gamma$ (s$^{-1}$)"

    uniform = xr.full_like(rate, 2.0)  # no band: nothing drawn, the legend says so
    fig = plot_shear_band(uniform)
    assert not [line for line in fig.axes[0].lines if line.get_xdata().size]
    assert fig.axes[0].get_legend().get_texts()[0].get_text().startswith("no band")

    # a lattice whose particles shear in a strip at 50 deg, through coarse_grained
    base = builders.square_lattice(24, 24)
    pos = base.position.values
    t50 = np.radians(50.0)
    centre = pos[0].mean(axis=0)
    s = -(pos[..., 0] - centre[0]) * np.sin(t50) + (pos[..., 1] - centre[1]) * np.cos(t50)
    speed = np.clip(s, -3 * builders.R, 3 * builders.R)
    velocity = np.stack([speed * np.cos(t50), speed * np.sin(t50)], axis=-1)
    ds = base.assign(velocity=(("time", "particle", "xy"), velocity, {"units": "m s-1"}))
    fields = coarse_grained(ds, width=builders.R, spacing=builders.R / 2)
    fig = plot_field_maps(ds, fields=fields, names=["shear_rate"], band=True)
    expected = find_shear_band(scalar_field(fields.isel(time=0), "shear_rate"), inside=interior(fields.isel(time=0)))
    assert bool(expected.found) and abs(float(expected.angle) - 50.0) <= 2.0
    drawn = [line for line in fig.axes[0].lines if line.get_xdata().size]
    t = np.radians(float(expected.angle))
    for line, edge in zip(drawn, expected.edges.values):
        np.testing.assert_allclose(-line.get_xdata() * np.sin(t) + line.get_ydata() * np.cos(t), edge, atol=1e-12)
    assert len(drawn) == 2
    with pytest.raises(ParameterError, match="expected 'shear_rate' among names"):
        plot_field_maps(ds, fields=fields, names=["sigma_yy"], band=True)
    matplotlib.pyplot.close("all")
