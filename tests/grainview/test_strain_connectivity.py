"""Strains, angles and inertia number on a hand-made box history; coordination by hand."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings, strategies as st

from grainview import make_dataset
from grainview.contract.errors import ParameterError

from . import builders
from .conftest import raise_if_dask_computes

RTOL = 1e-12


def box_history():
    """Two pressed disks in a box whose height shrinks and width grows over 4 snapshots."""
    h = np.array([1.0, 0.9, 0.8, 0.75])
    l = np.array([0.5, 0.52, 0.55, 0.56])
    t = np.array([0.0, 1.0, 2.0, 3.0])
    base = builders.two_disks(force=3.0)
    pos = np.repeat(base.position.values, 4, axis=0)
    contacts = [dict(i=[0], j=[1], kind=[1], normal=[[1.0, 0.0]], fn=[3.0], ft=[0.0])] * 4
    ds = make_dataset(radius=base.radius.values, position=pos, contacts=contacts, time=t,
                      box_min=np.zeros((4, 2)), box_max=np.stack([l, h], -1))
    return ds, h, l, t


def test_strains_by_hand(prepare):
    ds, h, l, t = box_history()
    eps = prepare(ds).grain.strains().compute()
    e1 = np.log(1 + (h[0] - h) / h[0])
    e2 = np.log(1 + (l[0] - l) / l[0])
    ep = np.log(1 + (h * l - h[0] * l[0]) / (h[0] * l[0]))
    np.testing.assert_allclose(eps.eps_1, e1, rtol=RTOL)
    np.testing.assert_allclose(eps.eps_2, e2, rtol=RTOL)
    np.testing.assert_allclose(eps.eps_p, ep, rtol=RTOL)
    np.testing.assert_allclose(eps.eps_q, e1 - e2, rtol=RTOL)
    assert eps.eps_q.attrs["units"] == "1"


def test_angles_and_inertia_number(prepare):
    ds, h, l, t = box_history()
    out = prepare(ds).grain.friction_and_dilatancy().compute()
    e1 = np.log(1 + (h[0] - h) / h[0]); e2 = np.log(1 + (l[0] - l) / l[0])
    ep = np.log(h * l / (h[0] * l[0])); eq = e1 - e2
    assert np.isnan(out.psi[0])
    np.testing.assert_allclose(out.psi[1:], np.arcsin(ep[1:] / eq[1:]), rtol=RTOL)
    rate = np.gradient(ep, t) / np.gradient(eq, t)  # numpy's centred / one-sided differences
    np.testing.assert_allclose(out.psi_incremental, np.arcsin(rate), rtol=1e-10)
    # a single contact: s2 = 0, q/p = 1, phi = pi/2
    np.testing.assert_allclose(out.phi, np.pi / 2, rtol=RTOL)
    inertia = prepare(ds).grain.inertia_number().compute()
    p = ds.grain.stress_invariants()["p"].values
    expected = np.abs(np.gradient(h, t)) / h * np.sqrt(float(ds.mass.sum()) / p)
    np.testing.assert_allclose(inertia, expected, rtol=1e-10)


def test_square_lattice_coordination(prepare):
    ds = prepare(builders.square_lattice(4, 3))
    out = ds.grain.coordination().compute().isel(time=0)
    assert out.z == pytest.approx(2 * 17 / 12, rel=RTOL)
    assert out.n_active == 12
    pc = ds.grain.connectivity_pdf(max_c=5).compute().isel(time=0)
    np.testing.assert_allclose(pc.values, [0, 0, 4 / 12, 6 / 12, 2 / 12, 0], rtol=RTOL)


def test_rattlers_and_zero_forces_are_left_out():
    ds = builders.square_lattice(3, 1, fx=1.0, fy=1.0)  # a row of three disks: 0-1-2
    ds["fn"][0, 1] = 0.0  # contact 1-2 carries no force: particle 2 becomes a rattler
    out = ds.grain.coordination().isel(time=0)
    assert out.z == pytest.approx(1.0, rel=RTOL) and out.n_active == 2
    out2 = ds.grain.coordination(min_contacts=2).isel(time=0)
    assert out2.n_active == 0 and np.isnan(out2.z)
    with pytest.raises(ParameterError, match="min_contacts"):
        ds.grain.coordination(min_contacts=0)


def test_joint_connectivity_counts_double_contacts_once():
    # horizontal contacts simple, vertical double in a 2x2 square: each particle has 1 + 1
    ds = builders.square_lattice(2, 2, kinds=[1, 1, 2, 2])
    pm = ds.grain.joint_connectivity_pdf(max_m=3).isel(time=0)
    assert float(pm.sel(m_s=1, m_d=1)) == pytest.approx(1.0, rel=RTOL)
    assert float(pm.sum()) == pytest.approx(1.0, rel=RTOL)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000), perm_seed=st.integers(0, 10_000))
def test_coordination_invariant_under_relabelling(seed, perm_seed):
    ds = builders.mixed_contacts(seed=seed)
    n = ds.sizes["particle"]
    perm = np.random.default_rng(perm_seed).permutation(n)  # new id of old particle k
    i, j = ds.i.values.copy(), ds.j.values.copy()
    occ = i >= 0
    part = occ & (j < n)
    ni = np.where(occ, perm[np.clip(i, 0, n - 1)], i)
    nj = np.where(part, perm[np.clip(j, 0, n - 1)], j)
    swap = part & (ni > nj)
    relabelled = ds.copy(deep=True)
    relabelled["i"][:] = np.where(swap, nj, ni)
    relabelled["j"][:] = np.where(swap, ni, nj)
    relabelled["normal"][:] = np.where(swap[..., None], -ds.normal.values, ds.normal.values)
    a = ds.grain.coordination()
    b = relabelled.grain.coordination()
    xr.testing.assert_allclose(a, b, rtol=1e-14)
    xr.testing.assert_allclose(ds.grain.connectivity_pdf(), relabelled.grain.connectivity_pdf())


def test_lazy_equals_eager():
    ds = builders.mixed_contacts(t=4)
    chunked = ds.chunk(time=1)
    with raise_if_dask_computes():
        lazy = [chunked.grain.coordination(), chunked.grain.joint_connectivity_pdf(),
                chunked.grain.strains(), chunked.grain.friction_and_dilatancy()]
    eager = [ds.grain.coordination(), ds.grain.joint_connectivity_pdf(),
             ds.grain.strains(), ds.grain.friction_and_dilatancy()]
    for l, e in zip(lazy, eager):
        xr.testing.assert_allclose(l.compute(), e, rtol=1e-13)


def test_solid_fraction_of_disks_and_pentagons():
    from grainview.contract.shapes import particle_area
    assert particle_area(1.0, 0) == pytest.approx(np.pi, rel=RTOL)
    assert particle_area(1.0, 4) == pytest.approx(2.0, rel=RTOL)  # square of diagonal 2
    assert particle_area(2.0, 6) == pytest.approx(6 * np.sqrt(3) / 4 * 4, rel=RTOL)  # 6 triangles of side 2
    ds, h, l, t = box_history()
    phi = ds.grain.solid_fraction().values
    np.testing.assert_allclose(phi, 2 * np.pi * builders.R**2 / (h * l), rtol=RTOL)
