"""Force pdfs: hand-counted histograms, np.histogram as oracle, pooling, and the exponent of
the strong-force tail recovered from forces drawn with a known alpha."""

import numpy as np
import pytest
import xarray as xr

from grainview import make_dataset
from grainview.contract.errors import ParameterError
from grainview.analysis.force_pdf import force_pdf, pooled_force_pdf, strong_force_exponent

from . import builders
from .conftest import raise_if_dask_computes

RTOL = 1e-12


def contacts_dataset(snapshots, n_particles=6, n_walls=0):
    """Particles at rest; each snapshot a dict of i, j, fn and optionally kind (default simple).
    Normals along x, branch 0.02 m along the normal: only the forces matter here."""
    contacts = []
    for snap in snapshots:
        m = len(snap["i"])
        normal = np.tile([1.0, 0.0], (m, 1))
        contacts.append(dict(i=snap["i"], j=snap["j"], fn=snap["fn"], kind=snap.get("kind", np.ones(m)),
                             normal=normal, ft=np.zeros(m), branch=0.02 * normal, point=np.zeros((m, 2))))
    t = len(snapshots)
    return make_dataset(radius=np.full(n_particles, 0.01), position=np.zeros((t, n_particles, 2)),
                        contacts=contacts, box_min=[0.0, 0.0], box_max=[1.0, 1.0], n_walls=n_walls)


def particle_contacts(ds):
    """Boolean (time, contact): occupied particle–particle slots, by plain numpy."""
    occupied = np.arange(ds.sizes["contact"]) < ds.contact_count.values[:, None]
    return occupied & (ds.j.values < ds.sizes["particle"])


def hand_dataset():
    """Snapshot 0: f = 1, 2, 3, 6 (mean 3) and a wall contact of 100 N; snapshot 1: f = 0, 2, 2, 4
    (mean 2). Kinds in snapshot 0: s, d, s, d."""
    return contacts_dataset([
        dict(i=[0, 1, 2, 3, 4], j=[1, 2, 3, 4, 6], fn=[1.0, 2.0, 3.0, 6.0, 100.0], kind=[1, 2, 1, 2, 1]),
        dict(i=[0, 1, 2, 3], j=[1, 2, 3, 4], fn=[0.0, 2.0, 2.0, 4.0]),
    ], n_walls=4)


def test_linear_pdf_by_hand(prepare):
    ds = prepare(hand_dataset())
    with raise_if_dask_computes():
        out = force_pdf(ds, bins=4, scale="linear", range=(0.0, 2.0), near=np.inf)
        loaded = force_pdf(ds, bins=4, scale="linear", range=(0.0, 2.0))
    # force-bearing only (the default): snapshot 1 has 3 contacts, none with f_n = 0
    np.testing.assert_array_equal(loaded["n_contacts"].values, [4, 3])
    np.testing.assert_allclose(loaded["zero_fraction"].values, [0.0, 0.0], atol=0)
    out = out.compute()
    # ratios f/<f>: 1/3, 2/3, 1, 2 (2 sits on the last edge, which np.histogram includes)
    # and 0, 1, 1, 2; edges 0, 0.5, 1, 1.5, 2
    np.testing.assert_array_equal(out["count"].values, [[1, 1, 1, 1], [1, 0, 2, 1]])
    np.testing.assert_allclose(out["pdf"].values, [[0.5, 0.5, 0.5, 0.5], [0.5, 0.0, 1.0, 0.5]], rtol=RTOL)
    np.testing.assert_allclose((out["pdf"] * out["bin_width"]).sum("bin").values, 1.0, rtol=RTOL)
    np.testing.assert_allclose(out["f_over_mean"].values, [0.25, 0.75, 1.25, 1.75], rtol=RTOL)
    np.testing.assert_allclose(out["bin_edges"].values, [0, 0.5, 1, 1.5, 2], rtol=RTOL)
    np.testing.assert_array_equal(out["n_contacts"].values, [4, 4])
    np.testing.assert_allclose(out["zero_fraction"].values, [0.0, 0.25], rtol=RTOL)
    np.testing.assert_allclose(out["outside_fraction"].values, [0.0, 0.0], atol=0)


