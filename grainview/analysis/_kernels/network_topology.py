"""Numba kernels of the force network's topology: the 0-dimensional persistence diagram by
union-find, the 1-dimensional diagram of the clique complex by the standard reduction of its
triangles' boundary matrix over Z/2, and the counts of 3-cycles and chordless 4-cycles by their
number of strong edges.

Structure of arrays: a graph is given as its edge endpoints ``u``, ``v`` (int64, node ids in
[0, n_nodes)) and one value per edge; :mod:`grainview.analysis.arrays.network_topology` checks them
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
    # 3-cycles: every triangle once, by its three edges (_triangles)
    found = _triangles(n_nodes, u, v)
    for row in range(found.shape[0]):
        triangles[strong[found[row, 0]] + strong[found[row, 1]] + strong[found[row, 2]]] += 1
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


@njit(cache=True)
def _triangles(n_nodes, u, v):
    """Every triangle of a simple graph as its three edge ids, largest first.

    Returns
    -------
    ndarray of int64, shape (T, 3)
        Row k: the ids e0 > e1 > e2 of the k-th triangle's edges, the rows in lexicographic
        order of (e0, e1, e2).
    """
    start, neighbour, edge = _adjacency(n_nodes, u, v)
    count = 0
    out = np.empty((0, 3), np.int64)
    for twice in range(2):  # count, then fill
        if twice == 1:
            out = np.empty((count, 3), np.int64)
            count = 0
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
                    if neighbour[p] > b:
                        if twice == 1:
                            x, y, z = e, edge[p], edge[q]
                            if x < y:
                                x, y = y, x
                            if y < z:
                                y, z = z, y
                            if x < y:
                                x, y = y, x
                            out[count, 0] = x
                            out[count, 1] = y
                            out[count, 2] = z
                        count += 1
                    p += 1
                    q += 1
    if count == 0:
        return np.empty((0, 3), np.int64)
    n_edges = u.size
    order = np.argsort(out[:, 1] * n_edges + out[:, 2], kind="mergesort")
    out = out[order]
    order = np.argsort(out[:, 0], kind="mergesort")
    return out[order]


@njit(cache=True)
def _add_columns(a, b):
    """Sum over Z/2 of two columns, each its row ids in decreasing order (the symmetric
    difference, a merge)."""
    out = np.empty(a.size + b.size, np.int64)
    p = 0
    q = 0
    n = 0
    while p < a.size and q < b.size:
        if a[p] > b[q]:
            out[n] = a[p]
            p += 1
            n += 1
        elif a[p] < b[q]:
            out[n] = b[q]
            q += 1
            n += 1
        else:
            p += 1
            q += 1
    while p < a.size:
        out[n] = a[p]
        p += 1
        n += 1
    while q < b.size:
        out[n] = b[q]
        q += 1
        n += 1
    return out[:n]


@njit(cache=True)
def flag_persistence_1(n_nodes, u, v, value):
    """1-dimensional persistence of the clique complex of a graph filtered by DECREASING edge
    value, over Z/2, up to its triangles.

    The filtration: the edges in the given order, which must be by non-increasing ``value``
    (ties broken by that order), each triangle right after its last edge (the one of largest
    id; triangles after the same edge by the ids of their other two, lexicographically), so a
    triangle enters at the smallest value of its three edges. The standard persistence
    algorithm with the twist (clearing): the boundary matrix of the triangles (rows: edges,
    columns: triangles in filtration order) is reduced first, left to right, adding to a
    column the reduced column with the same lowest row (largest edge id) until that row is
    free or the column is zero. A column left non-zero pairs its lowest edge (a loop born at
    that edge's value) with the triangle (the loop dies at the triangle's value). Those edges
    close loops, so they are cleared from the edges' own reduction, which is the union-find of
    the remaining edges in order: an edge that joins two components is paired with a node
    (dimension 0); one whose ends are already joined closes a loop, and a loop no triangle
    kills never dies (death = -inf). Pairs with birth == death are left out.

    A column that reduces to zero is a triangle that closes a 2-cycle (the four triangles of a
    4-clique, the eight of an octahedron: a sphere of triangles) instead of filling a loop; no
    tetrahedra are added, so these spheres are never filled, and they are not reported. They
    change nothing in dimension 1, whose homology depends on the edges and triangles alone.

    Parameters
    ----------
    n_nodes : int
        Node ids are in [0, n_nodes).
    u, v : ndarray of int64, shape (E,)
        The edges' endpoints, each pair once, no self-loop.
    value : ndarray of float64, shape (E,)
        The edges' filtration values, non-increasing.

    Returns
    -------
    birth, death : ndarray of float64, shape (P,)
        The loops, in the order of the edges that close them: birth = the value of that edge,
        death = the value of the triangle that fills the loop, -inf if none does; birth > death.
    n_triangles : int
        Number of triangles of the whole graph.
    """
    n_edges = u.size
    tri = _triangles(n_nodes, u, v)
    owner = np.full(n_edges, -1, np.int64)  # the stored reduced column whose lowest row is this edge
    dies = np.full(n_edges, -1, np.int64)  # the triangle that kills the loop born at this edge
    column_start = np.empty(tri.shape[0] + 1, np.int64)
    column_start[0] = 0
    pool = np.empty(max(16, 3 * tri.shape[0]), np.int64)
    n_stored = 0
    for t in range(tri.shape[0]):
        col = tri[t].copy()
        while col.size > 0 and owner[col[0]] >= 0:
            k = owner[col[0]]
            col = _add_columns(col, pool[column_start[k]:column_start[k + 1]])
        if col.size == 0:
            continue  # a 2-cycle closes
        top = column_start[n_stored]
        if top + col.size > pool.size:
            bigger = np.empty(max(2 * pool.size, top + col.size), np.int64)
            bigger[:top] = pool[:top]
            pool = bigger
        pool[top:top + col.size] = col
        column_start[n_stored + 1] = top + col.size
        owner[col[0]] = n_stored
        dies[col[0]] = t
        n_stored += 1
    # the edges' columns, the paired ones cleared: union-find in order
    parent = np.arange(n_nodes)
    birth = np.empty(n_edges)
    death = np.empty(n_edges)
    n = 0
    for e in range(n_edges):
        if dies[e] >= 0:
            x = value[tri[dies[e], 0]]  # the triangle enters with its last edge
            if value[e] > x:
                birth[n] = value[e]
                death[n] = x
                n += 1
            continue
        ra = _find(parent, u[e])
        rb = _find(parent, v[e])
        if ra != rb:
            parent[rb] = ra
        else:
            birth[n] = value[e]
            death[n] = -np.inf
            n += 1
    return birth[:n], death[:n], tri.shape[0]


@njit(cache=True)
def _offset_root(parent, offset, a):
    """Root of ``a`` and the image offset of ``a`` relative to it (p_a - p_root, whole cells),
    compressing the path (each node on it then points to the root, its offset summed)."""
    root = a
    ox = 0
    oy = 0
    while parent[root] != root:
        ox += offset[root, 0]
        oy += offset[root, 1]
        root = parent[root]
    # compress: walk again, giving each node its offset to the root
    node = a
    rx = ox
    ry = oy
    while parent[node] != node:
        nxt = parent[node]
        nx_ = rx - offset[node, 0]
        ny_ = ry - offset[node, 1]
        offset[node, 0] = rx
        offset[node, 1] = ry
        parent[node] = root
        node = nxt
        rx = nx_
        ry = ny_
    return root, ox, oy


@njit(cache=True)
def winding_ranks(n_nodes, u, v, shift):
    """The number of independent loops that wind around a periodic cell, after each edge of a
    graph whose edges cross the cell's boundary by whole cells.

    Each edge e = (u, v) carries the shift s_e = (m, n), the whole cells between the image of
    v it reaches and the stored v (p_v = p_u + s_e, p a node's image). A loop's winding is the
    sum of the shifts along it; the loops of a connected component wind along a sublattice of
    Z^2 of rank 0, 1 or 2, and the number of independent loops that wind is the sum of these
    ranks over the components. Union-find with offsets: each node keeps p_node - p_root; an
    edge inside a component closes a loop of winding p_u + s_e - p_v; components that merge
    keep the span of both their windings.

    Parameters
    ----------
    n_nodes : int
        Node ids are in [0, n_nodes).
    u, v : ndarray of int64, shape (E,)
        The edges' endpoints, in the order they enter.
    shift : ndarray of int64, shape (E, 2)
        Each edge's shift (m, n).

    Returns
    -------
    ndarray of int64, shape (E,)
        The number of independent winding loops of the graph of the first e + 1 edges.
    """
    parent = np.arange(n_nodes)
    size = np.ones(n_nodes, np.int64)
    offset = np.zeros((n_nodes, 2), np.int64)
    rank = np.zeros(n_nodes, np.int64)
    basis = np.zeros((n_nodes, 2), np.int64)  # a component of rank 1: its winding direction
    out = np.empty(u.size, np.int64)
    total = 0
    for e in range(u.size):
        ra, ax, ay = _offset_root(parent, offset, u[e])
        rb, bx, by = _offset_root(parent, offset, v[e])
        sx = shift[e, 0]
        sy = shift[e, 1]
        if ra == rb:
            wx = ax + sx - bx
            wy = ay + sy - by
            if (wx != 0 or wy != 0) and rank[ra] < 2:
                if rank[ra] == 0:
                    rank[ra] = 1
                    basis[ra, 0] = wx
                    basis[ra, 1] = wy
                    total += 1
                elif basis[ra, 0] * wy - basis[ra, 1] * wx != 0:
                    rank[ra] = 2
                    total += 1
        else:
            # p_rb - p_ra = (p_v - b) - (p_u - a) = s + a - b
            dx = sx + ax - bx
            dy = sy + ay - by
            if size[ra] < size[rb]:
                ra, rb = rb, ra
                dx = -dx
                dy = -dy
            parent[rb] = ra
            offset[rb, 0] = dx
            offset[rb, 1] = dy
            size[ra] += size[rb]
            before = rank[ra] + rank[rb]
            if rank[ra] == 2 or rank[rb] == 2:
                merged = 2
            elif rank[ra] == 1 and rank[rb] == 1:
                cross = basis[ra, 0] * basis[rb, 1] - basis[ra, 1] * basis[rb, 0]
                merged = 2 if cross != 0 else 1
            elif rank[rb] == 1:
                merged = 1
                basis[ra, 0] = basis[rb, 0]
                basis[ra, 1] = basis[rb, 1]
            else:
                merged = rank[ra]
            rank[ra] = merged
            total += merged - before
        out[e] = total
    return out
