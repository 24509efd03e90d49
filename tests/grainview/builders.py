"""Small datasets built by hand, whose answers are known exactly.

Each builder returns an eager dataset of the contract; tests derive the expected values
from the same few numbers with pencil-and-paper formulas.
"""

from __future__ import annotations

import numpy as np

from grainview.contract.dataset import make_dataset

R = 0.01  # disk radius, m


def two_disks(force=3.0, tangential=0.0, overlap=0.0):
    """Two disks of radius R side by side along x, pressed with normal force ``force`` (N)."""
    d = 2 * R - overlap
    pos = np.array([[0.0, 0.0], [d, 0.0]])
    contacts = [dict(i=[0], j=[1], kind=[1], normal=[[1.0, 0.0]], fn=[force], ft=[tangential])]
    return make_dataset(radius=[R, R], position=pos, contacts=contacts,
                        box_min=[-R, -R], box_max=[d + R, R])


def square_lattice(nx=4, ny=3, fx=2.0, fy=5.0, kinds=None):
    """Disks of radius R on an nx-by-ny square grid of spacing 2R, every horizontal contact
    carrying ``fx`` and every vertical one ``fy`` (N). Box: the grid's bounding square cells.

    Counts: (nx-1) ny horizontal and nx (ny-1) vertical contacts. ``kinds`` optionally gives
    the kind (1/2) of each contact in the order horizontal then vertical.
    """
    a = 2 * R
    ix, iy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    ids = ix * ny + iy
    pos = np.stack([ix.ravel() * a, iy.ravel() * a], axis=-1).astype(float)
    hi, hj = ids[:-1, :].ravel(), ids[1:, :].ravel()
    vi, vj = ids[:, :-1].ravel(), ids[:, 1:].ravel()
    i = np.concatenate([hi, vi])
    j = np.concatenate([hj, vj])
    normal = np.concatenate([np.tile([1.0, 0.0], (hi.size, 1)), np.tile([0.0, 1.0], (vi.size, 1))])
    fn = np.concatenate([np.full(hi.size, fx), np.full(vi.size, fy)])
    kind = np.ones(i.size, "i1") if kinds is None else np.asarray(kinds, "i1")
    contacts = [dict(i=i, j=j, kind=kind, normal=normal, fn=fn, ft=np.zeros(i.size))]
    return make_dataset(radius=np.full(nx * ny, R), position=pos, contacts=contacts,
                        box_min=[-R, -R], box_max=[(nx - 1) * a + R, (ny - 1) * a + R])


def hexagonal_lattice(nx=6, ny=5, force=1.0):
    """Disks of radius R on a triangular (hexagonal-packing) lattice of spacing 2R; every
    nearest-neighbour contact carries ``force``. Contact directions: 0, 60 and 120 degrees."""
    a = 2 * R
    pos = np.array([[a * (x + 0.5 * (y % 2)), a * np.sqrt(3) / 2 * y] for y in range(ny) for x in range(nx)])
    n = len(pos)
    d = np.linalg.norm(pos[:, None] - pos[None], axis=-1)
    i, j = np.nonzero(np.triu(np.isclose(d, a), 1))
    normal = (pos[j] - pos[i]) / a
    contacts = [dict(i=i, j=j, kind=np.ones(i.size, "i1"), normal=normal, fn=np.full(i.size, force),
                     ft=np.zeros(i.size))]
    lo = pos.min(0) - R
    hi = pos.max(0) + R
    return make_dataset(radius=np.full(n, R), position=pos, contacts=contacts, box_min=lo, box_max=hi)


def mixed_contacts(seed=0, n=12, m=20, t=3, walls=True):
    """A random but explicit set of simple and double contacts (and wall contacts) over ``t``
    snapshots, with random forces of both signs of ft; for identities that must hold exactly
    (sigma = sigma_s + sigma_d, F = F_s + F_d) rather than for closed-form values."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 0.2, size=(t, n, 2))
    snaps = []
    n_walls = 4 if walls else 0
    for k in range(t):
        pairs = set()
        while len(pairs) < m:
            a, b = sorted(rng.choice(n, 2, replace=False))
            pairs.add((int(a), int(b)))
        i, j = np.array(sorted(pairs)).T
        branch = pos[k, j] - pos[k, i]
        normal = branch / np.linalg.norm(branch, axis=1, keepdims=True)
        point = pos[k, i] + 0.5 * branch
        if walls:
            wi = np.array([0, 3])
            wj = np.array([n + 0, n + 2])
            wn = np.array([[0.0, -1.0], [0.0, 1.0]])
            wb = 0.01 * wn
            i = np.concatenate([i, wi]); j = np.concatenate([j, wj])
            normal = np.concatenate([normal, wn]); branch = np.concatenate([branch, wb])
            point = np.concatenate([point, pos[k, wi] + wb])
        c = i.size
        snaps.append(dict(i=i, j=j, kind=rng.integers(1, 3, c), normal=normal, branch=branch, point=point,
                          fn=rng.exponential(1.0, c), ft=rng.normal(0, 0.3, c)))
    return make_dataset(radius=np.full(n, 0.01), position=pos, contacts=snaps,
                        box_min=[0.0, 0.0], box_max=[0.2, 0.2], n_walls=n_walls)
