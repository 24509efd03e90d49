"""Topology of the force network: hand-made graphs with known persistence diagrams, Betti
curves and cycle counts (eager and chunked, nothing computed until asked); the union-find and
the cycle kernel against slow, obviously-correct versions; the union-find against gudhi."""

import itertools
import sys

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from grainview.arrays import network_topology as nt
from grainview.contract.dataset import make_dataset
from grainview.contract.errors import ParameterError
from grainview.network_topology import network_persistence

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
    return sorted(zip(np.round(birth, 12), np.round(death, 12)))


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


def test_beta_1_is_the_euler_characteristic_on_a_triangulated_packing():
    """On a planar triangulation (no 2-cycles) beta_1 = beta_0 - V + E - T at every threshold,
    V, E, T the nodes, edges and triangles (trace A^3 / 6) of the network above it."""
    pytest.importorskip("gudhi")
    ds = builders.hexagonal_lattice(7, 6)
    rng = np.random.default_rng(3)
    n_contacts = int(ds.contact_count[0])
    fn, i, j = rng.exponential(1.0, n_contacts), ds.i.values[0, :n_contacts], ds.j.values[0, :n_contacts]
    u, v, value = nt.filtration_edges(fn, i, j, np.ones(n_contacts, bool))
    diagrams = nt.diagrams_gudhi(u, v, value, 42)
    grid = np.r_[0.0, np.sort(value), np.sort(value) + 1e-9]
    beta_0 = nt.betti_curve(*nt.diagram_0(u, v, value, 42), grid)
    beta_1 = nt.betti_curve(*diagrams[1], grid)
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
}
EXPECTED = {
    "triangle with one weak edge": dict(d0=[(1.5, -INF)], d1=[], cycles_3=[0, 0, 1, 0, 0], cycles_4=[0] * 5),
    "square": dict(d0=[(1.6, -INF)], d1=[(0.4, -INF)], cycles_3=[0] * 5, cycles_4=[0, 0, 1, 0, 0]),
    "square with weak diagonal": dict(d0=[(4 / 3.4, -INF)], d1=[(4 / 3.4, 1 / 3.4)], cycles_3=[0, 0, 2, 0, 0],
                                      cycles_4=[0] * 5),
    "two loops sharing an edge": dict(d0=[(1.25, 0.75), (1.75, -INF)], d1=[(0.25, -INF), (0.5, -INF)],
                                      cycles_3=[0] * 5, cycles_4=[0, 0, 2, 0, 0]),
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


def test_hand_made_graphs_give_their_diagrams(prepare):
    pytest.importorskip("gudhi")
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
    # padding: NaN births, dimension -1, after the features
    assert np.isnan(out.birth.values[0, 1:]).all() and (out.dimension.values[0, 1:] == -1).all()
    assert out.birth.attrs["units"] == "1" and out.attrs["walls"] == 0


def test_square_lattice_by_hand(prepare):
    """4 x 3 disks, 9 horizontal contacts of 2 N and 8 vertical of 5 N, <f_n> = 58/17 N: the
    4 vertical columns appear at xi = 85/58, join at 34/58 closing the 6 unit squares."""
    pytest.importorskip("gudhi")
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
    pytest.importorskip("gudhi")
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
    pytest.importorskip("gudhi")
    ds = builders.square_lattice(4, 3, 2.0, 5.0)
    whole = network_persistence(ds)
    cut = network_persistence(ds, max_features=2)
    assert cut.sizes["feature"] == 2
    assert cut.dimension.values[0].tolist() == [0, 1] and np.isinf(cut.death.values[0]).all()
    np.testing.assert_array_equal(cut.beta_1.values, whole.beta_1.values)


def test_dimension_0_needs_no_gudhi_and_dimension_1_says_so(monkeypatch):
    monkeypatch.setitem(sys.modules, "gudhi", None)  # import gudhi raises ImportError
    ds = hand_made()
    with pytest.raises(ParameterError, match=r"needs the TDA library gudhi: pip install 'grainview\[topology\]'"):
        ds.grain.network_persistence()
    out = ds.grain.network_persistence(dimensions=(0,), xi=[0.0, 1.0])
    assert "beta_1" not in out and set(np.unique(out.dimension.values)) == {-1, 0}
    assert diagram(out, 3, 0) == as_pairs([1.25, 1.75], [0.75, -INF])
    assert out.cycles_4.values[3].tolist() == [0, 0, 2, 0, 0]


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
    pytest.importorskip("gudhi")
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
