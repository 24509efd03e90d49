"""The contact points of a step: who they are across steps, and the forces they carry.

The narrow phase gives each candidate body pair one contact point (a vertex against an edge,
or any contact of a disk) or two (two edges facing each other: a double contact), in the order
of their pair. Two facts about these points are used by the stepper, the writer and restart,
and live here only:

* **Identity.** A point is the same point from one step to the next when it belongs to the same
  body pair (i, j) and has the same rank in that pair (0 for the first point, 1 for the second
  of a double contact): :func:`rank_in_pair`, :func:`point_keys`. The warm start and a
  bit-for-bit restart match impulses by these keys.
* **Impulse to force.** The contact solver works with impulses p (N s) over a time step h; the
  force a point carries during the step is f = p / h (N): :func:`point_forces`,
  :func:`force_vectors`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class PairIndex(NamedTuple):
    """The fields of a contact-point set that identity needs: ``pair`` (index of each point's
    pair, non-decreasing), ``body_i``, ``body_j`` (the pair's bodies; walls are N + w)."""

    pair: np.ndarray
    body_i: np.ndarray
    body_j: np.ndarray


def rank_in_pair(pair) -> np.ndarray:
    """Rank (0 or 1) of each point in its pair; ``pair`` lists the points' pairs in order."""
    pair = np.asarray(pair)
    rank = np.zeros(len(pair), np.int64)
    if len(pair) > 1:
        rank[1:] = (pair[1:] == pair[:-1]).astype(np.int64)
    return rank


def point_keys(points, n_bodies: int) -> np.ndarray:
    """One integer per point, equal for the same point in two steps:
    ((body_i * n_bodies) + body_j) * 2 + rank."""
    return (np.asarray(points.body_i, np.int64) * n_bodies + points.body_j) * 2 + rank_in_pair(points.pair)


def point_forces(impulse, time_step: float):
    """Normal and tangential force (N) of each point, f = p / h, from its impulses (P, 2)."""
    impulse = np.asarray(impulse)
    return impulse[:, 0] / time_step, impulse[:, 1] / time_step


def force_vectors(normal, impulse, time_step: float) -> np.ndarray:
    """(P, 2) force of body i on body j at each point, f_n n + f_t t with t = (-n_y, n_x) (N)."""
    impulse, normal = np.asarray(impulse), np.asarray(normal)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], -1)
    return (impulse[:, 0:1] * normal + impulse[:, 1:2] * tangent) / time_step
