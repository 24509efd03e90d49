"""Topology of the force network: hand-made graphs with known persistence diagrams, Betti
curves and cycle counts (eager and chunked, nothing computed until asked); the union-find, the
dimension-1 reduction and the cycle kernel against slow, obviously-correct versions; both
dimensions against gudhi, on random graphs and on every snapshot of sheared samples (of the
study's runs too, slow, when GRAINVIEW_STUDY names them)."""

import itertools
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from grainview.analysis.arrays import network_topology as nt
from grainview.contract.dataset import make_dataset
from grainview.contract.errors import ParameterError
from grainview.analysis.network_topology import network_persistence

from . import builders
from .conftest import raise_if_dask_computes

INF = np.inf

# ---------------------------------------------------------------- slow, obvious versions


def slow_diagram_0(u, v, value, n_nodes):
    """Elder rule from the components at each distinct threshold (scipy), no union-find: a node
    is born with its strongest edge; components that merge at t all die at t but the oldest."""
    node_birth = {}
    for a, b, x in zip(u, v, value):
        for node in (a, b):
            node_birth[node] = max(node_birth.get(node, -INF), x)
    pairs, previous = [], []
    for t in sorted(set(value), reverse=True):
        keep = value >= t
        graph = coo_matrix((np.ones(keep.sum()), (u[keep], v[keep])), shape=(n_nodes, n_nodes))
        _, labels = connected_components(graph, directed=False)
        present = sorted({int(x) for x in np.concatenate([u[keep], v[keep]])})
        components = {}
        for node in present:
            components.setdefault(labels[node], set()).add(node)
        for members in components.values():
            older = [c for c in previous if c <= members]
            births = sorted((max(node_birth[n] for n in c) for c in older), reverse=True)
            pairs += [(b, t) for b in births[1:] if b > t]
        previous = [frozenset(c) for c in components.values()]
    pairs += [(max(node_birth[n] for n in c), -INF) for c in previous]
    return sorted(pairs)


def slow_cycles(u, v, strong):
    """3-cycles and chordless 4-cycles by number of strong edges, by trying every node set."""
    edges = {frozenset((int(a), int(b))): int(s) for a, b, s in zip(u, v, strong)}
    nodes = sorted({int(x) for x in np.concatenate([u, v])})
    triangles, squares = np.zeros(5, int), np.zeros(5, int)
    for a, b, c in itertools.combinations(nodes, 3):
        sides = [frozenset(p) for p in ((a, b), (b, c), (a, c))]
        if all(s in edges for s in sides):
            triangles[sum(edges[s] for s in sides)] += 1
    for quad in itertools.combinations(nodes, 4):
        a = quad[0]
        for b, c, d in ((quad[1], quad[2], quad[3]), (quad[1], quad[3], quad[2]), (quad[2], quad[1], quad[3])):
            sides = [frozenset(p) for p in ((a, b), (b, c), (c, d), (d, a))]
            chords = [frozenset((a, c)), frozenset((b, d))]
            if all(s in edges for s in sides) and not any(ch in edges for ch in chords):
                squares[sum(edges[s] for s in sides)] += 1
    return triangles, squares


def slow_flag_persistence(u, v, value, seed=0):
    """The textbook algorithm, no shortcut: every simplex of the clique complex up to the
    triangles (nodes, edges, triangles) in one list sorted by its value, largest first (a node
    with its strongest edge, a triangle with its weakest), faces before cofaces at a tie and
    otherwise in random order; the whole boundary matrix, dense over Z/2; each column reduced
    by adding the earlier column with the same lowest one. Returns {dimension: sorted
    [(birth, death)]} for dimensions 0, 1 and 2, zero-persistence pairs left out."""
    rng = np.random.default_rng(seed)
    edges = {frozenset((int(a), int(b))): float(x) for a, b, x in zip(u, v, value)}
    adjacent = {}
    for a, b in map(tuple, edges):
        adjacent.setdefault(a, set()).add(b)
        adjacent.setdefault(b, set()).add(a)
    simplices = [(frozenset([n]), max(edges[frozenset((n, m))] for m in near)) for n, near in adjacent.items()]
    simplices += list(edges.items())
    for a, b in map(sorted, edges):
        for c in adjacent[a] & adjacent[b]:
            if c > b:
                simplices.append((frozenset((a, b, c)), min(edges[frozenset(p)] for p in ((a, b), (b, c), (a, c)))))
    keys = rng.random(len(simplices))
    simplices = [simplices[k] for k in sorted(range(len(simplices)),
                                              key=lambda k: (-simplices[k][1], len(simplices[k][0]), keys[k]))]
    index = {s: k for k, (s, _) in enumerate(simplices)}
    boundary = np.zeros((len(simplices), len(simplices)), bool)
    for k, (s, _) in enumerate(simplices):
        if len(s) > 1:
            for face in itertools.combinations(sorted(s), len(s) - 1):
                boundary[index[frozenset(face)], k] = True
    owner = {}
    for k in range(len(simplices)):
        while boundary[:, k].any():
            low = np.flatnonzero(boundary[:, k])[-1]
            if low not in owner:
                owner[low] = k
                break
            boundary[:, k] ^= boundary[:, owner[low]]
    pairs = {0: [], 1: [], 2: []}
    for low, k in owner.items():
        pairs[len(simplices[low][0]) - 1].append((simplices[low][1], simplices[k][1]))
    paired = set(owner) | set(owner.values())
    for k, (s, x) in enumerate(simplices):
        if k not in paired:
            pairs[len(s) - 1].append((x, -INF))
    return {dim: sorted((round(b, 12), round(d, 12)) for b, d in p if b != d) for dim, p in pairs.items()}


