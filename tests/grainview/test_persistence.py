"""Persistence gamma(t) and simple/double transitions: a hand-made sequence, a set-based
oracle, relabelling invariance, and streaming one time-chunk at a time."""

import numpy as np
import pytest

from grainview import make_dataset
from grainview.analysis.arrays import persistence as persistence_arrays
from grainview.contract.errors import ParameterError
from grainview.analysis.persistence import pair_keys, persistence, type_transitions

from .conftest import raise_if_dask_computes

N = 5  # particles; the wall is body 5


def sequence_dataset(snapshots, n_particles=N, n_walls=1, permutation=None, rng=None):
    """Snapshots given as lists of (i, j, kind, fn). ``permutation`` relabels the particles,
    ``rng`` shuffles the slots and swaps i and j of particle pairs at random."""
    contacts = []
    for snap in snapshots:
        i, j, kind, fn = (np.array(v) for v in zip(*snap))
        if permutation is not None:
            i, j = permutation[i], np.where(j < n_particles, permutation[np.minimum(j, n_particles - 1)], j)
        if rng is not None:
            order = rng.permutation(i.size)
            i, j, kind, fn = i[order], j[order], kind[order], fn[order]
            swap = (rng.uniform(size=i.size) < 0.5) & (j < n_particles)
            i, j = np.where(swap, j, i), np.where(swap, i, j)
        m = i.size
        normal = np.tile([1.0, 0.0], (m, 1))
        contacts.append(dict(i=i, j=j, kind=kind, fn=fn, normal=normal, ft=np.zeros(m),
                             branch=0.02 * normal, point=np.zeros((m, 2))))
    t = len(snapshots)
    return make_dataset(radius=np.full(n_particles, 0.01), position=np.zeros((t, n_particles, 2)),
                        contacts=contacts, box_min=[0.0, 0.0], box_max=[1.0, 1.0], n_walls=n_walls)


S, D = 1, 2
WALL = (4, N, S, 1.0)  # a particle–wall contact present throughout
SEQUENCE = [
    [(0, 1, S, 1.0), (1, 2, S, 1.0), (2, 3, D, 1.0), (3, 4, S, 1.0), WALL],
    [(0, 1, S, 1.0), (2, 3, S, 1.0), (3, 4, D, 0.0), (0, 4, S, 1.0), WALL],  # (1,2) lost; (3,4) carries no force
    [(1, 2, S, 1.0), (0, 1, D, 1.0), (3, 4, D, 1.0), WALL],                  # (1,2) back, (2,3) lost
    [(0, 4, S, 1.0), WALL],
    [(0, 1, S, 1.0), (1, 2, S, 1.0), (2, 3, D, 1.0), (3, 4, S, 1.0), WALL],  # all back
]


def test_gamma_by_hand(prepare):
    ds = prepare(sequence_dataset(SEQUENCE))
    # every pair the file holds (near=inf): (3,4) carries no force at t = 1 but is present
    np.testing.assert_allclose(persistence(ds, near=np.inf).values, [1, 3 / 4, 3 / 4, 0, 1], rtol=1e-12)
    np.testing.assert_allclose(persistence(ds, near=np.inf, uninterrupted=True).values, [1, 3 / 4, 2 / 4, 0, 0],
                               rtol=1e-12)
    # the wall contact counts too with walls=True (5 reference contacts)
    np.testing.assert_allclose(persistence(ds, walls=True, near=np.inf).values, [1, 4 / 5, 4 / 5, 1 / 5, 1],
                               rtol=1e-12)
    # force-bearing only (the default): (3,4) is absent at t = 1
    np.testing.assert_allclose(persistence(ds).values, [1, 2 / 4, 3 / 4, 0, 1], rtol=1e-12)
    np.testing.assert_allclose(persistence(ds, uninterrupted=True).values, [1, 2 / 4, 1 / 4, 0, 0], rtol=1e-12)


