"""Broad phase: cell-list candidate pairs against an all-pairs oracle; wall candidates."""

from __future__ import annotations

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver.broadphase import candidate_pairs, wall_candidates

from . import naive_geometry as naive


def _pairs(pos, radius, alert):
    pi, pj = candidate_pairs(pos, radius, alert)
    assert pi.dtype == np.int32 and pj.dtype == np.int32
    assert np.all(pi < pj)
    order = np.lexsort((pj, pi))
    assert np.array_equal(order, np.arange(pi.size)), "pairs sorted by pi then pj"
    return list(zip(pi.tolist(), pj.tolist()))


@pytest.mark.parametrize("seed, n, box, alert", [
    (0, 200, 1.0, 0.0),     # dense
    (1, 300, 5.0, 0.01),    # dilute: many empty cells
    (2, 50, 20.0, 0.05),    # very sparse
    (3, 2, 1.0, 0.0),
    (4, 120, 0.2, 0.02),    # everything in one or two cells
])
def test_matches_all_pairs(seed, n, box, alert):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.0, box, size=(n, 2))
    radius = rng.choice([0.0125, 0.01875, 0.025], size=n)
    got = _pairs(pos, radius, alert)
    assert got == naive.all_pairs(pos, radius, alert)


def test_particles_on_cell_borders_and_exact_reach():
    # lattice with spacing equal to the cell size 2 r + alert: pairs exactly at reach are kept
    r, alert = 0.5, 0.25
    g = np.arange(6) * (2 * r + alert)
    pos = np.array([(x, y) for x in g for y in g], dtype=float)
    radius = np.full(len(pos), r)
    got = _pairs(pos, radius, alert)
    assert got == naive.all_pairs(pos, radius, alert)
    assert len(got) == 2 * 6 * 5  # nearest neighbours along x and y only


def test_outlier_does_not_blow_up_the_grid():
    rng = np.random.default_rng(5)
    pos = np.vstack([rng.uniform(0, 1, (100, 2)), [[1e6, 1e6]]])
    radius = np.full(101, 0.03)
    assert _pairs(pos, radius, 0.0) == naive.all_pairs(pos, radius, 0.0)


def test_fewer_than_two_particles():
    for n in (0, 1):
        pi, pj = candidate_pairs(np.zeros((n, 2)), np.ones(n), 0.1)
        assert pi.size == 0 and pj.size == 0 and pi.dtype == np.int32


def test_wall_candidates():
    pos = np.array([[0.5, 0.1], [0.5, 0.5], [0.95, 0.5], [0.5, -0.2]])
    radius = np.array([0.1, 0.1, 0.1, 0.1])
    wall_point = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    wall_normal = np.array([[0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 0.0]])
    p, w = wall_candidates(pos, radius, wall_point, wall_normal, alert=0.0)
    # particle 0 touches the bottom exactly, 2 overlaps the right wall, 3 went through the bottom
    assert list(zip(p.tolist(), w.tolist())) == [(0, 0), (2, 1), (3, 0)]
    p, w = wall_candidates(pos, radius, wall_point, wall_normal, alert=0.31)
    assert (1, 0) not in list(zip(p.tolist(), w.tolist()))
    p, w = wall_candidates(pos, radius, wall_point, wall_normal, alert=0.41)
    assert {(1, 0), (1, 1), (1, 2), (1, 3)} <= set(zip(p.tolist(), w.tolist()))


def test_wall_candidates_match_numpy():
    rng = np.random.default_rng(7)
    pos = rng.uniform(0, 1, (80, 2))
    radius = rng.uniform(0.01, 0.05, 80)
    angles = rng.uniform(0, 2 * np.pi, 3)
    wall_normal = np.column_stack([np.cos(angles), np.sin(angles)])
    wall_point = rng.uniform(0, 1, (3, 2))
    p, w = wall_candidates(pos, radius, wall_point, wall_normal, 0.02)
    d = ((pos[:, None, :] - wall_point[None]) * wall_normal[None]).sum(-1)
    ep, ew = np.nonzero(d <= radius[:, None] + 0.02)
    assert np.array_equal(p, ep) and np.array_equal(w, ew)


def test_invalid_inputs():
    with pytest.raises(ParameterError, match="alert"):
        candidate_pairs(np.zeros((2, 2)), np.ones(2), -1.0)
    with pytest.raises(ParameterError, match="pos"):
        candidate_pairs(np.zeros((2, 3)), np.ones(2), 0.0)
    with pytest.raises(ParameterError, match="radius"):
        candidate_pairs(np.zeros((2, 2)), np.ones(3), 0.0)
    with pytest.raises(ParameterError, match="unit"):
        wall_candidates(np.zeros((2, 2)), np.ones(2), [[0, 0]], [[0, 2.0]], 0.0)