def rank_z2(matrix):
    """Rank over Z/2 by Gaussian elimination."""
    m = np.array(matrix, bool)
    rank = 0
    for col in range(m.shape[1]):
        rows = np.flatnonzero(m[rank:, col]) + rank
        if rows.size == 0:
            continue
        m[[rank, rows[0]]] = m[[rows[0], rank]]
        below = np.flatnonzero(m[:, col])
        below = below[below != rank]
        m[below] ^= m[rank]
        rank += 1
        if rank == m.shape[0]:
            break
    return rank


def betti_1_by_ranks(u, v, value, x):
    """beta_1 of the clique complex (up to triangles) of the edges with value >= x, from its
    chain groups alone: dim ker d1 - rank d2 = E - rank d1 - rank d2 over Z/2."""
    keep = value >= x
    a, b = u[keep], v[keep]
    nodes = np.unique(np.concatenate([a, b]))
    if nodes.size == 0:
        return 0
    node = {n: k for k, n in enumerate(nodes)}
    d1 = np.zeros((nodes.size, a.size), bool)
    d1[[node[n] for n in a], np.arange(a.size)] = True
    d1[[node[n] for n in b], np.arange(a.size)] = True
    edge = {frozenset((int(p), int(q))): k for k, (p, q) in enumerate(zip(a, b))}
    columns = []
    for tri in itertools.combinations(nodes.tolist(), 3):
        sides = [edge.get(frozenset(p)) for p in itertools.combinations(tri, 2)]
        if None not in sides:
            column = np.zeros(a.size, bool)
            column[sides] = True
            columns.append(column)
    d2 = np.array(columns).T if columns else np.zeros((a.size, 0), bool)
    return a.size - rank_z2(d1) - rank_z2(d2)


def random_graph(seed, n=14, m=30, ties=False):
    rng = np.random.default_rng(seed)
    pairs = set()
    while len(pairs) < m:
        a, b = sorted(rng.choice(n, 2, replace=False))
        pairs.add((int(a), int(b)))
    i, j = np.array(sorted(pairs)).T
    fn = rng.integers(1, 5, m).astype(float) if ties else rng.exponential(1.0, m)
    return nt.filtration_edges(fn, i, j, np.ones(m, bool))


def as_pairs(birth, death):
    """Sorted (birth, death) pairs rounded to 12 digits as the slow versions round theirs (Python's
    correctly rounded ``round``: ``np.round`` scales by 1e12 first and may round the other way)."""
    return sorted((round(float(b), 12), round(float(d), 12)) for b, d in zip(birth, death))


# ---------------------------------------------------------------- kernels


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("ties", [False, True])
def test_union_find_equals_the_slow_elder_rule(seed, ties):
    u, v, value = random_graph(seed, ties=ties)
    got = as_pairs(*nt.diagram_0(u, v, value, 14))
    assert got == [(round(b, 12), round(d, 12)) for b, d in slow_diagram_0(u, v, value, 14)]