def test_gamma_from_a_later_reference(prepare):
    ds = prepare(sequence_dataset(SEQUENCE))
    # reference t = 1: {(0,1), (2,3), (3,4), (0,4)}
    gamma = persistence(ds, reference=1, near=np.inf)
    assert np.isnan(gamma.values[0])
    np.testing.assert_allclose(gamma.values[1:], [1, 2 / 4, 1 / 4, 3 / 4], rtol=1e-12)
    np.testing.assert_allclose(persistence(ds, reference=-4, uninterrupted=True, near=np.inf).values[1:], [1, 2 / 4, 0, 0],
                               rtol=1e-12)
    assert gamma.attrs["reference"] == 1


def test_transitions_by_hand(prepare):
    ds = prepare(sequence_dataset(SEQUENCE))
    out = type_transitions(ds, near=np.inf)  # every pair the file holds, (3,4) at t1 too
    # t0 -> t1: (3,4) s -> d, (2,3) d -> s, over 4 contacts at t0; t1 -> t2: (0,1) s -> d over 4
    np.testing.assert_allclose(out.delta_gamma_s_to_d.values, [0, 1 / 4, 2 / 4, 2 / 4, 2 / 4], rtol=1e-12)
    np.testing.assert_allclose(out.delta_gamma_d_to_s.values, [0, 1 / 4, 1 / 4, 1 / 4, 1 / 4], rtol=1e-12)
    with_walls = type_transitions(ds, walls=True, near=np.inf)  # the wall contact adds one contact to each N_c(t-1)
    np.testing.assert_allclose(with_walls.delta_gamma_s_to_d.values, [0, 1 / 5, 2 / 5, 2 / 5, 2 / 5], rtol=1e-12)


def test_relabelling_and_slot_order_do_not_matter():
    rng = np.random.default_rng(3)
    base = sequence_dataset(SEQUENCE)
    relabelled = sequence_dataset(SEQUENCE, permutation=np.array([3, 0, 4, 1, 2]), rng=rng)
    for kwargs in (dict(), dict(uninterrupted=True), dict(walls=True, uninterrupted=True)):
        np.testing.assert_array_equal(persistence(relabelled, **kwargs).values, persistence(base, **kwargs).values)
    for name, da in type_transitions(relabelled).items():
        np.testing.assert_array_equal(da.values, type_transitions(base)[name].values)


def oracle(ds, reference=0, walls=False):
    """Python sets of pairs, snapshot by snapshot: gamma, uninterrupted gamma, transitions."""
    n = ds.sizes["particle"]
    snaps = []
    for k in range(ds.sizes["time"]):
        m = int(ds.contact_count[k])
        pairs = {}
        for c in range(m):
            i, j = int(ds.i[k, c]), int(ds.j[k, c])
            if walls or j < n:
                pairs[(min(i, j), max(i, j))] = int(ds.kind[k, c])
        snaps.append(pairs)
    ref = set(snaps[reference])
    alive = set(ref)
    gamma, unbroken, s_to_d, d_to_s = [], [], [0.0], [0.0]
    for k, pairs in enumerate(snaps):
        if k < reference:
            gamma.append(np.nan)
            unbroken.append(np.nan)
            continue
        alive &= set(pairs)
        gamma.append(len(ref & set(pairs)) / len(ref))
        unbroken.append(len(alive) / len(ref))
    for k in range(1, len(snaps)):
        before, now = snaps[k - 1], snaps[k]
        common = set(before) & set(now)
        s_to_d.append(s_to_d[-1] + sum(before[p] == 1 and now[p] == 2 for p in common) / len(before))
        d_to_s.append(d_to_s[-1] + sum(before[p] == 2 and now[p] == 1 for p in common) / len(before))
    return np.array(gamma), np.array(unbroken), np.array(s_to_d), np.array(d_to_s)


