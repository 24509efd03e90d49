"""Fabric and force anisotropies: lattices by hand, the harmonic model, F = F_s + F_d."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings, strategies as st

from grainview import make_dataset
from grainview.datasets import harmonic_contacts
from grainview.contract.errors import ParameterError

from . import builders
from .conftest import raise_if_dask_computes

RTOL = 1e-12


def test_square_lattice_fabric(prepare):
    ds = prepare(builders.square_lattice(4, 3))
    n_h, n_v = 9, 8
    fab = ds.grain.fabric_anisotropy().compute().isel(time=0)
    assert fab.a == pytest.approx(2 * (n_h - n_v) / (n_h + n_v), rel=RTOL)
    assert fab.theta_F == 0.0
    # stress is vertical (fy > fx), the fabric horizontal: a' = -a
    assert fab.a_prime == pytest.approx(-2 * (n_h - n_v) / (n_h + n_v), rel=RTOL)
    F = ds.grain.fabric_tensor().compute().isel(time=0).values
    np.testing.assert_allclose(F, [[n_h / 17, 0], [0, n_v / 17]], rtol=RTOL, atol=1e-300)


def test_hexagonal_lattice_fabric_is_isotropic():
    ds = builders.hexagonal_lattice(nx=6, ny=5)
    normals = ds.normal.values[0, : int(ds.contact_count[0])]
    theta = np.round(np.degrees(np.mod(np.arctan2(normals[:, 1], normals[:, 0]), np.pi))).astype(int)
    counts = {d: int((theta == d).sum()) for d in (0, 60, 120)}
    F = ds.grain.fabric_tensor().isel(time=0).values
    # by hand: F = sum_d (N_d/N_c) n_d n_d^T
    expected = sum(c * np.outer([np.cos(np.radians(d)), np.sin(np.radians(d))],
                                [np.cos(np.radians(d)), np.sin(np.radians(d))]) for d, c in counts.items()) / sum(counts.values())
    np.testing.assert_allclose(F, expected, rtol=RTOL, atol=1e-15)
    assert np.trace(F) == pytest.approx(1.0, rel=RTOL)


def test_square_lattice_force_tensor_by_hand(prepare):
    fx, fy, bins = 2.0, 5.0, 4
    ds = prepare(builders.square_lattice(4, 3, fx, fy))
    h = ds.grain.force_tensors(bins=bins).compute().isel(time=0)
    w = np.pi / bins  # sector 0 is centred on 0, sector 2 on pi/2
    j0 = np.diag([w / 2 + np.sin(w) / 2, w / 2 - np.sin(w) / 2])
    j2 = np.diag([w / 2 - np.sin(w) / 2, w / 2 + np.sin(w) / 2])
    np.testing.assert_allclose(h.H_n.values, (fx * j0 + fy * j2) / np.pi, rtol=RTOL, atol=1e-15)
    np.testing.assert_allclose(h.H_t.values, 0.0, atol=1e-300)
    an = ds.grain.force_anisotropies(bins=bins).compute().isel(time=0)
    expected = 2 * (fy - fx) * np.sin(w) / ((fx + fy) * w)
    assert an.a_n == pytest.approx(expected, rel=RTOL)
    assert an.theta_n == pytest.approx(np.pi / 2, rel=RTOL)


def test_angular_averages_and_orientation_pdf():
    ds = builders.square_lattice(4, 3, 2.0, 5.0)
    avg = ds.grain.angular_force_averages(bins=4).isel(time=0)
    np.testing.assert_array_equal(avg["count"].values, [9, 0, 8, 0])
    np.testing.assert_allclose(avg.fn_mean.values[[0, 2]], [2.0, 5.0], rtol=RTOL)
    assert np.isnan(avg.fn_mean.values[1])
    pdf = ds.grain.orientation_pdf(bins=4).isel(time=0)
    assert float((pdf * np.pi / 4).sum()) == pytest.approx(1.0, rel=RTOL)
    assert avg.theta.attrs["units"] == "rad"


def harmonic_sample(n=100_000, a=0.3, a_n=0.4, a_t=0.25, theta_0=0.3, seed=0):
    """Contacts drawn from the harmonic model of ERRATA item 3 (grainview.datasets), all
    directions theta_0, tangential forces resisting the shear; each contact its own pair."""
    normal, fn, ft, kind = harmonic_contacts(n, a, a_n, a_t, theta_0, mean_force=2.0, rng=seed)
    i = np.arange(0, 2 * n, 2)
    pos = np.zeros((2 * n, 2))
    pos[i + 1] = normal * 0.02
    return make_dataset(radius=np.full(2 * n, 0.01), position=pos,
                        contacts=[dict(i=i, j=i + 1, kind=kind, normal=normal, fn=fn, ft=ft)],
                        box_min=[-1, -1], box_max=[1, 1], n_contact_slots=n)


def test_harmonic_model_anisotropies_are_recovered():
    a, a_n, a_t, theta_0 = 0.3, 0.4, 0.25, 0.3
    ds = harmonic_sample(a=a, a_n=a_n, a_t=a_t, theta_0=theta_0)
    fab = ds.grain.fabric_anisotropy().isel(time=0)
    frc = ds.grain.force_anisotropies(bins=36).isel(time=0)
    assert float(fab.a) == pytest.approx(a, abs=0.01)
    assert float(frc.a_n_magnitude) == pytest.approx(a_n, abs=0.01)
    assert float(frc.a_t_magnitude) == pytest.approx(a_t, abs=0.01)
    assert float(fab.theta_F) == pytest.approx(theta_0, abs=0.02)
    assert float(frc.theta_n) == pytest.approx(theta_0, abs=0.02)
    assert float(frc.theta_t) == pytest.approx(theta_0, abs=0.02)
    # all directions coincide with the stress: the signed values equal the magnitudes and
    # q/p ~ (a + a_n + a_t)/2 up to the neglected cross products (a a_n ~ 0.1)
    pred = ds.grain.harmonic_prediction().isel(time=0)
    assert float(pred.a_t) == pytest.approx(a_t, abs=0.01)
    assert float(pred.prediction) == pytest.approx((a + a_n + a_t) / 2, abs=0.01)
    assert float(pred.q_over_p) == pytest.approx(float(pred.prediction), abs=0.05)


@pytest.mark.parametrize("a, a_n, a_t", [(0.3, 0.4, 0.25), (0.6, 0.6, 0.2), (0.6, 0.55, 0.18)])
def test_the_cross_term_makes_the_harmonic_prediction_exact(a, a_n, a_t):
    """For the harmonic model with coaxial directions and equal branch lengths, integrating
    P(theta) <f_n>(theta) over the angles gives p ~ 1 + a a_n / 2 and q ~ (a + a_n + a_t)/2:
    q/p = (a + a_n + a_t)/(2 + a a_n) exactly, while the first-order form is off by the
    factor 1 + a a_n / 2 (18% at a = a_n = 0.6)."""
    pred = harmonic_sample(a=a, a_n=a_n, a_t=a_t, theta_0=0.3).grain.harmonic_prediction().isel(time=0)
    exact = (a + a_n + a_t) / (2 + a * a_n)
    assert float(pred.q_over_p) == pytest.approx(exact, abs=0.005)
    assert float(pred.prediction_cross_term) == pytest.approx(float(pred.q_over_p), abs=0.005)
    first_order_error = float(pred.prediction) / float(pred.q_over_p) - 1
    assert first_order_error == pytest.approx(a * a_n / 2, abs=0.01)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_partial_fabrics_add_up(seed):
    ds = builders.mixed_contacts(seed=seed)
    total = ds.grain.fabric_tensor()
    parts = ds.grain.fabric_tensor("simple") + ds.grain.fabric_tensor("double")
    np.testing.assert_allclose(parts.values, total.values, rtol=1e-12, atol=1e-15)


def test_bad_bins():
    ds = builders.two_disks()
    with pytest.raises(ParameterError, match="bins=0"):
        ds.grain.force_tensors(bins=0)
    with pytest.raises(ParameterError, match="kind='edge'"):
        ds.grain.fabric_tensor(kind="edge")


def test_lazy_equals_eager():
    ds = builders.mixed_contacts(t=4)
    chunked = ds.chunk(time=1)
    with raise_if_dask_computes():
        lazy = [chunked.grain.fabric_anisotropy(), chunked.grain.force_anisotropies(),
                chunked.grain.harmonic_prediction(), chunked.grain.orientation_pdf()]
    eager = [ds.grain.fabric_anisotropy(), ds.grain.force_anisotropies(),
             ds.grain.harmonic_prediction(), ds.grain.orientation_pdf()]
    for l, e in zip(lazy, eager):
        xr.testing.assert_allclose(l.compute(), e, rtol=1e-13)


def _angular_profile_by_loop(ds, snapshots, bins, component="fn"):
    """<f>(theta)/<f_n> of each snapshot, one contact at a time, then averaged NaN-aware."""
    rows = []
    n = ds.sizes["particle"]
    for t in snapshots:
        sums, counts, total, m = np.zeros(bins), np.zeros(bins), 0.0, 0
        for c in range(int(ds["contact_count"].values[t])):
            fn = float(ds["fn"].values[t, c])
            if fn <= 0 or ds["j"].values[t, c] >= n:
                continue
            nx, ny = ds["normal"].values[t, c]
            k = int(np.floor((np.arctan2(ny, nx) % np.pi) / (np.pi / bins) + 0.5)) % bins
            sums[k] += float(ds[component].values[t, c])
            counts[k] += 1
            total, m = total + fn, m + 1
        with np.errstate(invalid="ignore"):
            rows.append(sums / counts / (total / m))
    return np.nanmean(rows, axis=0)


@pytest.mark.parametrize("component", ["fn", "ft"])
def test_angular_profile_against_a_loop_through_the_accessor(prepare, component):
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=4, n_contacts=150, seed=5)
    lazy = prepare(ds)
    with raise_if_dask_computes():
        profile = lazy.grain.angular_profile(component, time=slice(1, 4), bins=12)
    np.testing.assert_allclose(profile.values, _angular_profile_by_loop(ds, [1, 2, 3], 12, component), rtol=1e-12)
    assert profile.dims == ("theta",) and profile.attrs["units"] == "1"
    raw = ds.grain.angular_profile(component, time=-1, bins=12, normalise=False)
    assert raw.attrs["units"] == "N"
    with pytest.raises(ParameterError, match="component='fx'"):
        ds.grain.angular_profile("fx")