@pytest.mark.parametrize("seed", range(6))
def test_beta_0_counts_the_components_of_the_network_above_xi(seed):
    u, v, value = random_graph(seed, n=20, m=24)
    grid = np.r_[0.0, np.sort(value), np.sort(value) + 1e-9, 50.0]
    beta = nt.betti_curve(*nt.diagram_0(u, v, value, 20), grid)
    for x, b in zip(grid, beta):
        keep = value >= x
        present = np.unique(np.concatenate([u[keep], v[keep]]))
        graph = coo_matrix((np.ones(keep.sum()), (u[keep], v[keep])), shape=(20, 20))
        labels = connected_components(graph, directed=False)[1]
        assert b == np.unique(labels[present]).size


@pytest.mark.parametrize("seed", range(5))
def test_cycle_kernel_equals_trying_every_node_set(seed):
    u, v, value = random_graph(seed, n=11, m=28)
    triangles, squares = nt.short_cycles(u, v, value, 11, strong=1.0)
    slow_triangles, slow_squares = slow_cycles(u, v, value >= 1.0)
    np.testing.assert_array_equal(triangles, slow_triangles)
    np.testing.assert_array_equal(squares, slow_squares)
    assert squares.sum() > 0 and triangles.sum() > 0  # the random graphs have both


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("ties", [False, True])
def test_union_find_equals_gudhi(seed, ties):
    pytest.importorskip("gudhi")
    u, v, value = random_graph(seed, ties=ties)
    library = nt.diagrams_gudhi(u, v, value, 14)
    assert as_pairs(*nt.diagram_0(u, v, value, 14)) == as_pairs(*library[0])


def dense_graph(seed, ties=False):
    """9 nodes, 22 of the 36 pairs: many triangles, 4-cliques among them."""
    return random_graph(seed, n=9, m=22, ties=ties)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("ties", [False, True])
def test_dimension_1_equals_the_textbook_reduction(seed, ties):
    for u, v, value, n in (dense_graph(seed, ties) + (9,), random_graph(seed, ties=ties) + (14,)):
        slow = slow_flag_persistence(u, v, value, seed)
        assert as_pairs(*nt.diagram_1(u, v, value, n)) == slow[1]
        assert as_pairs(*nt.diagram_0(u, v, value, n)) == slow[0]


def test_the_dense_graphs_fill_loops_and_close_spheres():
    """The graphs of the test above are not trivial: loops that die, loops that never die, and
    2-spheres (the kernel's zero columns), with and without ties."""
    for ties in (False, True):
        slow = [slow_flag_persistence(*dense_graph(seed, ties)) for seed in range(8)]
        assert sum(np.isfinite(d).sum() for s in slow for _, d in s[1]) >= 10
        assert sum(np.isinf(d).sum() for s in slow for _, d in s[1]) >= 4
        assert sum(len(s[2]) for s in slow) >= 20


@pytest.mark.parametrize("seed", range(4))
def test_beta_1_equals_the_ranks_of_the_boundary_maps(seed):
    """beta_1(xi) = E - rank d1 - rank d2 over Z/2 of the complex above xi, with no persistence."""
    for u, v, value, n in (dense_graph(seed) + (9,), random_graph(seed) + (14,)):
        grid = np.r_[0.0, np.sort(value), 50.0]
        beta = nt.betti_curve(*nt.diagram_1(u, v, value, n), grid)
        assert beta.tolist() == [betti_1_by_ranks(u, v, value, x) for x in grid]
        assert beta.max() >= 1


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("ties", [False, True])
def test_dimension_1_equals_gudhi(seed, ties):
    pytest.importorskip("gudhi")
    for u, v, value, n in (dense_graph(seed, ties) + (9,), random_graph(seed, ties=ties) + (14,)):
        assert as_pairs(*nt.diagram_1(u, v, value, n)) == as_pairs(*nt.diagrams_gudhi(u, v, value, n)[1])


def test_beta_1_is_the_euler_characteristic_on_a_triangulated_packing():
    """On a planar triangulation (no 2-cycles) beta_1 = beta_0 - V + E - T at every threshold,
    V, E, T the nodes, edges and triangles (trace A^3 / 6) of the network above it."""
    ds = builders.hexagonal_lattice(7, 6)
    rng = np.random.default_rng(3)
    n_contacts = int(ds.contact_count[0])
    fn, i, j = rng.exponential(1.0, n_contacts), ds.i.values[0, :n_contacts], ds.j.values[0, :n_contacts]
    u, v, value = nt.filtration_edges(fn, i, j, np.ones(n_contacts, bool))
    grid = np.r_[0.0, np.sort(value), np.sort(value) + 1e-9]
    beta_0 = nt.betti_curve(*nt.diagram_0(u, v, value, 42), grid)
    beta_1 = nt.betti_curve(*nt.diagram_1(u, v, value, 42), grid)
    assert beta_1.max() >= 3
    for x, b0, b1 in zip(grid, beta_0, beta_1):
        keep = value >= x
        nodes = np.unique(np.concatenate([u[keep], v[keep]])).size
        adjacency = coo_matrix((np.ones(keep.sum()), (u[keep], v[keep])), shape=(42, 42)).toarray()
        adjacency += adjacency.T
        triangles = round(np.trace(np.linalg.matrix_power(adjacency, 3)) / 6)
        assert b1 == b0 - nodes + keep.sum() + 0 - triangles


