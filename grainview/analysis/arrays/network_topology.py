"""Topology of the force network: persistent homology of the contact graph filtered by
decreasing normal force, its Betti curves, and its short cycles by force class.

The filtration. Each contact c of the selection is an edge between its two bodies with the
value xi_c = f_n,c / <f_n> (<f_n> the mean over the selection, the xi-network's scale). The
complex at threshold xi holds the edges with xi_c >= xi (the complement of the xi-network
f_n < xi <f_n>: the network stronger than xi), their nodes, and every triangle of three such
edges (the clique, or flag, complex: a triangle enters with its weakest edge). Lowering xi
from +inf to 0 adds edges, so features are born at a larger xi than they die; a node enters
with its strongest contact. A feature alive at the end (xi = 0: the whole selection) has
death = -inf. Betti curves: beta_k(xi) = #{features of dimension k : birth >= xi > death}.

Both dimensions are the project's own numba kernels: dimension 0 (connected components) the
union-find of :func:`grainview.analysis._kernels.network_topology.union_find_pairs`, dimension 1 (loops
not filled by triangles) the standard reduction over Z/2 of the triangles' boundary matrix, with
the twist (:func:`grainview.analysis._kernels.network_topology.flag_persistence_1`). The complex stops at
the triangles: the triangles of a 4-clique (or of an octahedron) close a 2-sphere that no
tetrahedron fills; the last of them to enter fills no loop and the sphere is not reported.
Dimension 1 is the same with or without the higher cliques (the homology of dimension 1
depends on the edges and triangles alone) and the same as gudhi's (``expansion(2)``, Z/2,
:func:`diagrams_gudhi`: the cross-check, ``pip install 'grainview[topology]'``).
Zero-persistence pairs (birth == death) are left out; ties between values may change which
simplex a feature is paired with but not the diagram.

References
----------
Kramár, Goullet, Kondic & Mischaikow, Phys. Rev. E 87, 042207 (2013) (persistence of force
networks); Tordesillas, Walker & Lin, Phys. Rev. E 81, 011302 (2010) (3- and 4-cycles).
"""

from __future__ import annotations

import numpy as np

from .._kernels.network_topology import cycle_counts, flag_persistence_1, union_find_pairs, winding_ranks
from ...contract.errors import ParameterError
from .force_pdf import mean_normal_force
from .signature import CONTACT, CONTACT_XY, core_dims

FEATURE = ("feature",)
XI = ("xi",)
STRONG_EDGES = ("strong_edges",)
N_STRONG_EDGES = 5
"""Size of the ``strong_edges`` dimension: a cycle of 3 or 4 edges has 0 to 4 strong edges."""

GUDHI_MISSING = ("diagrams_gudhi, the cross-check of the force network's persistence, needs the TDA library gudhi: "
                 "pip install 'grainview[topology]' (network_persistence computes both dimensions without it)")


def gudhi_module():
    """The gudhi module (for :func:`diagrams_gudhi`), or a
    :class:`~grainview.contract.errors.ParameterError` in one line saying how to install it."""
    try:
        import gudhi
    except ImportError:
        raise ParameterError(GUDHI_MISSING) from None
    return gudhi


def filtration_edges(fn, i, j, mask):
    """One snapshot's graph: the selected contacts as edges sorted by decreasing value.

    Parameters
    ----------
    fn : ndarray, shape (C,)
        Normal forces (N).
    i, j : ndarray of int, shape (C,)
        The contacts' bodies.
    mask : ndarray of bool, shape (C,)
        The selected contacts.

    Returns
    -------
    u, v : ndarray of int64, shape (E,)
        The edges' endpoints (u < v), each pair once (a pair listed twice keeps its larger force).
    value : ndarray of float64, shape (E,)
        xi_e = f_n / <f_n> (dimensionless), <f_n> the mean over the selection (0 for every edge
        when <f_n> = 0: a selection of unloaded near pairs); non-increasing.
    """
    mask = np.asarray(mask, bool)
    if not mask.any():
        empty = np.empty(0, np.int64)
        return empty, empty, np.empty(0)
    a = np.asarray(i)[mask].astype(np.int64)
    b = np.asarray(j)[mask].astype(np.int64)
    mean = mean_normal_force(fn, mask)
    forces = np.asarray(fn, np.float64)[mask]
    value = forces / mean if mean > 0 else np.zeros_like(forces)  # only unloaded pairs: all enter at xi = 0
    if np.any(a == b) or np.any(a < 0) or np.any(b < 0):
        raise ParameterError("network persistence: a selected contact joins a body to itself or to a "
                             "negative body id; expected two different bodies >= 0")
    u, v = np.minimum(a, b), np.maximum(a, b)
    order = np.lexsort((-value, v, u))  # by pair, the largest value first
    u, v, value = u[order], v[order], value[order]
    first = np.ones(u.size, bool)
    first[1:] = (u[1:] != u[:-1]) | (v[1:] != v[:-1])
    u, v, value = u[first], v[first], value[first]
    order = np.argsort(-value, kind="stable")
    return u[order], v[order], value[order]


