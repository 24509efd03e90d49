"""Force classes and the proportions of simple/double, weak/strong contacts, by hand
(ERRATA item 4: f_s = k_s <f_n>_s / <f_n>, not the paper's printed swap)."""

import numpy as np
import pytest

from grainview import make_dataset
from grainview.contract.errors import ParameterError
from grainview.analysis.force_networks import contact_proportions, force_class

from . import builders
from .conftest import raise_if_dask_computes

RTOL = 1e-12


def contacts_dataset(snapshots, n_particles=6, n_walls=4):
    contacts = []
    for snap in snapshots:
        m = len(snap["i"])
        normal = np.tile([0.0, 1.0], (m, 1))
        contacts.append(dict(i=snap["i"], j=snap["j"], fn=snap["fn"], kind=snap["kind"], normal=normal,
                             ft=np.zeros(m), branch=0.02 * normal, point=np.zeros((m, 2))))
    t = len(snapshots)
    return make_dataset(radius=np.full(n_particles, 0.01), position=np.zeros((t, n_particles, 2)),
                        contacts=contacts, box_min=[0.0, 0.0], box_max=[1.0, 1.0], n_walls=n_walls)


def hand_dataset():
    """Snapshot 0: f = 0, 1, 2, 10, 37 (mean 10), kinds s s d d s, and a wall contact of 100 N
    (simple). Snapshot 1: f = 4, 4 (mean 4), both double."""
    return contacts_dataset([
        dict(i=[0, 1, 2, 3, 4, 5], j=[1, 2, 3, 4, 5, 6], fn=[0.0, 1.0, 2.0, 10.0, 37.0, 100.0],
             kind=[1, 1, 2, 2, 1, 1]),
        dict(i=[0, 2], j=[1, 3], fn=[4.0, 4.0], kind=[2, 2]),
    ])


def test_force_class_by_hand(prepare):
    ds = prepare(hand_dataset())
    with raise_if_dask_computes():
        labels = force_class(ds, near=np.inf)  # every pair the file holds, the f_n = 0 one too
        loaded = force_class(ds)
    labels = labels.compute()
    # force-bearing only (the default): mean (1 + 2 + 10 + 37)/4 = 12.5, thresholds 1.25 and 12.5
    np.testing.assert_array_equal(loaded.values[0, :6], [0, 1, 2, 2, 3, 0])
    assert labels.dtype == np.int8
    assert labels.dims == ("time", "contact")
    # thresholds 0.1 * 10 = 1 and 10: 0 very weak, 1 (not < 1) weak, 2 weak, 10 (<= 10) weak,
    # 37 strong; the wall contact and the empty slots are 0
    np.testing.assert_array_equal(labels.values[0, :6], [1, 2, 2, 2, 3, 0])
    np.testing.assert_array_equal(labels.values[0, 6:], 0)
    np.testing.assert_array_equal(labels.values[1, :3], [2, 2, 0])
    np.testing.assert_array_equal(labels.attrs["flag_values"], [0, 1, 2, 3])
    assert labels.attrs["flag_meanings"] == "not_selected very_weak weak strong"


def test_force_class_thresholds_and_walls():
    ds = hand_dataset()
    # with the wall contact the mean is 150/6 = 25: 0, 1, 2 < 2.5 very weak, 10 weak, 37 and 100 strong
    np.testing.assert_array_equal(force_class(ds, walls=True, near=np.inf).values[0, :6], [1, 1, 1, 2, 3, 3])
    # thresholds 0.15 * 10 = 1.5 and 0.5 * 10 = 5
    np.testing.assert_array_equal(force_class(ds, very_weak=0.15, strong=0.5, near=np.inf).values[0, :5],
                                  [1, 1, 2, 3, 3])