# ---------------------------------------------------------------- hand-made graphs

# six particles; each snapshot one small graph: (i, j, fn)
GRAPHS = {
    # a triangle whose weakest edge closes it: the loop is filled as it appears, no 1-feature;
    # xi = 1.5, 1, 0.5
    "triangle with one weak edge": ([0, 1, 2], [1, 2, 0], [3.0, 2.0, 1.0]),
    # a square, xi = 1.6, 1.2, 0.8, 0.4: one loop born at 0.4, never filled
    "square": ([0, 1, 2, 3], [1, 2, 3, 0], [4.0, 3.0, 2.0, 1.0]),
    # the square's sides of 4 N and a diagonal of 1 N: <f_n> = 3.4 N; the loop born at 4/3.4 dies
    # at 1/3.4, when the diagonal fills both triangles
    "square with weak diagonal": ([0, 1, 2, 3, 0], [1, 2, 3, 0, 2], [4.0, 4.0, 4.0, 4.0, 1.0]),
    # a 2 x 3 ladder, two squares sharing the edge 1-4: <f_n> = 4 N; xi = 1.75 (0-1), 1.5 (1-2),
    # 1.25 (3-4), 1 (4-5), 0.75 (0-3: the component {3,4,5} born at 1.25 merges into the older
    # one), 0.5 (2-5: the outer loop), 0.25 (1-4: the second loop)
    "two loops sharing an edge": ([0, 1, 3, 4, 0, 2, 1], [1, 2, 4, 5, 3, 5, 4], [7.0, 6.0, 5.0, 4.0, 3.0, 2.0, 1.0]),
    # a 4-clique: a square of 4 N sides, its diagonals 0-2 of 2 N and 1-3 of 1 N, <f_n> = 19/6 N.
    # The loop born at 4/<f_n> dies at 2/<f_n> when 0-2 fills it with two triangles; 1-3 brings
    # two more, which with those close a 2-sphere: the last of the four fills no loop
    "4-clique": ([0, 1, 2, 3, 0, 1], [1, 2, 3, 0, 2, 3], [4.0, 4.0, 4.0, 4.0, 2.0, 1.0]),
    # an octahedron: the equator 1-2-3-4 of 4 N, the spokes to the top 0 of 2 N and to the bottom
    # 5 of 1 N, <f_n> = 7/3 N. The equator's loop is born at 12/7 and filled at 6/7 by the top
    # cone; the bottom cone closes the sphere
    "octahedron": ([1, 2, 3, 4, 0, 0, 0, 0, 1, 2, 3, 4], [2, 3, 4, 1, 1, 2, 3, 4, 5, 5, 5, 5],
                   [4.0] * 4 + [2.0] * 4 + [1.0] * 4),
}
EXPECTED = {
    "triangle with one weak edge": dict(d0=[(1.5, -INF)], d1=[], cycles_3=[0, 0, 1, 0, 0], cycles_4=[0] * 5),
    "square": dict(d0=[(1.6, -INF)], d1=[(0.4, -INF)], cycles_3=[0] * 5, cycles_4=[0, 0, 1, 0, 0]),
    "square with weak diagonal": dict(d0=[(4 / 3.4, -INF)], d1=[(4 / 3.4, 1 / 3.4)], cycles_3=[0, 0, 2, 0, 0],
                                      cycles_4=[0] * 5),
    "two loops sharing an edge": dict(d0=[(1.25, 0.75), (1.75, -INF)], d1=[(0.25, -INF), (0.5, -INF)],
                                      cycles_3=[0] * 5, cycles_4=[0, 0, 2, 0, 0]),
    # each triangle two sides and a diagonal; every 4-cycle has a chord
    "4-clique": dict(d0=[(24 / 19, -INF)], d1=[(24 / 19, 12 / 19)], d2=[(6 / 19, -INF)], cycles_3=[0, 0, 4, 0, 0],
                     cycles_4=[0] * 5),
    # each triangle one equator side; the chordless 4-cycles: the equator, and two through both poles
    "octahedron": dict(d0=[(12 / 7, -INF)], d1=[(12 / 7, 6 / 7)], d2=[(3 / 7, -INF)], cycles_3=[0, 8, 0, 0, 0],
                       cycles_4=[2, 0, 0, 0, 1]),
}


