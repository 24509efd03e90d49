"""Identity of contact points across steps and impulse -> force, against hand-made cases."""

import numpy as np
import pytest

from solver.contact_points import PairIndex, force_vectors, point_forces, point_keys, rank_in_pair


def test_rank_in_pair_by_hand():
    # pairs: 0 (simple), 1 (double), 2 (simple), 3 (double)
    np.testing.assert_array_equal(rank_in_pair([0, 1, 1, 2, 3, 3]), [0, 0, 1, 0, 0, 1])
    np.testing.assert_array_equal(rank_in_pair([]), [])
    np.testing.assert_array_equal(rank_in_pair([5]), [0])


def test_keys_identify_the_same_point_and_only_it():
    points = PairIndex(pair=np.array([0, 1, 1]), body_i=np.array([0, 2, 2]), body_j=np.array([3, 5, 5]))
    keys = point_keys(points, n_bodies=10)
    np.testing.assert_array_equal(keys, [(0 * 10 + 3) * 2, (2 * 10 + 5) * 2, (2 * 10 + 5) * 2 + 1])
    # the same points found in another order of pairs get the same keys
    later = PairIndex(pair=np.array([0, 0, 1]), body_i=np.array([2, 2, 0]), body_j=np.array([5, 5, 3]))
    assert set(point_keys(later, 10)) == set(keys)


def test_forces_are_impulses_over_the_time_step():
    impulse = np.array([[2e-3, -1e-3], [0.0, 0.0]])
    fn, ft = point_forces(impulse, 5e-4)
    np.testing.assert_allclose(fn, [4.0, 0.0], rtol=1e-14)
    np.testing.assert_allclose(ft, [-2.0, 0.0], rtol=1e-14)
    # normal along x: t = (-n_y, n_x) = (0, 1), so f = (f_n, f_t)
    f = force_vectors(np.array([[1.0, 0.0], [0.0, 1.0]]), impulse, 5e-4)
    np.testing.assert_allclose(f, [[4.0, -2.0], [0.0, 0.0]], rtol=1e-14, atol=0)
    normal = np.array([[0.6, 0.8]])
    f = force_vectors(normal, np.array([[1e-3, 5e-4]]), 1e-3)
    assert f[0] @ normal[0] == pytest.approx(1.0, rel=1e-14)  # the normal component is f_n
    assert f[0] @ np.array([-0.8, 0.6]) == pytest.approx(0.5, rel=1e-14)  # the tangential one f_t