def evolving_dataset(seed=0, n=10, t=7, m=14):
    """Random contact lists where each snapshot keeps most pairs of the previous one and
    flips some kinds."""
    rng = np.random.default_rng(seed)
    all_pairs = [(a, b) for a in range(n) for b in range(a + 1, n)]
    current = {all_pairs[k]: int(rng.integers(1, 3)) for k in rng.choice(len(all_pairs), m, replace=False)}
    snapshots = []
    for _ in range(t):
        snapshots.append([(a, b, kind, 1.0) for (a, b), kind in current.items()] + [(0, n, S, 1.0)])
        kept = {p: (3 - k if rng.uniform() < 0.3 else k) for p, k in current.items() if rng.uniform() < 0.8}
        while len(kept) < m:
            kept.setdefault(all_pairs[rng.integers(len(all_pairs))], int(rng.integers(1, 3)))
        current = kept
    return sequence_dataset(snapshots, n_particles=n, rng=rng)


@pytest.mark.parametrize("reference", [0, 2])
@pytest.mark.parametrize("walls", [False, True])
def test_against_set_oracle(reference, walls):
    ds = evolving_dataset(seed=reference + 5)
    gamma, unbroken, s_to_d, d_to_s = oracle(ds, reference, walls)
    np.testing.assert_allclose(persistence(ds, reference, walls=walls).values, gamma, rtol=1e-12)
    np.testing.assert_allclose(persistence(ds, reference, uninterrupted=True, walls=walls).values, unbroken, rtol=1e-12)
    out = type_transitions(ds, walls=walls)
    np.testing.assert_allclose(out.delta_gamma_s_to_d.values, s_to_d, rtol=1e-12)
    np.testing.assert_allclose(out.delta_gamma_d_to_s.values, d_to_s, rtol=1e-12)
    assert s_to_d[-1] > 0 and d_to_s[-1] > 0  # the data exercise both transitions


@pytest.mark.parametrize("chunk,reference,expected_computes", [(2, 0, 4), (3, 0, 3), (2, 3, 3), (1, 6, 1)])
def test_streams_one_chunk_at_a_time(chunk, reference, expected_computes):
    eager = evolving_dataset(seed=1)  # 7 snapshots
    ds = eager.chunk({"time": chunk})
    with raise_if_dask_computes(max_computes=expected_computes) as scheduler:
        gamma = persistence(ds, reference=reference, uninterrupted=True)
    assert scheduler.total_computes == expected_computes  # one compute per chunk from the reference's on
    np.testing.assert_array_equal(gamma.values, persistence(eager, reference=reference, uninterrupted=True).values)
    n_chunks = len(ds.chunks["time"])
    with raise_if_dask_computes(max_computes=n_chunks) as scheduler:
        transitions = type_transitions(ds)
    assert scheduler.total_computes == n_chunks
    for name, da in transitions.items():
        np.testing.assert_array_equal(da.values, type_transitions(eager)[name].values)


def test_key_overflow_guard_gives_same_answer(monkeypatch):
    ds = evolving_dataset(seed=4)
    expected = type_transitions(ds)
    monkeypatch.setattr(persistence_arrays, "_MAX_KEY", 3 * 11**2)  # forces passes of 2 rows
    for name, da in type_transitions(ds).items():
        np.testing.assert_array_equal(da.values, expected[name].values)


def test_pair_keys_are_unordered_and_unique():
    i = np.array([0, 3, 1, 4, 2])
    j = np.array([3, 0, 4, 5, 2])
    keys = pair_keys(i, j, 6)
    assert keys[0] == keys[1] == 3
    assert keys[3] == 4 * 6 + 5
    a, b = np.triu_indices(6, 1)
    assert np.unique(pair_keys(a, b, 6)).size == a.size


def test_empty_reference_gives_nan():
    ds = sequence_dataset([[WALL], [(0, 1, S, 1.0), WALL]])
    assert np.isnan(persistence(ds).values).all()
    np.testing.assert_allclose(persistence(ds, walls=True).values, [1.0, 1.0])
    np.testing.assert_array_equal(type_transitions(ds).delta_gamma_s_to_d.values, [0.0, 0.0])


@pytest.mark.parametrize("kwargs", [dict(reference=5), dict(reference=-6), dict(reference=1.0),
                                    dict(reference=True), dict(uninterrupted="yes"), dict(walls=1)])
def test_bad_parameters(kwargs):
    with pytest.raises(ParameterError):
        persistence(sequence_dataset(SEQUENCE), **kwargs)