def hand_made():
    pos = np.array([[0.0, 0.0], [0.02, 0.0], [0.04, 0.0], [0.0, 0.02], [0.02, 0.02], [0.04, 0.02]])
    snaps = []
    for i, j, fn in GRAPHS.values():
        i, j = np.array(i), np.array(j)
        branch = pos[j] - pos[i]
        normal = branch / np.linalg.norm(branch, axis=1, keepdims=True)
        snaps.append(dict(i=np.minimum(i, j), j=np.maximum(i, j), kind=np.ones(i.size, int),
                          normal=np.where((i < j)[:, None], normal, -normal), fn=np.array(fn), ft=np.zeros(i.size)))
    return make_dataset(radius=np.full(6, 0.01), position=np.stack([pos] * len(snaps)), contacts=snaps, box_min=[-0.01, -0.01],
                        box_max=[0.05, 0.03])


def diagram(out, t, dim):
    snap = out.isel(time=t)
    keep = snap.dimension.values == dim
    return as_pairs(snap.birth.values[keep], snap.death.values[keep])


@pytest.mark.parametrize("name", GRAPHS)
def test_hand_made_graphs_by_the_textbook_reduction_and_gudhi(name):
    """The expected diagrams of the hand-made graphs (dimension 2: the spheres, which the module
    does not report) are the slow reduction's and, when it is installed, gudhi's."""
    i, j, fn = (np.array(a) for a in GRAPHS[name])
    u, v, value = nt.filtration_edges(fn, i, j, np.ones(i.size, bool))
    want = {dim: as_pairs(*zip(*EXPECTED[name][key])) if EXPECTED[name].get(key) else []
            for dim, key in enumerate(("d0", "d1", "d2"))}
    assert slow_flag_persistence(u, v, value) == want
    assert as_pairs(*nt.diagram_1(u, v, value, 6)) == want[1]
    try:
        library = nt.diagrams_gudhi(u, v, value, 6)
    except ParameterError:  # no gudhi
        return
    assert [as_pairs(*library[dim]) for dim in (0, 1)] == [want[0], want[1]]


def test_hand_made_graphs_give_their_diagrams(prepare):
    ds = prepare(hand_made())
    with raise_if_dask_computes():
        lazy = ds.grain.network_persistence(xi=[0.0, 0.25, 0.3, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0])
    out = lazy.compute()
    for t, name in enumerate(GRAPHS):
        want = EXPECTED[name]
        assert diagram(out, t, 0) == as_pairs(*zip(*want["d0"])), name
        assert diagram(out, t, 1) == (as_pairs(*zip(*want["d1"])) if want["d1"] else []), name
        assert out.cycles_3.values[t].tolist() == want["cycles_3"], name
        assert out.cycles_4.values[t].tolist() == want["cycles_4"], name
    # Betti curves at xi = 0, 0.25, 0.3, 0.5, 0.75, 1, 1.25, 1.5, 2 (features alive on (death, birth])
    ladder = out.isel(time=3)
    assert ladder.beta_0.values.tolist() == [1, 1, 1, 1, 1, 2, 2, 1, 0]
    assert ladder.beta_1.values.tolist() == [2, 2, 1, 1, 0, 0, 0, 0, 0]
    diagonal = out.isel(time=2)  # the loop lives on (0.294, 1.176]
    assert diagonal.beta_1.values.tolist() == [0, 0, 1, 1, 1, 1, 0, 0, 0]
    assert out.isel(time=0).beta_1.values.tolist() == [0] * 9  # the triangle's loop never shows
    assert out.isel(time=1).beta_1.values.tolist() == [1, 1, 1, 0, 0, 0, 0, 0, 0]  # born at 0.4
    assert out.isel(time=4).beta_1.values.tolist() == [0, 0, 0, 0, 1, 1, 1, 0, 0]  # on (12/19, 24/19]
    assert out.isel(time=5).beta_1.values.tolist() == [0, 0, 0, 0, 0, 1, 1, 1, 0]  # on (6/7, 12/7]
    # padding: NaN births, dimension -1, after the features
    assert np.isnan(out.birth.values[0, 1:]).all() and (out.dimension.values[0, 1:] == -1).all()
    assert out.birth.attrs["units"] == "1" and out.attrs["walls"] == 0


