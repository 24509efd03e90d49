"""Near contacts as a counting convention (``near=``): a hand-made chain of five particles
whose last two pairs are open at known gaps."""

import numpy as np
import pytest

from grainview import make_dataset
from grainview.analysis.contacts import selection
from grainview.contract.errors import ParameterError

from .conftest import raise_if_dask_computes

X, Y = [1.0, 0.0], [0.0, 1.0]


def chain(held=3e-3, gap=True):
    """Pairs (0,1), (1,2) loaded (5 N, 3 N) along x; (2,3) open at 0.5 mm and (3,4) open at
    2 mm, both along y, f = 0. ``held``: the file's near_contacts_m attribute."""
    snap = dict(i=[0, 1, 2, 3], j=[1, 2, 3, 4], kind=[1, 1, 1, 1], normal=[X, X, Y, Y],
                fn=[5.0, 3.0, 0.0, 0.0], ft=[0.0, 0.0, 0.0, 0.0])
    if gap:
        snap["gap"] = [-1e-4, 0.0, 5e-4, 2e-3]
    attrs = {} if held is None else {"near_contacts_m": held}
    return make_dataset(radius=np.full(5, 0.01), position=np.zeros((5, 2)), contacts=[snap],
                        box_min=[0.0, 0.0], box_max=[1.0, 1.0], attrs=attrs)


def test_gap_threshold_decides_which_pairs_count(prepare):
    ds = prepare(chain())
    with raise_if_dask_computes():
        results = {near: (ds.grain.coordination(near=near)["z"], ds.grain.fabric_anisotropy(near=near)["a"],
                          ds.grain.contact_proportions(near=near)["very_weak_fraction"])
                   for near in (None, 1e-3, 3e-3)}
    expected = {  # z; fabric a = 2 (F1 - F2); very weak (f < 0.1 <f>)
        None: (4 / 3, 2.0, 0.0),        # 2 loaded pairs along x
        1e-3: (6 / 4, 2 / 3, 1 / 3),    # + (2,3): F = diag(2/3, 1/3), <f> = 8/3
        3e-3: (8 / 5, 0.0, 2 / 4),      # + (3,4): F = diag(1/2, 1/2), <f> = 2
    }
    for near, values in expected.items():
        for da, value in zip(results[near], values):
            assert float(da.compute()[0]) == pytest.approx(value, abs=1e-12), (near, da.name)


def test_every_pair_the_file_holds_needs_no_gap():
    ds = chain(held=None, gap=False)
    assert int(selection(ds, near=np.inf).sum()) == 4
    assert int(selection(ds).sum()) == 2


@pytest.mark.parametrize("near,held,gap,match", [
    (-1e-3, 3e-3, True, "expected None"),
    ("close", 3e-3, True, "expected None"),
    (1e-3, 3e-3, False, "no 'gap' variable"),
    (1e-3, None, True, "force-bearing contacts only"),
    (4e-3, 3e-3, True, "exceeds the gap"),
])
def test_bad_near_arguments_say_what_is_wrong(near, held, gap, match):
    with pytest.raises(ParameterError, match=match):
        selection(chain(held=held, gap=gap), near=near)


def test_a_pair_whose_gap_equals_near_counts():
    """The rule is gap <= near: an unloaded pair exactly at the threshold is in the network, and
    one a float's width beyond it is not."""
    ds = chain()
    gaps = ds["gap"].values[0]
    for pair, expected in ((2, 3), (3, 4)):  # threshold at the gap of pair (2,3), then of (3,4)
        near = float(gaps[pair])
        assert int(selection(ds, near=near).sum()) == expected
        assert int(selection(ds, near=float(np.nextafter(near, 0.0))).sum()) == expected - 1
    assert float(ds.grain.coordination(near=float(gaps[2]))["z"].values[0]) == pytest.approx(6 / 4, abs=1e-12)
