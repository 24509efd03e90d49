"""solver.warm_start: the binary-search kernel against numpy's sort and search, bit for bit, and
against a dictionary from key to impulse; no last points, no new points."""

import numpy as np
import pytest

from solver.warm_start import match_impulses, match_impulses_reference


def _keys(seed, last=400, kept=250, new=30, shuffle=True):
    rng = np.random.default_rng(seed)
    last_keys = np.sort(rng.choice(10**6, last, replace=False)).astype(np.int64)
    last_keys[[10, 11]] = last_keys[[11, 10]]  # nearly sorted, as detection gives them
    impulse = rng.normal(size=(last, 2))
    keys = np.concatenate([last_keys[50:50 + kept], rng.choice(np.arange(10**6, 2 * 10**6), new, replace=False),
                           [-1, 2 * 10**6 + 7]])  # below and above every last key
    if shuffle:
        rng.shuffle(keys)
    else:  # nearly sorted, as detection gives them: the forward walk, with one step back
        keys = np.sort(keys)
        keys[[100, 101]] = keys[[101, 100]]
    return last_keys, impulse, keys.astype(np.int64)


@pytest.mark.parametrize("shuffle", [True, False])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_kernel_is_the_reference_and_the_dictionary(seed, shuffle):
    last_keys, impulse, keys = _keys(seed, shuffle=shuffle)
    got = match_impulses(last_keys, impulse, keys)
    np.testing.assert_array_equal(got, match_impulses_reference(last_keys, impulse, keys))
    by_key = dict(zip(last_keys.tolist(), map(tuple, impulse)))
    np.testing.assert_array_equal(got, [by_key.get(k, (0.0, 0.0)) for k in keys.tolist()])
    assert np.count_nonzero(got[:, 0]) == 250


def test_no_last_points_and_no_new_points():
    last_keys, impulse, keys = _keys(0)
    assert match_impulses(np.empty(0, np.int64), np.empty((0, 2)), keys).tolist() == [[0.0, 0.0]] * keys.size
    assert match_impulses(last_keys, impulse, np.empty(0, np.int64)).shape == (0, 2)
    one = match_impulses(np.array([5]), np.array([[1.5, -0.5]]), np.array([4, 5, 6]))
    assert one.tolist() == [[0.0, 0.0], [1.5, -0.5], [0.0, 0.0]]


@pytest.mark.parametrize("seed", [0, 1])
def test_repeated_keys_far_jumps_and_two_sorted_runs(seed):
    """Keys that repeat, that jump far ahead (past the walk's steps, to the binary search) and
    that come in two sorted runs (as blocks of points detected apart would)."""
    last_keys, impulse, keys = _keys(seed, last=2000, kept=1500, new=100, shuffle=False)
    by_key = dict(zip(last_keys.tolist(), map(tuple, impulse)))
    cases = {"repeated": np.repeat(keys, 2), "far jumps": keys[::37].copy(),
             "two runs": np.concatenate([np.sort(keys[1::2]), np.sort(keys[::2])])}
    for name, case in cases.items():
        got = match_impulses(last_keys, impulse, case)
        np.testing.assert_array_equal(got, match_impulses_reference(last_keys, impulse, case), err_msg=name)
        np.testing.assert_array_equal(got, [by_key.get(k, (0.0, 0.0)) for k in case.tolist()], err_msg=name)