def test_square_lattice_by_hand(prepare):
    """4 x 3 disks, 9 horizontal contacts of 2 N and 8 vertical of 5 N, <f_n> = 58/17 N: the
    4 vertical columns appear at xi = 85/58, join at 34/58 closing the 6 unit squares."""
    ds = prepare(builders.square_lattice(4, 3, 2.0, 5.0))
    with raise_if_dask_computes():
        lazy = network_persistence(ds, xi=[0.0, 0.5, 1.0, 1.5])
    out = lazy.compute()
    strong, weak = 5 / (58 / 17), 2 / (58 / 17)
    assert diagram(out, 0, 0) == as_pairs([strong] * 4, [-INF] + [weak] * 3)
    assert diagram(out, 0, 1) == as_pairs([weak] * 6, [-INF] * 6)
    assert out.beta_0.values[0].tolist() == [1, 1, 4, 0]
    assert out.beta_1.values[0].tolist() == [6, 6, 0, 0]
    assert out.cycles_4.values[0].tolist() == [0, 0, 6, 0, 0]  # 2 vertical (strong) sides each
    assert out.cycles_3.values[0].tolist() == [0] * 5
    # the whole diagram, in decreasing persistence: the never-dying first, the component then the loops
    assert out.dimension.values[0, :7].tolist() == [0, 1, 1, 1, 1, 1, 1]


def test_hexagonal_lattice_fills_every_loop():
    out = network_persistence(builders.hexagonal_lattice(6, 5), xi=[0.0, 1.0])
    # 4 strips between 5 rows of 6 disks, each a zigzag of 12 disks holding 10 triangles, all of
    # equal (strong) force
    assert out.cycles_3.values[0].tolist() == [0, 0, 0, 40, 0]
    assert out.cycles_4.values[0].tolist() == [0] * 5  # every 4-cycle has a chord
    assert out.beta_1.values[0].tolist() == [0, 0]
    assert out.beta_0.values[0].tolist() == [1, 1]
    assert diagram(out, 0, 0) == [(1.0, -INF)] and diagram(out, 0, 1) == []


def test_walls_as_nodes():
    """Two particles that touch only the bottom wall: no network without walls; with them one
    component through the wall."""
    pos = np.array([[0.0, 0.01], [0.05, 0.01]])
    contacts = [dict(i=[0, 1], j=[2, 2], kind=[1, 1], normal=[[0.0, -1.0], [0.0, -1.0]], fn=[1.0, 3.0],
                     ft=[0.0, 0.0], point=[[0.0, 0.0], [0.05, 0.0]], branch=[[0.0, -0.01], [0.0, -0.01]])]
    ds = make_dataset(radius=[0.01, 0.01], position=pos, contacts=contacts, box_min=[-0.01, 0.0],
                      box_max=[0.06, 0.05], n_walls=1)
    without = network_persistence(ds, xi=[0.0], dimensions=(0,))
    assert without.beta_0.values.tolist() == [[0]] and (without.dimension.values == -1).all()
    with_walls = network_persistence(ds, xi=[0.0, 1.0], dimensions=(0,), walls=True)
    assert with_walls.beta_0.values.tolist() == [[1, 1]]  # xi = 1.5 and 0.5: one component from 1.5 on
    assert diagram(with_walls, 0, 0) == [(1.5, -INF)]


def test_max_features_keeps_the_most_persistent_and_every_count():
    ds = builders.square_lattice(4, 3, 2.0, 5.0)
    whole = network_persistence(ds)
    cut = network_persistence(ds, max_features=2)
    assert cut.sizes["feature"] == 2
    assert cut.dimension.values[0].tolist() == [0, 1] and np.isinf(cut.death.values[0]).all()
    np.testing.assert_array_equal(cut.beta_1.values, whole.beta_1.values)