def test_log_pdf_skips_zero_forces(prepare):
    ds = prepare(hand_dataset())
    with raise_if_dask_computes():
        out = force_pdf(ds, bins=2, scale="log", range=(0.5, 2.0), near=np.inf)
    out = out.compute()
    # edges 0.5, 1, 2: snapshot 0 -> 1/3 outside, 2/3 | 1, 2; snapshot 1 -> 0 skipped | 1, 1, 2
    np.testing.assert_array_equal(out["count"].values, [[1, 2], [0, 3]])
    np.testing.assert_allclose(out["pdf"].values, [[1 / (3 * 0.5), 2 / (3 * 1.0)], [0.0, 1.0]], rtol=RTOL)
    np.testing.assert_allclose(out["f_over_mean"].values, [np.sqrt(0.5), np.sqrt(2.0)], rtol=RTOL)
    np.testing.assert_allclose(out["zero_fraction"].values, [0.0, 0.25], rtol=RTOL)
    np.testing.assert_allclose(out["outside_fraction"].values, [0.25, 0.25], rtol=RTOL)


def test_walls_and_kind_selection(prepare):
    ds = prepare(hand_dataset())
    with_walls = force_pdf(ds, bins=2, scale="linear", range=(0.0, 5.0), walls=True, near=np.inf).compute()
    # snapshot 0 with the wall contact: mean 112/5, ratios 5/112, 10/112, 15/112, 30/112, 500/112
    np.testing.assert_array_equal(with_walls["count"].values[0], [4, 1])
    # simple contacts of snapshot 0 (f = 1 and 3), still normalised by the mean of all kinds (3)
    simple = force_pdf(ds, bins=4, scale="linear", range=(0.0, 2.0), kind="simple", near=np.inf).compute()
    np.testing.assert_array_equal(simple["count"].values[0], [1, 0, 1, 0])
    np.testing.assert_array_equal(simple["n_contacts"].values, [2, 4])
    double = force_pdf(ds, bins=4, scale="linear", range=(0.0, 2.0), kind="double", near=np.inf).compute()
    np.testing.assert_array_equal(double["count"].values[0], [0, 1, 0, 1])


@pytest.mark.parametrize("scale,value_range", [("linear", (0.0, 3.0)), ("log", (0.05, 4.0))])
def test_matches_numpy_histogram(scale, value_range):
    ds = builders.mixed_contacts(seed=3, t=4)
    out = force_pdf(ds, bins=7, scale=scale, range=value_range)
    mask = particle_contacts(ds)
    for k in range(ds.sizes["time"]):
        f = ds.fn.values[k][mask[k]]
        ratio = f / f.mean()
        edges = np.linspace(*value_range, 8) if scale == "linear" else np.geomspace(*value_range, 8)
        pdf, _ = np.histogram(ratio, bins=edges, density=True)
        count, _ = np.histogram(ratio, bins=edges)
        np.testing.assert_array_equal(out["count"].values[k], count)
        np.testing.assert_allclose(out["pdf"].values[k], pdf, rtol=RTOL)


def test_pooled_pdf_is_histogram_of_all_snapshots(prepare):
    eager = builders.mixed_contacts(seed=5, t=4)
    ds = prepare(eager)
    with raise_if_dask_computes():
        pooled = pooled_force_pdf(ds, bins=6, scale="linear", range=(0.0, 3.0))
    pooled = pooled.compute()
    mask = particle_contacts(eager)
    ratios = np.concatenate([eager.fn.values[k][mask[k]] / eager.fn.values[k][mask[k]].mean() for k in range(4)])
    pdf, _ = np.histogram(ratios, bins=np.linspace(0, 3, 7), density=True)
    np.testing.assert_allclose(pooled["pdf"].values, pdf, rtol=RTOL)
    assert pooled["pdf"].dims == ("bin",)
    assert int(pooled["n_contacts"]) == ratios.size
    assert float(pooled["outside_fraction"]) == pytest.approx(np.mean(ratios > 3.0), rel=RTOL)


def test_strong_force_exponent_exact_on_exponential_pdf():
    x = np.linspace(0.05, 5.95, 60)
    pdf = xr.Dataset({"pdf": ("bin", 0.3 * np.exp(-0.74 * x)), "count": ("bin", np.arange(1, 61))},
                     coords={"f_over_mean": ("bin", x)})
    assert float(strong_force_exponent(pdf)) == pytest.approx(0.74, rel=RTOL)
    # empty bins are left out, and bins at or below the mean never enter the fit
    pdf["count"][30:40] = 0
    pdf["pdf"][:10] = 1e6
    assert float(strong_force_exponent(pdf)) == pytest.approx(0.74, rel=RTOL)
    too_few = pdf.assign(count=pdf["count"].where(pdf.f_over_mean < 1.1, 0))
    assert np.isnan(float(strong_force_exponent(too_few)))


def uniform_plus_exponential(alpha, n, rng):
    """f/<f> uniform on [0, 1) with probability w, 1 + Exp(alpha) otherwise, w chosen so that
    the mean is 1: the pdf above the mean is (1 - w) alpha exp(-alpha (x - 1))."""
    w = (1 / alpha) / (0.5 + 1 / alpha)
    weak = rng.uniform(size=n) < w
    return np.where(weak, rng.uniform(0, 1, n), 1 + rng.exponential(1 / alpha, n))


