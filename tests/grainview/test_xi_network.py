"""The xi-network: the sorted/cumulative-sum computation against K brute-force passes, the
whole-sample limit, and lattices by hand (ERRATA item 5)."""

import numpy as np
import pytest

from grainview.analysis.arrays import fabric as fabric_arrays
from grainview.analysis.arrays import stress as stress_arrays
from grainview.analysis.arrays.tensors import principal, signed_anisotropy
from grainview.analysis._kernels.xi_network import count_below
from grainview.contract.errors import ParameterError
from grainview.analysis.fabric import fabric_anisotropy
from grainview.analysis.stress import stress_invariants
from grainview.analysis.xi_network import xi_network

from . import builders
from .builders import R
from .conftest import raise_if_dask_computes

RTOL = 1e-12


def test_count_below_kernel_matches_searchsorted():
    rng = np.random.default_rng(1)
    rows = np.sort(rng.integers(0, 6, (5, 9)).astype(float), axis=1)  # many ties
    rows[2, 6:] = np.inf
    thresholds = rng.integers(-1, 8, (5, 7)).astype(float)
    thresholds[0, 0] = np.inf
    thresholds[1, 0] = np.nan
    got = count_below(rows, thresholds)
    for r in range(5):
        finite = ~np.isnan(thresholds[r])
        np.testing.assert_array_equal(got[r][finite], np.searchsorted(rows[r], thresholds[r][finite], side="left"))
    assert got[1, 0] == 0
    assert count_below(np.empty((2, 0)), np.ones((2, 3))).tolist() == [[0, 0, 0], [0, 0, 0]]


def brute_force(ds, xi, walls=False):
    """K passes: for each xi, the subset by a direct comparison, its stress and fabric from the
    plain array functions, and q/p, a' from their principal values."""
    n_slots = ds.sizes["contact"]
    mask = np.arange(n_slots) < ds.contact_count.values[:, None]
    if not walls:
        mask &= ds.j.values < ds.sizes["particle"]
    fn = ds.fn.values
    mean = np.where(mask, fn, 0).sum(1) / mask.sum(1)
    whole = stress_invariants(ds)
    volume = np.prod(ds.box_max.values - ds.box_min.values, axis=1)
    q_over_p, a_prime, fraction = [], [], []
    for x in xi:
        subset = mask & (np.where(mask, fn, np.inf) < x * mean[:, None])
        sigma = stress_arrays.stress_tensor(fn, ds.ft.values, ds.normal.values, ds.branch.values, subset, volume)
        s1, s2, _ = principal(sigma)
        q_over_p.append((s1 - s2) / 2 / whole.p.values)
        with np.errstate(invalid="ignore", divide="ignore"):
            f1, f2, theta = principal(fabric_arrays.fabric_tensor(ds.normal.values, subset))
            a_prime.append(signed_anisotropy(f1, f2, theta, whole.theta_sigma.values, normalisation=1.0))
        fraction.append(subset.sum(1) / mask.sum(1))
    return [np.stack(v, axis=1) for v in (q_over_p, a_prime, fraction)]


@pytest.mark.parametrize("walls", [False, True])
def test_sorted_sweep_equals_brute_force(walls):
    ds = builders.mixed_contacts(seed=11, t=4)
    xi = np.array([0.0, 0.3, 0.7, 1.0, 1.5, 2.2, 3.0, 50.0, 0.5])  # any order
    out = xi_network(ds, xi=xi, walls=walls)
    q_over_p, a_prime, fraction = brute_force(ds, xi, walls)
    np.testing.assert_allclose(out.q_over_p.values, q_over_p, rtol=RTOL, atol=1e-15)
    np.testing.assert_allclose(out.a_prime.values, a_prime, rtol=RTOL, atol=1e-15)
    np.testing.assert_allclose(out.contact_fraction.values, fraction, rtol=RTOL)
    np.testing.assert_array_equal(out.xi.values, xi)


