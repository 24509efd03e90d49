"""Contact lifetimes and their survival: hand-made series whose lives are known, Kaplan–Meier
by hand, chunked equal to eager under a scheduler that counts computes."""

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from grainview.analysis.lifetimes import contact_events, kaplan_meier, lifetime_survival

from .conftest import raise_if_dask_computes
from .test_persistence import N, S, D, sequence_dataset

# snapshots at t = 0, 1, 2, 3, 4, 5 (make_dataset's default times are the indices)
SERIES = [
    [(0, 1, S, 2.0), (4, N, S, 1.0)],                                   # t0
    [(0, 1, S, 4.0), (1, 2, S, 1.0), (4, N, S, 1.0)],                   # t1: (1,2) born
    [(0, 1, D, 6.0), (1, 2, S, 1.0), (2, 3, S, 3.0), (4, N, S, 1.0)],   # t2: (0,1) turns double; (2,3) born
    [(1, 2, S, 3.0), (2, 3, S, 3.0), (4, N, S, 1.0)],                   # t3: (0,1) dies
    [(2, 3, D, 3.0), (4, N, S, 1.0)],                                   # t4: (1,2) dies; (2,3) switches
    [(1, 2, S, 5.0), (2, 3, S, 3.0), (4, N, S, 1.0)],                   # t5: (1,2) reborn; (2,3) switches back
]


def test_lives_by_hand(prepare):
    ds = prepare(sequence_dataset(SERIES))
    ev = contact_events(ds)
    lives = {(int(i), int(j), float(b)): k for k, (i, j, b) in
             enumerate(zip(ev.i.values, ev.j.values, ev.birth.values))}
    assert set(lives) == {(0, 1, 0.0), (4, N, 0.0), (1, 2, 1.0), (2, 3, 2.0), (1, 2, 5.0)}
    first = lives[(0, 1, 0.0)]  # present t0-t2, gone at t3; left-censored; one s->d switch
    assert ev.death.values[first] == 3.0 and ev.lifetime.values[first] == 3.0
    assert ev.left_censored.values[first] and not ev.censored.values[first]
    assert ev.kind_at_birth.values[first] == S and ev.kind_switches.values[first] == 1
    assert ev.mean_fn.values[first] == pytest.approx(4.0) and ev.max_fn.values[first] == 6.0
    once = lives[(1, 2, 1.0)]  # t1-t3, dies at t4, reborn at t5 as a second life
    assert ev.death.values[once] == 4.0 and ev.lifetime.values[once] == 3.0 and not ev.censored.values[once]
    assert ev.mean_fn.values[once] == pytest.approx(5.0 / 3.0)
    again = lives[(1, 2, 5.0)]  # censored at the last snapshot, observed duration 0
    assert ev.censored.values[again] and np.isnan(ev.death.values[again]) and ev.lifetime.values[again] == 0.0
    chain = lives[(2, 3, 2.0)]  # t2-t5, censored, switches s->d->s
    assert ev.censored.values[chain] and ev.lifetime.values[chain] == 3.0 and ev.kind_switches.values[chain] == 2
    wall = lives[(4, N, 0.0)]  # the wall contact: both censored
    assert ev.censored.values[wall] and ev.left_censored.values[wall] and ev.lifetime.values[wall] == 5.0
    # without walls the wall contact is gone; ordered by birth
    no_walls = contact_events(ds, walls=False)
    assert no_walls.sizes["contact_event"] == 4 and np.all(np.diff(no_walls.birth.values) >= 0)


def test_kaplan_meier_by_hand():
    # durations 1, 2+, 3, 3, 4+ (+ censored): at u = 1, 5 at risk, 1 dies -> 4/5;
    # u = 3: 3 at risk (3, 3, 4+), 2 die -> 4/5 * 1/3
    u, s = kaplan_meier([1, 2, 3, 3, 4], [True, False, True, True, False])
    np.testing.assert_allclose(u, [1, 3])
    np.testing.assert_allclose(s, [4 / 5, 4 / 15])
    u, s = kaplan_meier([2.0, 2.0], [False, False])  # everything censored: no drop
    assert u.size == 0 and s.size == 0


def test_survival_of_the_hand_series(prepare):
    ds = prepare(sequence_dataset(SERIES))
    # lives born within the series: (1,2) 3 (dies), (2,3) 3+ (censored), (1,2) 0+ (censored)
    # at u = 3: at risk (3, 3+) = 2, one dies -> S = 1/2 from tau = 3 on
    s = lifetime_survival(ds, walls=False)
    np.testing.assert_allclose(s.lifetime.values, [3.0])
    np.testing.assert_allclose(s.sel(group="all").values, [0.5])
    assert int(s.lives.sel(group="all")) == 3
    by_kind = lifetime_survival(ds, walls=False, by="kind")
    assert list(by_kind.group.values) == ["simple", "double"] and int(by_kind.lives.sel(group="double")) == 0