def _check_nodes(u, v, n_nodes):
    if u.size and max(u.max(), v.max()) >= n_nodes:
        raise ParameterError(f"network persistence: a contact names body {max(u.max(), v.max())}, "
                             f"expected ids below {n_nodes} (particles and walls)")


def diagram_0(u, v, value, n_nodes):
    """0-dimensional diagram by the project's union-find (elder rule).

    Parameters
    ----------
    u, v, value : ndarray
        Edges as :func:`filtration_edges` gives them (sorted by decreasing value).
    n_nodes : int
        Node ids are in [0, n_nodes).

    Returns
    -------
    birth, death : ndarray of float64
        One pair per component's life, birth > death; death = -inf for the components of the
        whole graph.
    """
    _check_nodes(u, v, n_nodes)
    if u.size and np.any(np.diff(value) > 0):
        raise ParameterError("network persistence: edges must be sorted by decreasing value")
    birth, death, _ = union_find_pairs(int(n_nodes), np.ascontiguousarray(u, np.int64),
                                       np.ascontiguousarray(v, np.int64), np.ascontiguousarray(value, np.float64))
    return birth, death


def diagram_1(u, v, value, n_nodes):
    """1-dimensional diagram of the clique complex (edges and triangles) by the project's
    reduction over Z/2 (:func:`grainview.analysis._kernels.network_topology.flag_persistence_1`).

    A loop is born at the value of the edge that closes it and dies at the value of the
    triangle that fills it, a triangle entering with its weakest edge (the smallest value of
    its three). A triangle that closes a 2-sphere (the last of a 4-clique's four) fills no loop;
    the sphere is not reported.

    Parameters
    ----------
    u, v, value : ndarray
        Edges as :func:`filtration_edges` gives them (sorted by decreasing value).
    n_nodes : int
        Node ids are in [0, n_nodes).

    Returns
    -------
    birth, death : ndarray of float64
        One pair per loop, birth > death; death = -inf for a loop that no triangle fills.
    """
    _check_nodes(u, v, n_nodes)
    if u.size and np.any(np.diff(value) > 0):
        raise ParameterError("network persistence: edges must be sorted by decreasing value")
    birth, death, _ = flag_persistence_1(int(n_nodes), np.ascontiguousarray(u, np.int64),
                                         np.ascontiguousarray(v, np.int64), np.ascontiguousarray(value, np.float64))
    return birth, death


def diagrams_gudhi(u, v, value, n_nodes):
    """0- and 1-dimensional diagrams of the flag complex by gudhi (the filtration negated, as
    gudhi's filtrations increase), the cross-check of :func:`diagram_0` and :func:`diagram_1`.

    The complex is expanded to the triangles (``expansion(2)``) and its persistence computed
    over Z/2 in every dimension up to 2 (``persistence_dim_max=True``); the 2-dimensional
    classes (spheres of triangles) are not returned.

    Parameters
    ----------
    u, v, value : ndarray
        Edges as :func:`filtration_edges` gives them.
    n_nodes : int
        Node ids are in [0, n_nodes).

    Returns
    -------
    dict
        ``{0: (birth, death), 1: (birth, death)}`` in xi, death = -inf for a feature that never
        dies; zero-persistence pairs left out.
    """
    gudhi = gudhi_module()
    _check_nodes(u, v, n_nodes)
    out = {0: (np.empty(0), np.empty(0)), 1: (np.empty(0), np.empty(0))}
    if u.size == 0:
        return out
    node_birth = np.full(int(n_nodes), -np.inf)
    np.maximum.at(node_birth, u, value)
    np.maximum.at(node_birth, v, value)
    nodes = np.flatnonzero(np.isfinite(node_birth))
    tree = gudhi.SimplexTree()
    tree.insert_batch(nodes[None, :], -node_birth[nodes])
    tree.insert_batch(np.stack([u, v]), -np.asarray(value, float))
    tree.expansion(2)
    tree.compute_persistence(homology_coeff_field=2, min_persistence=0.0, persistence_dim_max=True)
    for dim in (0, 1):
        pairs = np.asarray(tree.persistence_intervals_in_dimension(dim), float).reshape(-1, 2)
        out[dim] = (-pairs[:, 0], -pairs[:, 1])
    return out