@pytest.mark.parametrize("alpha", [0.74, 1.4])
def test_strong_force_exponent_recovers_known_alpha(alpha):
    rng = np.random.default_rng(42)
    n_snap, n_c = 4, 25_000  # 10^5 contacts in all
    n_part = 2 * n_c
    i = np.arange(0, n_part, 2)
    snaps = [dict(i=i, j=i + 1, fn=2.5 * uniform_plus_exponential(alpha, n_c, rng), kind=np.ones(n_c),
                  normal=np.tile([1.0, 0.0], (n_c, 1)), branch=np.tile([0.02, 0.0], (n_c, 1)),
                  point=np.zeros((n_c, 2))) for _ in range(n_snap)]
    ds = make_dataset(radius=np.full(n_part, 0.01), position=np.zeros((n_snap, n_part, 2)), contacts=snaps,
                      box_min=[0.0, 0.0], box_max=[1.0, 1.0], n_contact_slots=n_c)
    pooled = pooled_force_pdf(ds.chunk({"time": 2}), scale="linear", bins=40, range=(0.0, 6.0))
    assert float(strong_force_exponent(pooled)) == pytest.approx(alpha, abs=0.02)
    per_snapshot = strong_force_exponent(force_pdf(ds, scale="linear", bins=40, range=(0.0, 6.0)))
    assert per_snapshot.dims == ("time",)
    np.testing.assert_allclose(per_snapshot.values, alpha, atol=0.06)


@pytest.mark.parametrize("kwargs,word", [
    (dict(bins=0), "bins"), (dict(bins=2.5), "bins"), (dict(bins=True), "bins"),
    (dict(scale="cubic"), "scale"), (dict(range=(1.0, 0.0)), "range"), (dict(range=(0.0, 1.0)), "log"),
    (dict(scale="linear", range="wide"), "range"), (dict(kind="triple"), "kind"),
])
def test_bad_parameters(kwargs, word):
    ds = hand_dataset()
    with pytest.raises(ParameterError, match=word):
        force_pdf(ds, **kwargs)
    with pytest.raises(ParameterError, match=word):
        pooled_force_pdf(ds, **kwargs)


def test_bad_exponent_input():
    with pytest.raises(ParameterError, match="force_pdf"):
        strong_force_exponent(xr.Dataset({"x": ("bin", [1.0])}))
    with pytest.raises(ParameterError, match="low"):
        strong_force_exponent(force_pdf(hand_dataset()), low=2.0, high=1.0)


# -- the strong-force prefactor and the counting errors (drawn by Fig. 14, computed here) -------

def _prefactor_by_loop(x, pdf, counts, alpha, low, high):
    """ln A as the plain weighted mean of ln P_k + alpha x_k, one bin at a time."""
    total = weighted = 0.0
    for xk, pk, nk in zip(x, pdf, counts):
        if low < xk < high and nk > 0 and pk > 0 and np.isfinite(pk):
            total += nk
            weighted += nk * (np.log(pk) + alpha * xk)
    return np.exp(weighted / total) if total > 0 and np.isfinite(alpha) else np.nan


def test_exponential_prefactor_against_a_loop():
    from grainview.analysis.arrays.force_pdf import exponential_prefactor

    rng = np.random.default_rng(3)
    x = np.linspace(0.05, 5.95, 30)
    pdf = rng.exponential(0.3, (4, 30)) * (rng.random((4, 30)) > 0.2)  # some empty bins
    counts = rng.integers(0, 9, (4, 30)) * (pdf > 0)
    alpha = np.array([0.7, 1.4, np.nan, 2.0])
    got = exponential_prefactor(x, pdf, counts, alpha, low=1.0, high=5.0)
    want = [_prefactor_by_loop(x, pdf[r], counts[r], alpha[r], 1.0, 5.0) for r in range(4)]
    np.testing.assert_allclose(got, want, rtol=RTOL)
    assert np.isnan(got[2])
    assert np.isnan(exponential_prefactor(x, pdf[0], np.zeros(30), 1.0))  # no bin holds a contact


def test_counting_error_against_a_loop():
    from grainview.analysis.arrays.force_pdf import counting_error as error_of

    rng = np.random.default_rng(4)
    counts = rng.integers(0, 5, (3, 12)).astype(float)
    pdf = counts / (counts.sum(-1, keepdims=True) * 0.5)
    want = np.array([[p / np.sqrt(n) if n > 0 else np.nan for p, n in zip(prow, nrow)]
                     for prow, nrow in zip(pdf, counts)])
    np.testing.assert_allclose(error_of(pdf, counts), want, rtol=RTOL)