def test_contact_proportions_by_hand(prepare):
    ds = prepare(hand_dataset())
    with raise_if_dask_computes():
        prop = contact_proportions(ds, near=np.inf)  # every pair the file holds, the f_n = 0 one too
        loaded = contact_proportions(ds)
    prop = prop.compute().isel(time=0)
    # force-bearing only (the default): 4 contacts, mean 12.5, 1 very weak (f = 1 < 1.25)
    loaded = loaded.compute().isel(time=0)
    assert int(loaded["n_contacts"]) == 4 and float(loaded["mean_fn"]) == pytest.approx(12.5, rel=RTOL)
    assert float(loaded["very_weak_fraction"]) == pytest.approx(1 / 4, rel=RTOL)
    k_s, k_d = 3 / 5, 2 / 5
    mean, mean_s, mean_d = 10.0, 38 / 3, 6.0
    expected = {
        "n_contacts": 5, "k_s": k_s, "k_d": k_d,
        "f_s": k_s * mean_s / mean, "f_d": k_d * mean_d / mean,  # 0.76 and 0.24 (ERRATA item 4)
        "k_s_strong": 1 / 5, "k_s_weak": 2 / 5, "k_d_strong": 0.0, "k_d_weak": 2 / 5,
        "weak_fraction": 4 / 5, "very_weak_fraction": 1 / 5, "very_weak_simple": 1 / 5, "very_weak_double": 0.0,
        "mean_fn": mean, "mean_fn_simple": mean_s, "mean_fn_double": mean_d,
    }
    for name, value in expected.items():
        assert float(prop[name]) == pytest.approx(value, rel=RTOL, abs=0), name
    assert float(prop["f_s"]) == pytest.approx(0.76, rel=RTOL)
    # the paper's printed (swapped) form would give k_s <f_n>_d/<f_n> = 0.36: not what we return
    assert float(prop["f_s"]) != pytest.approx(k_s * mean_d / mean)


def test_contact_proportions_second_snapshot_and_walls():
    prop = contact_proportions(hand_dataset()).isel(time=1)
    # two double contacts of equal force: nothing strong, no simple contact, f_s = 0 (not NaN)
    assert float(prop["k_d"]) == 1.0 and float(prop["k_s"]) == 0.0
    assert float(prop["f_s"]) == 0.0 and float(prop["f_d"]) == 1.0
    assert float(prop["k_d_weak"]) == 1.0 and float(prop["k_d_strong"]) == 0.0
    assert np.isnan(float(prop["mean_fn_simple"]))
    walls = contact_proportions(hand_dataset(), walls=True, near=np.inf).isel(time=0)
    # mean 25: strong 37 (s), 100 (s); very weak 0, 1 (s), 2 (d)
    assert float(walls["k_s"]) == pytest.approx(4 / 6, rel=RTOL)
    assert float(walls["k_s_strong"]) == pytest.approx(2 / 6, rel=RTOL)
    assert float(walls["very_weak_simple"]) == pytest.approx(2 / 6, rel=RTOL)
    assert float(walls["very_weak_double"]) == pytest.approx(1 / 6, rel=RTOL)
    assert float(walls["f_s"]) == pytest.approx(138 / 150, rel=RTOL)


def test_proportions_add_up_and_agree_with_classes(prepare):
    eager = builders.mixed_contacts(seed=7, t=4)
    ds = prepare(eager)
    prop = contact_proportions(ds).compute()
    np.testing.assert_allclose(prop.k_s + prop.k_d, 1.0, rtol=RTOL)
    np.testing.assert_allclose(prop.f_s + prop.f_d, 1.0, rtol=RTOL)
    np.testing.assert_allclose(prop.k_s_strong + prop.k_s_weak, prop.k_s, rtol=RTOL)
    np.testing.assert_allclose(prop.k_d_strong + prop.k_d_weak, prop.k_d, rtol=RTOL)
    np.testing.assert_allclose(prop.weak_fraction, prop.k_s_weak + prop.k_d_weak, rtol=RTOL)
    np.testing.assert_allclose(prop.very_weak_fraction, prop.very_weak_simple + prop.very_weak_double, rtol=RTOL)
    labels = force_class(ds).compute().values
    n_c = prop.n_contacts.values
    kind = eager.kind.values
    np.testing.assert_allclose(prop.very_weak_fraction, (labels == 1).sum(1) / n_c, rtol=RTOL)
    np.testing.assert_allclose(prop.k_s_strong, ((labels == 3) & (kind == 1)).sum(1) / n_c, rtol=RTOL)
    np.testing.assert_allclose(prop.k_d_weak, (np.isin(labels, (1, 2)) & (kind == 2)).sum(1) / n_c, rtol=RTOL)


@pytest.mark.parametrize("kwargs", [dict(very_weak=-0.1), dict(strong=np.nan), dict(very_weak=2.0, strong=1.0),
                                    dict(very_weak="low"), dict(strong=True)])
def test_bad_thresholds(kwargs):
    ds = hand_dataset()
    with pytest.raises(ParameterError):
        force_class(ds, **kwargs)
    with pytest.raises(ParameterError):
        contact_proportions(ds, **kwargs)