def betti_curve(birth, death, xi):
    """beta(xi) = #{features : birth >= xi > death} at each threshold of ``xi`` (K,).

    Parameters
    ----------
    birth, death : ndarray of float
        One dimension's diagram (birth >= death).
    xi : ndarray of float, shape (K,)
        Thresholds (dimensionless).

    Returns
    -------
    ndarray of int64, shape (K,)
    """
    xi = np.asarray(xi, float)
    born = np.sort(np.asarray(birth, float))
    dead = np.sort(np.asarray(death, float))
    # birth >= xi counts born.size - #{birth < xi}; death >= xi implies birth >= xi
    return (np.searchsorted(dead, xi, side="left") - np.searchsorted(born, xi, side="left")).astype(np.int64)


def short_cycles(u, v, value, n_nodes, strong=1.0):
    """Counts of the 3-cycles and the chordless 4-cycles by their number of strong edges.

    An edge is strong when xi_e >= ``strong`` (f_n >= strong <f_n>; ``strong=1``: the strong
    network of Radjai et al., the complement of the xi-network at xi = 1).

    Parameters
    ----------
    u, v, value : ndarray
        Edges as :func:`filtration_edges` gives them.
    n_nodes : int
        Node ids are in [0, n_nodes).
    strong : float, default 1
        The strong-force threshold in units of <f_n>.

    Returns
    -------
    triangles, squares : ndarray of int64, shape (5,)
        Element k: the cycles with k strong edges (``triangles[4]`` is 0).
    """
    _check_nodes(u, v, n_nodes)
    triangles, squares = cycle_counts(int(n_nodes), np.ascontiguousarray(u, np.int64),
                                      np.ascontiguousarray(v, np.int64),
                                      (np.asarray(value) >= strong).astype(np.int64))
    return np.concatenate([triangles, [0]]), squares


@core_dims(CONTACT, CONTACT, CONTACT, CONTACT, out=(FEATURE, FEATURE, FEATURE, XI, XI, STRONG_EDGES, STRONG_EDGES))
def network_persistence(fn, i, j, mask, xi, n_nodes, n_features, strong=1.0, dimension_1=True):
    """Persistence diagrams, Betti curves and short cycles of each snapshot's force network.

    Parameters
    ----------
    fn : ndarray, shape (..., C)
        Normal forces (N), f_n > 0 compressive.
    i, j : ndarray of int, shape (..., C)
        The contacts' bodies (particles 0..N-1, walls N + w).
    mask : ndarray of bool, shape (..., C)
        The contacts of the network.
    xi : ndarray, shape (K,)
        Thresholds of the Betti curves, in units of <f_n>.
    n_nodes : int
        Body ids are in [0, n_nodes).
    n_features : int
        Length of the padded ``feature`` axis; the most persistent features are kept.
    strong : float, default 1
        Strong-force threshold of the cycle counts, in units of <f_n>.
    dimension_1 : bool, default True
        Compute the 1-dimensional diagram (:func:`diagram_1`); otherwise it is empty and
        beta_1 = -1.

    Returns
    -------
    birth, death : ndarray of float64, shape (..., n_features)
        In units of <f_n>; death = -inf for a feature that never dies; NaN padding. Features
        in decreasing persistence birth - death (the never-dying first), then by dimension.
    dimension : ndarray of int8, shape (..., n_features)
        0 or 1; -1 in the padding.
    beta_0, beta_1 : ndarray of int64, shape (..., K)
        Betti curves.
    triangles, squares : ndarray of int64, shape (..., 5)
        3-cycles and chordless 4-cycles with k = 0..4 strong edges.
    """
    fn = np.asarray(fn)
    lead = fn.shape[:-1]
    flat = [np.asarray(a).reshape(-1, fn.shape[-1]) for a in (fn, i, j, mask)]
    rows = flat[0].shape[0]
    xi = np.asarray(xi, float)
    birth = np.full((rows, n_features), np.nan)
    death = np.full((rows, n_features), np.nan)
    dimension = np.full((rows, n_features), -1, np.int8)
    beta = np.full((2, rows, xi.size), -1, np.int64)
    triangles = np.zeros((rows, N_STRONG_EDGES), np.int64)
    squares = np.zeros((rows, N_STRONG_EDGES), np.int64)
    for r in range(rows):
        u, v, value = filtration_edges(*(a[r] for a in flat))
        diagrams = {0: diagram_0(u, v, value, n_nodes)}
        if dimension_1:
            diagrams[1] = diagram_1(u, v, value, n_nodes)
        for dim, (b, d) in diagrams.items():
            beta[dim, r] = betti_curve(b, d, xi)
        b = np.concatenate([diagrams[dim][0] for dim in diagrams])
        d = np.concatenate([diagrams[dim][1] for dim in diagrams])
        k = np.concatenate([np.full(diagrams[dim][0].size, dim, np.int8) for dim in diagrams])
        order = np.lexsort((-b, k, -(b - d)))[:n_features]
        birth[r, :order.size], death[r, :order.size], dimension[r, :order.size] = b[order], d[order], k[order]
        triangles[r], squares[r] = short_cycles(u, v, value, n_nodes, strong)
    shape = lambda a: a.reshape(lead + a.shape[1:])  # noqa: E731
    return (shape(birth), shape(death), shape(dimension), shape(beta[0]), shape(beta[1]), shape(triangles),
            shape(squares))