def test_an_exact_exponential_gives_back_its_prefactor_and_exponent():
    """P = A exp(-alpha x) on every bin: the fit recovers alpha and A exactly, whatever the counts."""
    from grainview.analysis.force_pdf import counting_error, strong_force_prefactor

    x = np.linspace(0.1, 5.9, 30)
    counts = np.arange(30.0) % 7  # bins with no contact are left out of both fits
    pdf = xr.Dataset({"pdf": ("bin", 2.5 * np.exp(-0.8 * x)), "count": ("bin", counts)},
                     coords={"f_over_mean": ("bin", x)})
    assert float(strong_force_exponent(pdf)) == pytest.approx(0.8, rel=1e-12)
    assert float(strong_force_prefactor(pdf)) == pytest.approx(2.5, rel=1e-12)
    assert float(strong_force_prefactor(pdf, alpha=0.8, low=3.0)) == pytest.approx(2.5, rel=1e-12)
    error = counting_error(pdf)
    with np.errstate(divide="ignore"):
        want = np.where(counts > 0, pdf["pdf"].values / np.sqrt(counts), np.nan)
    np.testing.assert_allclose(error.values, want, rtol=RTOL)
    assert error.name == "pdf_error" and error.attrs["units"] == "1"
    assert np.isnan(counting_error(pdf.drop_vars("count")).values).all()  # counts unknown
    with pytest.raises(ParameterError, match="expected the Dataset"):
        strong_force_prefactor(pdf["pdf"])
    with pytest.raises(ParameterError, match="low < high"):
        strong_force_prefactor(pdf, low=2.0, high=1.0)


def test_pooled_pdf_over_chosen_snapshots_through_the_accessor(prepare):
    """``time=`` pools the snapshots it chooses, lazily, the same as pooling them picked by hand."""
    from grainview.analysis.force_pdf import counting_error, strong_force_prefactor
    from grainview.datasets import harmonic_series

    ds = harmonic_series(n_snapshots=5, n_contacts=400, seed=2)
    lazy = prepare(ds)
    with raise_if_dask_computes():
        pooled = lazy.grain.pooled_force_pdf(bins=20, scale="linear", range=(0.0, 6.0), time=[1, 3, 4])
        prefactor = strong_force_prefactor(pooled)
        error = counting_error(pooled)
    want = pooled_force_pdf(ds.isel(time=[1, 3, 4]), bins=20, scale="linear", range=(0.0, 6.0))
    xr.testing.assert_allclose(pooled.compute(), want)
    assert int(pooled["n_contacts"]) == 3 * 400
    assert float(prefactor) == pytest.approx(_prefactor_by_loop(
        want["f_over_mean"].values, want["pdf"].values, want["count"].values,
        float(strong_force_exponent(want)), 1.0, np.inf), rel=1e-10)
    np.testing.assert_allclose(error.values, counting_error(want).values, rtol=RTOL)


@pytest.mark.parametrize("scale", ["linear", "log"])
def test_pooling_per_snapshot_pdfs_is_the_pooled_pdf(scale):
    """Two computations: the per-snapshot histograms summed (pool_force_pdf) and the contacts
    of every snapshot histogrammed at once (pooled_force_pdf)."""
    from grainview.analysis.force_pdf import pool_force_pdf

    ds = builders.mixed_contacts(seed=7, t=5)
    kwargs = dict(bins=8, scale=scale, range=(0.0, 3.0) if scale == "linear" else (0.05, 5.0))
    pooled = pooled_force_pdf(ds, **kwargs).compute()
    from_snapshots = pool_force_pdf(force_pdf(ds, **kwargs).compute())
    for name in ("pdf", "count", "n_contacts", "zero_fraction", "outside_fraction"):
        np.testing.assert_array_equal(from_snapshots[name].values, pooled[name].values, err_msg=name)
    assert from_snapshots.attrs["pooled_snapshots"] == 5
    assert 0 < float(pooled["outside_fraction"]) < 1  # the range cuts some contacts off: counted the same
    assert float(strong_force_exponent(from_snapshots)) == float(strong_force_exponent(pooled))


def test_pooling_needs_a_per_snapshot_pdf():
    from grainview.analysis.force_pdf import pool_force_pdf

    pooled = pooled_force_pdf(builders.mixed_contacts(seed=7, t=2), bins=4, scale="linear")
    with pytest.raises(ParameterError, match="per-snapshot result of force_pdf"):
        pool_force_pdf(pooled)
