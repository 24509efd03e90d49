"""One snapshot as a tidy table and as a sparse graph: row for row the hand-made contacts."""

import numpy as np
import pytest

from grainview.contract.errors import ParameterError

from .test_lifetimes import SERIES
from .test_persistence import N, sequence_dataset


def test_table_holds_the_occupied_slots_only():
    ds = sequence_dataset(SERIES)
    table = ds.grain.contacts_table(time=2)
    expected = sorted((i, j, kind, fn) for i, j, kind, fn in SERIES[2])
    got = sorted(zip(table.i, table.j, table.kind, table.fn))
    assert got == expected and len(table) == ds.sizes["contact"] - int((ds.kind.isel(time=2) == 0).sum())
    assert table.wall.tolist() == [j >= N for j in table.j]
    np.testing.assert_array_equal(table[["normal_x", "normal_y"]].to_numpy(), np.tile([1.0, 0.0], (len(table), 1)))
    assert table.attrs["units"]["fn"] == "N" and table.attrs["time"] == 2.0
    assert len(ds.grain.contacts_table()) == len(SERIES[-1])  # default: the last snapshot


def test_graph_is_symmetric_and_weighted_by_the_normal_force():
    ds = sequence_dataset(SERIES)
    graph = ds.grain.contact_graph(time=2)
    assert graph.shape == (N + 1, N + 1) and (graph != graph.T).nnz == 0
    for i, j, _, fn in SERIES[2]:
        assert graph[i, j] == fn and graph[j, i] == fn
    assert graph.nnz == 2 * len(SERIES[2])


def test_networkx_graph_when_available():
    nx = pytest.importorskip("networkx")
    ds = sequence_dataset(SERIES)
    graph = ds.grain.contact_graph(time=1, as_networkx=True)
    assert isinstance(graph, nx.Graph) and graph.number_of_edges() == len(SERIES[1])
    assert graph.edges[0, 1]["fn"] == 4.0


def test_bad_snapshot_index():
    ds = sequence_dataset(SERIES)
    with pytest.raises(ParameterError, match="time="):
        ds.grain.contacts_table(time=len(SERIES))
