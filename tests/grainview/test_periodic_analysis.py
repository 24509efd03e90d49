"""Every analysis in a periodic cell (issue 46, item 3): strains from the cell, coarse-grained
fields around the torus, force chains and cycles across the boundary, contacts that keep
their identity when they cross it, maps that draw the cell."""

from __future__ import annotations

import numpy as np
import pytest

import grainview
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
    f = grainview.analysis.strain.deformation_gradient(ds).values
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
