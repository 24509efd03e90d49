"""Numba kernels of the force network's topology: the 0-dimensional persistence diagram by
union-find, and the counts of 3-cycles and chordless 4-cycles by their number of strong edges.

Structure of arrays: a graph is given as its edge endpoints ``u``, ``v`` (int64, node ids in
[0, n_nodes)) and one value per edge; :mod:`grainview.arrays.network_topology` checks them
before calling.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _find(parent, a):
    """Root of ``a``, compressing the path (each node on it points to its grandparent)."""
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def union_find_pairs(n_nodes, u, v, value):
    """0-dimensional persistence of a graph filtered by DECREASING edge value (elder rule).

    The edges are taken in the given order, which must be by non-increasing ``value``; a node
    enters with its first edge, so its birth is the largest value among its edges. When an
    edge joins two components, the one born at the smaller value (the younger) dies at the
    edge's value. Pairs with birth == death (a node entering with the edge that joins it) are
    left out, as zero-persistence pairs are.

    Parameters
    ----------
    n_nodes : int
        Node ids are in [0, n_nodes).
    u, v : ndarray of int64, shape (E,)
        The edges' endpoints.
    value : ndarray of float64, shape (E,)
        The edges' filtration values, non-increasing.

    Returns
    -------
    birth, death : ndarray of float64, shape (P,)
        The finite pairs (birth > death), then one pair per component of the whole graph with
        death = -inf (it never dies).
    n_nodes_in : int
        Number of nodes with at least one edge.
    """
    parent = np.arange(n_nodes)
    born = np.full(n_nodes, np.nan)  # a root's component birth; NaN: the node has not entered
    birth = np.empty(u.size + n_nodes)
    death = np.empty(u.size + n_nodes)
    n = 0
    n_in = 0
    for e in range(u.size):
        a = u[e]
        b = v[e]
        x = value[e]
        if np.isnan(born[a]):
            born[a] = x
            n_in += 1
        if np.isnan(born[b]):
            born[b] = x
            n_in += 1
        ra = _find(parent, a)
        rb = _find(parent, b)
        if ra == rb:
            continue
        if born[ra] < born[rb]:  # ra is the younger: it dies
            ra, rb = rb, ra
        # now rb is the younger (or as old)
        if born[rb] > x:
            birth[n] = born[rb]
            death[n] = x
            n += 1
        parent[rb] = ra
    for a in range(n_nodes):
        if not np.isnan(born[a]) and parent[a] == a:
            birth[n] = born[a]
            death[n] = -np.inf
            n += 1
    return birth[:n], death[:n], n_in


@njit(cache=True)
def _adjacency(n_nodes, u, v):
    """CSR adjacency of an undirected simple graph: ``start`` (n_nodes + 1), and per node its
    neighbours in ascending order with the id of the edge to each."""
    degree = np.zeros(n_nodes + 1, np.int64)
    for e in range(u.size):
        degree[u[e] + 1] += 1
        degree[v[e] + 1] += 1
    start = np.cumsum(degree)
    fill = start[:-1].copy()
    neighbour = np.empty(2 * u.size, np.int64)
    edge = np.empty(2 * u.size, np.int64)
    for e in range(u.size):
        neighbour[fill[u[e]]] = v[e]
        edge[fill[u[e]]] = e
        fill[u[e]] += 1
        neighbour[fill[v[e]]] = u[e]
        edge[fill[v[e]]] = e
        fill[v[e]] += 1
    for a in range(n_nodes):
        lo = start[a]
        hi = start[a + 1]
        order = np.argsort(neighbour[lo:hi])
        neighbour[lo:hi] = neighbour[lo:hi][order]
        edge[lo:hi] = edge[lo:hi][order]
    return start, neighbour, edge


@njit(cache=True)
def _edge_id(start, neighbour, edge, a, b):
    """Id of the edge between ``a`` and ``b``, or -1 (binary search in a's neighbours)."""
    lo = start[a]
    hi = start[a + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if neighbour[mid] < b:
            lo = mid + 1
        else:
            hi = mid
    if lo < start[a + 1] and neighbour[lo] == b:
        return edge[lo]
    return -1


@njit(cache=True)
def cycle_counts(n_nodes, u, v, strong):
    """Counts of the 3-cycles and of the chordless 4-cycles of a simple graph, by the number
    of their edges that are strong.

    Parameters
    ----------
    n_nodes : int
        Node ids are in [0, n_nodes).
    u, v : ndarray of int64, shape (E,)
        The edges' endpoints, each edge once, no self-loop.
    strong : ndarray of int64, shape (E,)
        1 where the edge is strong, 0 where it is weak.

    Returns
    -------
    triangles : ndarray of int64, shape (4,)
        ``triangles[k]``: the 3-cycles with k strong edges.
    squares : ndarray of int64, shape (5,)
        ``squares[k]``: the 4-cycles without a chord (neither diagonal an edge) with k strong
        edges.
    """
    start, neighbour, edge = _adjacency(n_nodes, u, v)
    triangles = np.zeros(4, np.int64)
    squares = np.zeros(5, np.int64)
    # 3-cycles a < b < c: for each edge (a, b), the common neighbours c > b (a merge of two sorted lists)
    for e in range(u.size):
        a = min(u[e], v[e])
        b = max(u[e], v[e])
        p = start[a]
        q = start[b]
        while p < start[a + 1] and q < start[b + 1]:
            if neighbour[p] < neighbour[q]:
                p += 1
            elif neighbour[p] > neighbour[q]:
                q += 1
            else:
                c = neighbour[p]
                if c > b:
                    triangles[strong[e] + strong[edge[p]] + strong[edge[q]]] += 1
                p += 1
                q += 1
    # chordless 4-cycles a - m1 - c - m2 - a: for each node a and each c > a not adjacent to a,
    # the 2-paths a - m - c; two of them whose middles are not adjacent close such a cycle.
    # Each cycle has two diagonals, both non-edges, and is met once from each: counted twice.
    max_deg = 0
    for a in range(n_nodes):
        max_deg = max(max_deg, start[a + 1] - start[a])
    far = np.empty(max_deg * max_deg, np.int64)
    middle = np.empty(max_deg * max_deg, np.int64)
    n_strong = np.empty(max_deg * max_deg, np.int64)
    twice = np.zeros(5, np.int64)
    for a in range(n_nodes):
        k = 0
        for p in range(start[a], start[a + 1]):
            m = neighbour[p]
            for q in range(start[m], start[m + 1]):
                c = neighbour[q]
                if c > a and _edge_id(start, neighbour, edge, a, c) < 0:
                    far[k] = c
                    middle[k] = m
                    n_strong[k] = strong[edge[p]] + strong[edge[q]]
                    k += 1
        order = np.argsort(far[:k])
        s = 0
        while s < k:
            t = s
            while t < k and far[order[t]] == far[order[s]]:
                t += 1
            for x in range(s, t):
                for y in range(x + 1, t):
                    if _edge_id(start, neighbour, edge, middle[order[x]], middle[order[y]]) < 0:
                        twice[n_strong[order[x]] + n_strong[order[y]]] += 1
            s = t
    for k in range(5):
        squares[k] = twice[k] // 2
    return triangles, squares