def test_both_dimensions_without_gudhi(monkeypatch):
    """Without gudhi everything is computed; only the cross-check says, in one line, what it needs."""
    monkeypatch.setitem(sys.modules, "gudhi", None)  # import gudhi raises ImportError
    ds = hand_made()
    out = ds.grain.network_persistence(xi=[0.0, 1.0])
    for t, name in enumerate(GRAPHS):
        want = EXPECTED[name]
        assert diagram(out, t, 0) == as_pairs(*zip(*want["d0"])), name
        assert diagram(out, t, 1) == (as_pairs(*zip(*want["d1"])) if want["d1"] else []), name
    assert out.beta_1.values.tolist() == [[0, 0], [1, 0], [0, 1], [2, 0], [0, 1], [0, 1]]
    zero = ds.grain.network_persistence(dimensions=(0,), xi=[0.0, 1.0])
    assert "beta_1" not in zero and set(np.unique(zero.dimension.values)) == {-1, 0}
    assert diagram(zero, 3, 0) == as_pairs([1.25, 1.75], [0.75, -INF])
    u, v, value = nt.filtration_edges(np.array([1.0]), np.array([0]), np.array([1]), np.array([True]))
    needs = r"needs the TDA library gudhi: pip install 'grainview\[topology\]'"
    with pytest.raises(ParameterError, match=needs) as error:
        nt.diagrams_gudhi(u, v, value, 2)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("kwargs, match", [
    (dict(dimensions=(2,)), "dimensions"), (dict(dimensions="a"), "dimensions"), (dict(strong=-1.0), "strong"),
    (dict(strong=np.nan), "strong"), (dict(max_features=0), "max_features"), (dict(max_features=1.5), "max_features"),
    (dict(xi=[-1.0]), "xi"),
])
def test_bad_arguments(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        network_persistence(hand_made(), **{"dimensions": (0,), **kwargs})


# ---------------------------------------------------------------- figures


def test_figures_draw_the_analysis_with_labelled_axes():
    import matplotlib.pyplot as plt

    from grainview.plot.topology import (plot_betti_curves, plot_cycle_counts, plot_network_topology,
                                         plot_persistence_diagram)

    ds = builders.square_lattice(4, 3, 2.0, 5.0)  # 12 particles; diagram: 4 components, 6 loops
    result = network_persistence(ds)
    ax = plot_persistence_diagram(ds, label="lattice")
    points = [c.get_offsets() for c in ax.collections]
    assert [len(p) for p in points] == [4, 6]
    never = ax.get_lines()[1].get_ydata()[0]  # the "never" line, below zero
    assert never < 0 and sorted(points[0][:, 1]) == pytest.approx([never] + [2 / (58 / 17)] * 3)
    assert "birth" in ax.get_xlabel() and r"\langle f_n\rangle" in ax.get_ylabel()
    ax = plot_betti_curves({"lattice": ds})
    beta_1 = [line for line in ax.get_lines() if "beta_1" in line.get_label()][0]
    np.testing.assert_allclose(beta_1.get_ydata(), result.beta_1.values[0] / 12)
    assert ax.get_xlabel() == r"$\xi = f_n/\langle f_n\rangle$" and "per particle" in ax.get_ylabel()
    ax = plot_cycle_counts(ds, label="lattice")
    heights = [patch.get_height() for patch in ax.patches]
    assert heights[5:] == pytest.approx([0, 0, 0.5, 0, 0])  # 6 squares, 2 strong edges each, over 12 particles
    with pytest.raises(ParameterError, match="per_particle"):
        plot_cycle_counts(result)
    fig = plot_network_topology({"a": ds, "b": ds})
    assert len(fig.axes) == 3 and all(a.get_xlabel() and a.get_ylabel() for a in fig.axes)
    fig = ds.grain.plot.network_topology()  # one unlabelled sample: no "None" in the legends
    labels = [text.get_text() for a in fig.axes if a.get_legend() for text in a.get_legend().get_texts()]
    assert labels and not any("None" in text for text in labels)
    assert ds.grain.plot.betti_curves().get_xlabel() == r"$\xi = f_n/\langle f_n\rangle$"
    plt.close("all")


def test_unloaded_pairs_all_enter_at_zero():
    """A selection of near pairs only (f_n = 0, <f_n> = 0): every contact at xi = 0, no NaN."""
    u, v, value = nt.filtration_edges(np.zeros(3), np.array([0, 1, 0]), np.array([1, 2, 2]), np.ones(3, bool))
    assert value.tolist() == [0.0, 0.0, 0.0]
    assert as_pairs(*nt.diagram_0(u, v, value, 3)) == [(0.0, -INF)]
    assert nt.betti_curve(*nt.diagram_0(u, v, value, 3), [0.0, 0.1]).tolist() == [1, 0]


# ---------------------------------------------------------------- sheared samples


SHEARED = dict(particles=60, strain=0.02, every=10)


@pytest.fixture(scope="module")
def sheared_files(tmp_path_factory):
    """A small pentagon and disk sample of the solver, compacted and sheared (made here: a test
    reads no folder it did not write)."""
    import warnings

    from grainview.contract.errors import ConvergenceWarning
    from solver import biaxial_test
    from solver.preparation import preparation, prepare_sample

    folder = tmp_path_factory.mktemp("sheared")
    files = {}
    for label, shape in (("pentagons", "pentagon"), ("disks", "disk")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            sim = prepare_sample(preparation("paper", particles=SHEARED["particles"], shape=shape, seed=1),
                                 progress=False)
            files[label] = folder / f"{label}.nc"
            biaxial_test(sim, files[label], strain=SHEARED["strain"], every=SHEARED["every"], progress=False)
    return files


def study_file(label):
    """A run of ``grainview study`` named by GRAINVIEW_STUDY (a folder), or skip: the study's
    files are read only when asked for, never from the current folder."""
    folder = os.environ.get("GRAINVIEW_STUDY")
    if folder and (Path(folder) / f"{label}.nc").is_file():
        return Path(folder) / f"{label}.nc"
    pytest.skip("GRAINVIEW_STUDY does not name a folder of grainview study's files")


def snapshot_graphs(path, every=1):
    """Each snapshot's network as the module filters it: (u, v, value), the particle count."""
    import grainview
    from grainview.analysis.contacts import selection

    ds = grainview.open_dataset(path).isel(time=slice(None, None, every)).load()
    mask, fn, i, j = (a.transpose("time", "contact").values for a in (selection(ds), ds.fn, ds.i, ds.j))
    return ds, [nt.filtration_edges(fn[t], i[t], j[t], mask[t]) for t in range(ds.sizes["time"])]


def equals_gudhi(path):
    """Every snapshot of the file at ``path``: the module's diagrams (dimensions 0 and 1) equal
    gudhi's as multisets, and its beta_0 and beta_1 curves gudhi's. Returns (snapshots, loops
    born, loops filled) over the snapshots."""
    pytest.importorskip("gudhi")
    ds, graphs = snapshot_graphs(path)
    out = ds.grain.network_persistence().compute()
    n = ds.sizes["particle"]
    filled = loops = 0
    for t, (u, v, value) in enumerate(graphs):
        library = nt.diagrams_gudhi(u, v, value, n)
        for dim in (0, 1):
            assert diagram(out, t, dim) == as_pairs(*library[dim]), (t, dim)
            np.testing.assert_array_equal(out[f"beta_{dim}"].values[t], nt.betti_curve(*library[dim], out.xi.values))
        loops += library[1][0].size
        filled += np.isfinite(library[1][1]).sum()
    return ds.sizes["time"], loops, filled


def equals_the_textbook_reduction(path, every=1):
    ds, graphs = snapshot_graphs(path, every)
    n = ds.sizes["particle"]
    for u, v, value in graphs:
        slow = slow_flag_persistence(u, v, value)
        assert as_pairs(*nt.diagram_1(u, v, value, n)) == slow[1]
        assert as_pairs(*nt.diagram_0(u, v, value, n)) == slow[0]
    return len(graphs)


@pytest.mark.parametrize("label", ["pentagons", "disks"])
def test_sheared_snapshots_equal_gudhi(label, sheared_files):
    snapshots, loops, _ = equals_gudhi(sheared_files[label])
    assert snapshots >= 5 and loops > 5 * snapshots  # a network with loops in every snapshot, checked


@pytest.mark.parametrize("label", ["pentagons", "disks"])
def test_sheared_snapshots_equal_the_textbook_reduction(label, sheared_files):
    assert equals_the_textbook_reduction(sheared_files[label]) >= 5


@pytest.mark.slow
@pytest.mark.parametrize("label", ["pentagons", "disks"])
def test_study_snapshots_equal_gudhi(label):
    """Every snapshot of the study's runs (GRAINVIEW_STUDY)."""
    snapshots, loops, filled = equals_gudhi(study_file(label))
    assert snapshots > 150 and loops > 100 * snapshots and filled > 20


@pytest.mark.slow
@pytest.mark.parametrize("label", ["pentagons", "disks"])
def test_every_study_snapshot_equals_the_textbook_reduction(label):
    """Every snapshot of the study's runs (GRAINVIEW_STUDY)."""
    assert equals_the_textbook_reduction(study_file(label)) > 150