def test_large_xi_gives_the_whole_selection(prepare):
    eager = builders.mixed_contacts(seed=2, t=3)
    ds = prepare(eager)
    with raise_if_dask_computes():
        out = xi_network(ds, xi=[0.0, 1e6])
    out = out.compute()
    whole = stress_invariants(eager)
    particles = stress_invariants(eager, walls=False)
    np.testing.assert_allclose(out.q_over_p.values[:, 1], (particles.q / whole.p).values, rtol=RTOL)
    np.testing.assert_allclose(out.a_prime.values[:, 1], fabric_anisotropy(eager).a_prime.values, rtol=RTOL)
    np.testing.assert_array_equal(out.contact_fraction.values[:, 1], 1.0)
    # xi = 0: empty subset, no deviator, undefined fabric
    np.testing.assert_array_equal(out.q_over_p.values[:, 0], 0.0)
    assert np.isnan(out.a_prime.values[:, 0]).all()
    np.testing.assert_array_equal(out["count"].values[:, 0], 0)
    # with walls=True and every contact in, q(xi)/p is the whole sample's q/p
    with_walls = xi_network(eager, xi=[1e6], walls=True)
    np.testing.assert_allclose(with_walls.q_over_p.values[:, 0], whole.q_over_p.values, rtol=RTOL)


def test_square_lattice_by_hand(prepare):
    # 4 x 3 disks: 9 horizontal contacts of 2 N and 8 vertical ones of 5 N; <f_n> = 58/17 N
    ds = prepare(builders.square_lattice(4, 3, 2.0, 5.0))
    with raise_if_dask_computes():
        out = xi_network(ds, xi=[0.5, 1.0, 2.0])
    out = out.compute().isel(time=0)
    volume = (8 * R) * (6 * R)
    sxx, syy = 9 * 2.0 * 2 * R / volume, 8 * 5.0 * 2 * R / volume
    p = (sxx + syy) / 2
    # xi = 0.5: threshold 29/17 N < 2 N: empty
    assert float(out.q_over_p[0]) == 0.0 and float(out.contact_fraction[0]) == 0.0
    # xi = 1: threshold 58/17 N: the 9 horizontal contacts; sigma = diag(sxx, 0), F = diag(1, 0)
    # whose major direction 0 is orthogonal to the stress's (pi/2): a' = -2
    assert float(out.q_over_p[1]) == pytest.approx(sxx / 2 / p, rel=RTOL)
    assert float(out.a_prime[1]) == pytest.approx(-2.0, rel=RTOL)
    assert float(out.contact_fraction[1]) == pytest.approx(9 / 17, rel=RTOL)
    # xi = 2: every contact; q/p = (syy - sxx)/(syy + sxx) and a' = -2 (9 - 8)/17
    assert float(out.q_over_p[2]) == pytest.approx((syy - sxx) / (syy + sxx), rel=RTOL)
    assert float(out.a_prime[2]) == pytest.approx(-2 / 17, rel=RTOL)
    assert float(out.contact_fraction[2]) == 1.0


def test_cutoff_is_strict():
    # 3 x 3 disks: 6 horizontal contacts of 2 N, 6 vertical of 6 N; <f_n> = 4 N exactly
    ds = builders.square_lattice(3, 3, 2.0, 6.0)
    out = xi_network(ds, xi=[0.5, 0.5000001, 1.5, 1.5000001]).isel(time=0)
    # f_n < 0.5 * 4 = 2 excludes the 2 N contacts; f_n < 1.5 * 4 = 6 excludes the 6 N ones
    np.testing.assert_array_equal(out["count"].values, [0, 6, 6, 12])


@pytest.mark.parametrize("xi", [[-0.1, 1.0], [np.nan], [], [[0.5, 1.0]], ["a"], [np.inf]])
def test_bad_xi(xi):
    with pytest.raises(ParameterError, match="xi"):
        xi_network(builders.two_disks(), xi=xi)


def test_default_xi_and_scalar():
    ds = builders.square_lattice(3, 3, 2.0, 6.0)
    assert xi_network(ds).sizes["xi"] == 101
    assert xi_network(ds, xi=2.0)["count"].values.tolist() == [[12]]


def test_xi_profile_is_the_mean_of_each_snapshots_network_through_the_accessor(prepare):
    from grainview.datasets import harmonic_series

    from .conftest import raise_if_dask_computes

    ds = harmonic_series(n_snapshots=4, n_contacts=200, seed=6)
    xi = np.array([0.5, 1.0, 2.0, 4.0])
    lazy = prepare(ds)
    with raise_if_dask_computes():
        profile = lazy.grain.xi_profile(xi=xi, time=[0, 2, 3])
    for name in ("q_over_p", "a_prime", "contact_fraction", "count"):
        one_by_one = [xi_network(ds.isel(time=[t]), xi=xi)[name].values[0] for t in (0, 2, 3)]
        np.testing.assert_allclose(profile[name].values, np.mean(one_by_one, axis=0), rtol=1e-12)
    assert profile.sizes == {"xi": 4}
