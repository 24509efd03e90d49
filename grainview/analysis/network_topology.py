"""Topology of the force network: persistent homology of the contact network filtered by
decreasing normal force, Betti curves beta_0(xi), beta_1(xi), and 3- and 4-cycles by force
class (docs/analysis.md, "Topology of the force network").

Not to be confused with :mod:`grainview.analysis.persistence`, the persistence of contacts in TIME.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import network_topology as _topology
from .arrays import periodic as _periodic
from .contacts import near_attr, selection
from ..contract.errors import ParameterError
from .persistence import body_count
from .xi_network import DEFAULT_XI, _check_xi
from ._docs import fill_doc

__all__ = ["network_persistence"]


def _check_options(dimensions, strong, max_features):
    try:
        dims = tuple(sorted({int(d) for d in np.atleast_1d(dimensions)}))
    except (TypeError, ValueError):
        dims = None
    if dims not in ((0,), (0, 1)):
        raise ParameterError(f"dimensions={dimensions!r}: expected (0,) or (0, 1)")
    if isinstance(strong, bool) or not isinstance(strong, (int, float, np.integer, np.floating)) \
            or not np.isfinite(strong) or strong < 0:
        raise ParameterError(f"strong={strong!r}: expected a finite threshold >= 0 in units of <f_n>")
    if max_features is not None and (isinstance(max_features, bool)
                                     or not isinstance(max_features, (int, np.integer)) or max_features < 1):
        raise ParameterError(f"max_features={max_features!r}: expected None or an integer >= 1")
    return dims


@fill_doc
def network_persistence(ds: xr.Dataset, xi=DEFAULT_XI, dimensions=(0, 1), strong: float = 1.0,
                        walls: bool = False, near=None, max_features: int | None = None) -> xr.Dataset:
    """Persistent homology of each snapshot's force network, its Betti curves and its 3- and
    4-cycles by force class.

    The filtration: each selected contact is an edge of value xi_c = f_n,c / <f_n> (<f_n> the
    snapshot's mean over the selection); the complex at threshold xi holds the edges with
    xi_c >= xi — the network stronger than xi, the complement of the xi-network f_n < xi <f_n>
    (:func:`grainview.analysis.xi_network.xi_network`) — with their bodies, and every triangle of three
    such edges (clique complex: a triangle enters with its weakest edge). Lowering xi from the
    largest force to 0 adds contacts: a feature is born at xi = ``birth`` and dies at
    xi = ``death`` <= ``birth``; a body enters with its strongest contact. Dimension 0: the
    connected components (a component dies when it merges with one born at a larger xi, the
    elder rule); dimension 1: the loops of contacts not filled by triangles. Features of the
    whole network never die: ``death = -inf``. Zero-persistence pairs are left out.

    Betti curves: beta_k(xi) = #{features of dimension k : birth >= xi > death}, the number of
    components (k = 0) and of independent unfilled loops (k = 1) of the network above xi.

    Cycles (Tordesillas, Walker & Lin 2010): ``cycles_3[k]`` counts the 3-cycles (triangles) of
    the whole network with k strong edges, ``cycles_4[k]`` the 4-cycles without a chord
    (neither diagonal a contact: a 4-cycle with one is two 3-cycles) with k strong edges; a
    contact is strong when f_n >= ``strong`` <f_n>.

    In a periodic cell the network lives on the torus: the graph is that of the pairs (i, j),
    whatever boundary a contact crosses, so a loop may wind around the cell (its contacts'
    image shifts, :func:`grainview.analysis.arrays.periodic.contact_image_shifts`, sum to a
    non-zero number of cells). ``beta_1`` counts every independent unfilled loop, the winding
    ones included: on a 4 x 4 square lattice on the torus (16 particles, 32 contacts) it is
    32 - 16 + 1 = 17, the 16 squares (15 independent: their sum is zero) and 2 loops around the
    cell, one along each lattice vector. ``beta_1_winding`` (time, xi) counts the winding ones
    (:func:`grainview.analysis.arrays.network_topology.winding_loops`: per connected component
    the rank, 0, 1 or 2, of its loops' windings, summed), so that ``beta_1 - beta_1_winding``
    are the loops that close within the packing; a winding loop is never filled (no triangle
    winds). A strand of contacts around the cell is a winding loop: the network percolates
    along that direction. The 3- and 4-cycles are cycles of the graph: in a cell less than
    four particles wide, four contacts around it make a 4-cycle too (the 4 x 4 lattice has 24:
    16 squares and the 8 rows and columns).

    Walls are left out by default: a wall touches every particle along a side, so as a node it
    joins all of them into one component at the first wall contact and closes a loop with every
    pair of paths that reach it, loops of the box rather than of the packing. ``walls=True``
    makes each wall one node.

    All of it is the project's own code (numba kernels): dimension 0 by union-find, dimension 1
    by the standard reduction over Z/2 of the triangles' boundary matrix (with the twist), the
    cycles by merging sorted neighbour lists. The complex stops at the triangles: a 4-clique's
    four triangles (an octahedron's eight) close a 2-sphere, which no tetrahedron fills; its
    last triangle fills no loop, and the sphere is not reported (dimension 1 is the same as in
    the full clique complex). The tests check dimension 1 against gudhi
    (:func:`grainview.analysis.arrays.network_topology.diagrams_gudhi`, ``pip install
    'grainview[topology]'``), which is not needed to compute it.

    Parameters
    ----------
    {ds}
    xi : array_like of float, default 0, 0.05, ..., 5
        Thresholds of the Betti curves, multiples of <f_n> (dimensionless).
    dimensions : (0,) or (0, 1), default (0, 1)
        The homology dimensions; with (0,) ``beta_1`` is not returned.
    strong : float, default 1
        Strong-force threshold of the cycle counts, in units of <f_n> (dimensionless).
    walls : bool, default False
        Include the particle–wall contacts, each wall one node.
    near : float, optional
        Which pairs are contacts (:func:`grainview.analysis.contacts.in_network`); near pairs carry
        f_n = 0 and enter at xi = 0.
    max_features : int, optional
        Length of the ``feature`` dimension: the most persistent features of each snapshot are
        kept. Default: a bound no snapshot exceeds (contact slots + bodies / 2). The Betti
        curves count every feature whatever this is.

    Returns
    -------
    xarray.Dataset
        ``birth``, ``death`` (time, feature), in units of <f_n>, NaN padding, and ``dimension``
        (time, feature), 0 or 1, -1 in the padding: each snapshot's diagram, its features in
        decreasing persistence birth - death (the never-dying first); ``beta_0``, ``beta_1``
        (time, xi); ``cycles_3``, ``cycles_4`` (time, strong_edges), strong_edges = 0..4; in a
        periodic cell with dimension 1 also ``beta_1_winding`` (time, xi). Lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        On a bad argument.

    References
    ----------
    Kramár, Goullet, Kondic & Mischaikow, Phys. Rev. E 87, 042207 (2013): persistence of force
    networks filtered by force; Tordesillas, Walker & Lin, Phys. Rev. E 81, 011302 (2010):
    3- and 4-cycles of the contact network; Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76,
    011301 (2007), Sec. V.C: the xi-network.
    """
    xi = _check_xi(xi)
    dims = _check_options(dimensions, strong, max_features)
    dimension_1 = 1 in dims
    n_nodes = body_count(ds) if walls else ds.sizes["particle"]
    bound = ds.sizes["contact"] + n_nodes // 2 + 1
    n_features = bound if max_features is None else int(max_features)
    outputs = apply(_topology.network_persistence, ds["fn"], ds["i"], ds["j"], selection(ds, walls=walls, near=near),
                    output_sizes={"feature": n_features, "xi": xi.size, "strong_edges": _topology.N_STRONG_EDGES},
                    kwargs={"xi": xi, "n_nodes": n_nodes, "n_features": n_features, "strong": float(strong),
                            "dimension_1": dimension_1},
                    output_dtypes=[float, float, np.int8, np.int64, np.int64, np.int64, np.int64])
    birth, death, dimension, beta_0, beta_1, cycles_3, cycles_4 = outputs
    winding = None
    if dimension_1 and "cell" in ds.variables:
        shift = apply(_periodic.contact_image_shifts, ds["i"], ds["j"], ds["branch"], ds["position"], ds["cell"],
                      kwargs={"periodic": np.asarray(ds["periodic"].values, bool)}, output_dtypes=[np.int64])
        winding = apply(_topology.winding_loops, ds["fn"], ds["i"], ds["j"], selection(ds, walls=walls, near=near),
                        shift, output_sizes={"xi": xi.size}, kwargs={"xi": xi, "n_nodes": n_nodes},
                        output_dtypes=[np.int64])
    out = xr.Dataset({
        "birth": with_attrs(birth, "birth", "1", "threshold xi = f_n/<f_n> at which the feature appears"),
        "death": with_attrs(death, "death", "1",
                            "threshold xi = f_n/<f_n> at which the feature disappears (-inf: never)"),
        "dimension": with_attrs(dimension, "dimension", "1",
                                "homology dimension of the feature: 0 component, 1 loop; -1 padding"),
        "beta_0": with_attrs(beta_0, "beta_0", "1", "connected components of the network with f_n >= xi <f_n>"),
        "cycles_3": with_attrs(cycles_3, "cycles_3", "1", "3-cycles with strong_edges strong contacts"),
        "cycles_4": with_attrs(cycles_4, "cycles_4", "1", "chordless 4-cycles with strong_edges strong contacts"),
    })
    if dimension_1:
        out["beta_1"] = with_attrs(beta_1, "beta_1", "1",
                                   "independent loops not filled by triangles of the network with f_n >= xi <f_n>")
    if winding is not None:
        out["beta_1_winding"] = with_attrs(winding, "beta_1_winding", "1",
                                           "independent loops of the network with f_n >= xi <f_n> that wind around "
                                           "the periodic cell")
    out = out.assign_coords(
        xi=("xi", xi, {"units": "1", "long_name": "force threshold xi (contacts with f_n >= xi <f_n>)"}),
        strong_edges=("strong_edges", np.arange(_topology.N_STRONG_EDGES),
                      {"units": "1", "long_name": f"number of strong edges (f_n >= {float(strong):g} <f_n>)"}))
    out.attrs.update(walls=int(walls), near=near_attr(near), strong=float(strong), dimensions=list(dims))
    return out