def test_against_a_set_oracle_and_streaming():
    from .test_persistence import evolving_dataset

    eager = evolving_dataset(seed=3)
    # oracle: walk the snapshots with Python sets
    times = eager.time.values
    present = []
    for t in range(eager.sizes["time"]):
        snap = eager.isel(time=t)
        used = snap.kind.values > 0
        present.append({(min(a, b), max(a, b)) for a, b, f in zip(snap.i.values[used], snap.j.values[used],
                                                                  snap.fn.values[used]) if f > 0})
    expected = []
    for pair in set().union(*present):
        t = 0
        while t < len(present):
            if pair in present[t]:
                b = t
                while t < len(present) and pair in present[t]:
                    t += 1
                expected.append((pair, times[b], times[t] if t < len(present) else np.nan))
            t += 1
    got = contact_events(eager)
    found = [((int(i), int(j)), b, d) for i, j, b, d in zip(got.i.values, got.j.values, got.birth.values,
                                                              got.death.values)]
    found.sort(key=lambda e: (e[0], e[1]))
    expected.sort(key=lambda e: (e[0], e[1]))
    assert [(p, b) for p, b, _ in found] == [(p, b) for p, b, _ in expected]
    np.testing.assert_array_equal([d for *_, d in found], [d for *_, d in expected])  # NaN = censored
    assert len(found) > 14 and np.isfinite([d for *_, d in found]).sum() > 3  # deaths and rebirths occur
    chunked = eager.chunk({"time": 2})
    n_chunks = len(chunked.chunks["time"])
    with raise_if_dask_computes(max_computes=n_chunks + 1):
        streamed = contact_events(chunked, walls=True)
    for name in ("i", "j", "birth", "death", "lifetime", "kind_switches", "mean_fn"):
        np.testing.assert_array_equal(streamed[name].values, contact_events(eager, walls=True)[name].values)


def test_bad_arguments():
    ds = sequence_dataset(SERIES)
    with pytest.raises(ParameterError, match="by="):
        lifetime_survival(ds, by="colour")
    with pytest.raises(ParameterError, match="unit="):
        lifetime_survival(ds, unit="days")
    with pytest.raises(ParameterError, match="increase"):
        contact_events(ds.isel(time=[1, 0, 2]))


def test_strong_persistence_by_hand(prepare):
    ds = prepare(sequence_dataset(SERIES))
    # strong: f_n > mean f_n of the snapshot (walls out; a force equal to the mean is not strong)
    # t0 {} (one contact, at the mean); t1 {01} (4 > 2.5); t2 {01} (6 > 10/3); t3 {} (3 = 3);
    # t4 {}; t5 {12} (5 > 4)
    # lag 1: t1->t2 keeps 01, t2->t3 loses it: 1 of 2; lag 2: t1->t3, t2->t4 lose it: 0 of 2
    sp = ds.grain.strong_persistence(max_lag=2)
    np.testing.assert_allclose(sp.values, [1.0, 1 / 2, 0.0])
    np.testing.assert_allclose(sp.lag_time.values, [0.0, 1.0, 2.0])
    # with the strong threshold at half the mean: t0 {01}, t1 {01}, t2 {01, 23}, t3 {12, 23},
    # t4 {23}, t5 {12, 23}; lag 1 keeps 1 + 1 + 1 + 1 + 1 of 1 + 1 + 2 + 2 + 1 = 5/7
    np.testing.assert_allclose(ds.grain.strong_persistence(max_lag=1, strong=0.5).values, [1.0, 5 / 7])


def test_median_lifetime_by_force_by_hand():
    ds = sequence_dataset(SERIES)
    # lives born within the series, walls in: (1,2) born t1 mean 5/3 N, dies after 3 s; (2,3) born
    # t2 mean 3 N censored; (1,2) reborn t5 mean 5 N censored. Mean of the three: 29/9 N.
    # relative: 0.517 (bin 0.5-1), 0.931 (0.5-1), 1.55 (1.5-2): bin 0.5-1 has KM S = 1/2 at 3 s
    m = ds.grain.median_lifetime_by_force()
    assert m.sel(force_bin="0.5-1").item() == 3.0 and int(m.lives.sel(force_bin="0.5-1")) == 2
    assert np.isnan(m.sel(force_bin="1.5-2").item()) and int(m.lives.sel(force_bin="1.5-2")) == 1


def test_survival_by_force_class_at_birth_and_over_the_life():
    ds = sequence_dataset(SERIES)
    # lives born within the series (walls in): (1,2) born t1 at 1 N, mean 5/3 N, dies after 3 s;
    # (2,3) born t2 at 3 N, mean 3 N, censored; (1,2) reborn t5 at 5 N, censored
    life = ds.grain.lifetime_survival(by="force")  # <f> = 29/9 N over the life
    assert list(life.group.values) == ["strong", "weak", "very weak"]
    assert [int(n) for n in life.lives.values] == [1, 2, 0]
    np.testing.assert_allclose(life.sel(group="weak").values, [0.5])  # at tau = 3: 2 at risk, 1 dies
    birth = ds.grain.lifetime_survival(by="force", force_at="birth")  # <f> = 3 N at birth
    assert [int(n) for n in birth.lives.values] == [1, 2, 0]  # 5 N strong; 1 N and 3 N weak
    very = ds.grain.lifetime_survival(by="force", force_at="birth", very_weak=0.5)  # 1 N < 1.5 N
    assert [int(n) for n in very.lives.values] == [1, 1, 1]
    np.testing.assert_allclose(very.sel(group="very weak").values, [0.0])  # its one life ends at 3 s
    with pytest.raises(ParameterError, match="force_at"):
        ds.grain.lifetime_survival(by="force", force_at="death")