@core_dims(CONTACT, CONTACT, CONTACT, CONTACT, CONTACT_XY, out=(XI,))
def winding_loops(fn, i, j, mask, shift, xi, n_nodes):
    """The independent loops of each snapshot's force network above each threshold that wind
    around a periodic cell.

    The network's edges are those of :func:`filtration_edges` (a pair listed twice keeps its
    larger force, and the shift of that slot); each edge carries the whole cells ``shift``
    (m, n) between the stored centre of j and the image of j it touches. A loop winds when its
    shifts sum to a non-zero (m, n); the loops of a connected component wind along a lattice of
    rank 0, 1 or 2 (around the cell along a, b or both), and the count is the sum of these ranks
    over the components (:func:`grainview.analysis._kernels.network_topology.winding_ranks`).
    It is at most beta_1: no triangle winds, so a winding loop is never filled, and
    beta_1 - winding are the loops that close within the packing. Two components that each
    wind along a count 2; joined by a contact, 1 (the loop around the band between them
    winds zero times), so the count need not grow as the threshold falls.

    Parameters
    ----------
    fn : ndarray, shape (..., C)
        Normal forces (N).
    i, j : ndarray of int, shape (..., C)
        The contacts' bodies.
    mask : ndarray of bool, shape (..., C)
        The contacts of the network.
    shift : ndarray of int, shape (..., C, 2)
        Each contact's image shift (m, n) (0 for a wall contact).
    xi : ndarray, shape (K,)
        Thresholds, in units of <f_n>.
    n_nodes : int
        Body ids are in [0, n_nodes).

    Returns
    -------
    ndarray of int64, shape (..., K)
        The winding loops of the network with f_n >= xi <f_n>.
    """
    fn = np.asarray(fn)
    n_c = fn.shape[-1]
    lead = fn.shape[:-1]
    flat = [np.asarray(a).reshape(-1, n_c) for a in (fn, i, j, mask)]
    shifts = np.asarray(shift, np.int64).reshape(-1, n_c, 2)
    xi = np.asarray(xi, float)
    out = np.zeros((flat[0].shape[0], xi.size), np.int64)
    for r in range(out.shape[0]):
        fn_r, i_r, j_r, mask_r = (a[r] for a in flat)
        u, v, value = filtration_edges(fn_r, i_r, j_r, mask_r)
        if u.size == 0:
            continue
        _check_nodes(u, v, n_nodes)
        # the same edges with their shifts, oriented from u to v (s of j seen from i; negated when i > j)
        sel = np.flatnonzero(np.asarray(mask_r, bool))
        a, b = np.asarray(i_r)[sel].astype(np.int64), np.asarray(j_r)[sel].astype(np.int64)
        s = shifts[r, sel] * np.where(a <= b, 1, -1)[:, None]
        forces = np.asarray(fn_r, np.float64)[sel]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        order = np.lexsort((-forces, hi, lo))  # as filtration_edges: by pair, the largest force first
        lo, hi, s = lo[order], hi[order], s[order]
        first = np.ones(lo.size, bool)
        first[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
        key = lo[first] * (int(n_nodes) + 1) + hi[first]
        s = s[first]
        index = np.argsort(key)
        where = np.searchsorted(key[index], u * (int(n_nodes) + 1) + v)
        edge_shift = np.ascontiguousarray(s[index[where]])
        ranks = winding_ranks(int(n_nodes), np.ascontiguousarray(u, np.int64), np.ascontiguousarray(v, np.int64),
                              edge_shift)
        entered = np.searchsorted(-value, -xi, side="right")  # edges with value >= xi (value non-increasing)
        out[r] = np.where(entered > 0, ranks[np.maximum(entered - 1, 0)], 0)
    return out.reshape(lead + (xi.size,))


__all__ = ["winding_loops", "filtration_edges", "diagram_0", "diagram_1", "diagrams_gudhi", "betti_curve", "short_cycles",
           "network_persistence", "gudhi_module", "FEATURE", "XI", "STRONG_EDGES"]
