"""Force chains after Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005),
on plain arrays (docs/analysis.md, "Force chains").

For each snapshot:

1. the stress of each particle p from its own contacts, compression positive,

       sigma_p = (1/V_p) sum_{c of p} s_pc f^c (x) (x^c - x_p),

   f^c = f_n n + f_t t the force of body i on body j (docs/conventions.md §0), x^c the
   contact's application point (``point``), x_p the centre of p, s_pc = +1 when p is body i of
   the contact and -1 when it is body j, V_p the particle's volume (area times the slab
   thickness); wall contacts load their particle like any other. Summed over the particles,
   sum_p V_p sigma_p = sum_c f^c (x) l^c = V sigma, the sample's stress (docs/conventions.md §1),
   since (x^c - x_i) - (x^c - x_j) = x_j - x_i = l^c;
2. its principal stresses sigma_1 >= sigma_2 (of the symmetric part) and major direction
   theta_1;
3. the *chain particles*: sigma_1 above the mean of sigma_1 over the snapshot's particles, and
   a major direction (sigma_1 - sigma_2 > :data:`ISOTROPY_TOLERANCE` |sigma_1|: an isotropic
   stress has none);
4. a *link* for each force-bearing contact between two chain particles whose branch vector
   makes an angle of at most ``angle`` with the major direction of both (|cos| >= cos angle);
5. chains: the connected sets of linked particles of at least ``min_size`` (3) particles.

The per-contact sums, the link test and the connected sets (union-find) are numba kernels
(:mod:`grainview.analysis._kernels.force_chains`) over every snapshot at once; the rest is numpy.
"""

from __future__ import annotations

import numpy as np

from ...contract import portable_math
from .._kernels.force_chains import accumulate_moments, aligned_links, follow_tracks, label_components
from .._kernels.records import XY, Slots
from .signature import CONTACT, CONTACT_XY, PARTICLE, SCALAR, TENSOR, core_dims
from .tensors import principal
from .vectors import force_vectors

PARTICLE_XY = ("particle", "xy")
PARTICLE_TENSOR = ("particle",) + TENSOR
LENGTH = ("length",)

ISOTROPY_TOLERANCE = 1e-9
"""A particle stress with sigma_1 - sigma_2 <= this times |sigma_1| is isotropic: it has no
major direction, so the particle links nothing (an isotropically loaded particle's computed
direction would be round-off)."""


def _rows(a, tail):
    """``a`` as a C-contiguous array of rows: (R,) + its last ``tail`` axes."""
    a = np.asarray(a)
    return np.ascontiguousarray(a.reshape((-1,) + a.shape[a.ndim - tail:]))


@core_dims(CONTACT, CONTACT, CONTACT, CONTACT, CONTACT_XY, CONTACT_XY, CONTACT, PARTICLE_XY,
           out=(PARTICLE_TENSOR,))
def particle_moments(i, j, fn, ft, normal, point, mask, position, branch=None):
    """Sum over each particle's contacts of s f (x) (x^c - x_p), N m (..., P, 2, 2).

        M_p,ab = sum_{c of p} s_pc f^c_a (x^c - x_p)_b,

    s_pc = +1 for body i, -1 for body j of contact c; only the slots of ``mask`` count, and only
    the particle side of a wall contact (j >= P). ``i, j, fn, ft, mask`` (..., C),
    ``normal, point`` (..., C, 2), ``position`` (..., P, 2). sigma_p = M_p / V_p, and
    sum_p M_p = sum_c f (x) l.

    In a periodic cell, give the contacts' minimum-image ``branch`` (..., C, 2): the lever
    arms x^c - x_i and x^c - x_j are then those of one image of the pair
    (:func:`periodic_points`), so that a contact across the cell's boundary loads both its
    particles with levers of the size of the particles, whichever image its point is stored at.
    Without ``branch`` the levers are taken from the stored centres as they are (a bounded
    sample).
    """
    lead = np.broadcast_shapes(np.shape(fn), np.shape(mask), np.shape(i))
    n_part = np.shape(position)[-2]
    force = force_vectors(np.broadcast_to(fn, lead), np.broadcast_to(ft, lead), np.broadcast_to(normal, lead + (2,)))
    point = np.broadcast_to(point, lead + (2,))
    position = np.broadcast_to(position, lead[:-1] + (n_part, 2))
    i_rows = _rows(np.broadcast_to(i, lead), 1).astype(np.int64)
    j_rows = _rows(np.broadcast_to(j, lead), 1).astype(np.int64)
    forces = XY(_rows(force[..., 0], 1), _rows(force[..., 1], 1))
    centres = XY(_rows(position[..., 0], 1).astype(np.float64), _rows(position[..., 1], 1).astype(np.float64))
    mask_rows = _rows(np.broadcast_to(mask, lead), 1).astype(bool)
    if branch is None:
        moments = accumulate_moments(Slots(i_rows, j_rows, mask_rows), forces,
                                     XY(_rows(point[..., 0], 1).astype(np.float64),
                                        _rows(point[..., 1], 1).astype(np.float64)), centres)
        return moments.reshape(lead[:-1] + (n_part, 2, 2))
    point_i, point_j = periodic_points(i, j, point, np.broadcast_to(branch, lead + (2,)), position)
    nobody = np.full_like(i_rows, -1)
    moments = accumulate_moments(Slots(i_rows, nobody, mask_rows), forces,
                                 XY(_rows(point_i[..., 0], 1), _rows(point_i[..., 1], 1)), centres)
    moments += accumulate_moments(Slots(nobody, j_rows, mask_rows), forces,
                                  XY(_rows(point_j[..., 0], 1), _rows(point_j[..., 1], 1)), centres)
    return moments.reshape(lead[:-1] + (n_part, 2, 2))


def periodic_points(i, j, point, branch, position):
    """Each contact's point as seen from its body i and from its body j, m (..., C, 2) each:
    ``x_i + lever_i`` and ``x_j + lever_j`` with ``lever_i - lever_j = branch``, the levers of
    one image of the pair.

    In a periodic cell the stored centres of a contact's two particles may be whole cells apart
    from the image its point sits at. The point is at most a particle's size from the image of
    the body it was computed from, so of ``point - x_i`` and ``point - x_j`` the shorter is a
    true lever; the other is that one less (or plus) the minimum-image ``branch``. Wall
    contacts (j outside the particles) and empty slots keep their point.

    Parameters
    ----------
    i, j : array_like of int, (..., C)
        Bodies of each slot.
    point, branch : array_like, (..., C, 2)
        Contact points and minimum-image branch vectors, m.
    position : array_like, (..., P, 2)
        Centres, m.

    Returns
    -------
    point_i, point_j : numpy.ndarray, (..., C, 2)
        The point relative to body i's and to body j's stored centre, m.
    """
    point, branch = np.asarray(point, float), np.asarray(branch, float)
    position = np.asarray(position, float)
    n_part = position.shape[-2]
    i, j = np.broadcast_to(i, point.shape[:-1]), np.broadcast_to(j, point.shape[:-1])
    pair = (i >= 0) & (i < n_part) & (j >= 0) & (j < n_part)
    xi = np.take_along_axis(position, np.clip(i, 0, n_part - 1)[..., None], axis=-2)
    xj = np.take_along_axis(position, np.clip(j, 0, n_part - 1)[..., None], axis=-2)
    lever_i, lever_j = point - xi, point - xj
    near_i = (lever_i * lever_i).sum(-1) <= (lever_j * lever_j).sum(-1)
    lever_i = np.where(near_i[..., None], lever_i, lever_j + branch)
    lever_j = np.where(near_i[..., None], lever_i - branch, lever_j)
    point_i = np.where(pair[..., None], xi + lever_i, point)
    point_j = np.where(pair[..., None], xj + lever_j, point)
    return np.ascontiguousarray(point_i), np.ascontiguousarray(point_j)


def chain_particles(sigma_1, sigma_2):
    """Boolean (..., P): sigma_1 above the mean of sigma_1 over the last axis, with a major
    direction (sigma_1 - sigma_2 > :data:`ISOTROPY_TOLERANCE` |sigma_1|)."""
    sigma_1 = np.asarray(sigma_1, float)
    anisotropic = (sigma_1 - np.asarray(sigma_2, float)) > ISOTROPY_TOLERANCE * np.abs(sigma_1)
    return (sigma_1 > sigma_1.mean(-1, keepdims=True)) & anisotropic


def chain_links(i, j, branch, mask, candidate, theta_1, angle):
    """Boolean (..., C): the slots of ``mask`` between two particles of ``candidate`` (..., P)
    whose branch vector lies within ``angle`` (degrees) of both particles' major directions
    ``theta_1`` (..., P, rad): |cos(phi_l - theta_1)| >= cos(angle), phi_l the branch's angle."""
    candidate = np.asarray(candidate, bool)
    lead = np.broadcast_shapes(np.shape(mask), np.shape(i), np.shape(j))
    theta_1 = np.broadcast_to(theta_1, candidate.shape)
    branch = np.broadcast_to(branch, lead + (2,))
    slots = Slots(_rows(np.broadcast_to(i, lead), 1).astype(np.int64),
                  _rows(np.broadcast_to(j, lead), 1).astype(np.int64),
                  _rows(np.broadcast_to(mask, lead), 1).astype(bool))
    branches = XY(_rows(branch[..., 0], 1).astype(np.float64), _rows(branch[..., 1], 1).astype(np.float64))
    directions = XY(_rows(np.cos(theta_1), 1), _rows(np.sin(theta_1), 1))
    links = aligned_links(slots, branches, _rows(candidate, 1), directions, float(np.cos(np.deg2rad(angle))))
    return links.reshape(lead)


def components(i, j, link, n_particles, min_size=3):
    """Chain id (..., P) of each particle: the connected sets of the ``link`` graph of at least
    ``min_size`` particles, numbered 0, 1, ... per snapshot in the order of their smallest
    particle index; -1 outside (:func:`grainview.analysis._kernels.force_chains.label_components`)."""
    link = np.asarray(link, bool)
    lead = link.shape[:-1]
    i = _rows(np.broadcast_to(i, link.shape), 1).astype(np.int64)
    j = _rows(np.broadcast_to(j, link.shape), 1).astype(np.int64)
    flat = _rows(link, 1)
    ends = np.concatenate([i[flat], j[flat]])
    if ends.size and (ends.min() < 0 or ends.max() >= n_particles):
        raise ValueError(f"a linked contact names a body outside the particles 0 .. {n_particles - 1}")
    return label_components(i, j, flat, int(n_particles), int(min_size)).reshape(lead + (n_particles,))


def chain_sizes(chain):
    """Number of particles (..., P) of chain k at index k (0 beyond the snapshot's chains)."""
    chain = np.asarray(chain)
    n_part = chain.shape[-1]
    rows = _rows(chain, 1)
    where = (np.arange(rows.shape[0])[:, None] * n_part + rows)[rows >= 0]
    return np.bincount(where, minlength=rows.size).reshape(chain.shape)


@core_dims(CONTACT, CONTACT, CONTACT, CONTACT, CONTACT_XY, CONTACT_XY, CONTACT_XY, CONTACT, PARTICLE_XY, PARTICLE,
           out=(PARTICLE, CONTACT, PARTICLE, PARTICLE, PARTICLE, SCALAR, LENGTH, SCALAR, SCALAR, SCALAR, SCALAR))
def force_chains(i, j, fn, ft, normal, point, branch, mask, position, volume, angle=45.0, min_size=3,
                 max_length=50, periodic=False):
    """Force chains of every snapshot and their statistics (module docstring, steps 1-5).

    ``i, j, fn, ft, mask`` (..., C), ``normal, point, branch`` (..., C, 2), ``position``
    (..., P, 2) m, ``volume`` (..., P) m^3; ``angle`` in degrees. Returns, per snapshot:

    * ``chain`` (..., P): chain id, -1 outside chains;
    * ``link`` (..., C): the contacts linking two particles of the same chain;
    * ``sigma_1``, ``sigma_2`` (..., P): principal stresses of each particle, Pa;
    * ``theta_1`` (..., P): its major direction in [0, pi), rad (NaN when isotropic);
    * ``n_chains`` (...);
    * ``length_count`` (..., L): chains of ``min_size``, ..., ``max_length`` particles, the last
      bin counting every chain of ``max_length`` particles or more;
    * ``orientation`` (...): mean orientation of the chains' links, the axial mean
      phi = (1/2) atan2(sum sin 2 phi_l, sum cos 2 phi_l) in [0, pi), rad (NaN without chains);
    * ``particle_fraction`` (...): particles in chains / P;
    * ``deviator_fraction`` (...): the chains' contribution to the deviatoric stress in units
      of the sample's, (D_chains : D)/(D : D), D = dev(sum_p V_p sigma_p) over all particles
      and D_chains the same sum over the chain particles (equal to q_chains/q when both
      deviators are aligned). Signed and not bounded by 1: the chains' and the other
      particles' contributions add up to 1, so it exceeds 1 where the other particles'
      deviator opposes the sample's (a weak network loaded across the chains) and is
      ill-conditioned where D is small (a nearly isotropic state); 0 without chains, NaN for
      an isotropic sample stress;
    * ``pressure_fraction`` (...): tr(sum_chains V_p sigma_p)/tr(sum_p V_p sigma_p).

    ``periodic``: the sample is a periodic cell, its branches minimum images; the particle
    stresses take their levers from one image of each pair (:func:`particle_moments`). The
    links and the connected sets read only the branches and the pairs (i, j), so a chain that
    crosses the cell's boundary is one chain.
    """
    moments = particle_moments(i, j, fn, ft, normal, point, mask, position,
                               branch=np.asarray(branch, float) if periodic else None)
    volume = np.asarray(volume, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        stress = moments / volume[..., None, None]
    sigma_1, sigma_2, theta_1 = principal(stress)
    candidate = chain_particles(sigma_1, sigma_2)
    theta_1 = np.where((sigma_1 - sigma_2) > ISOTROPY_TOLERANCE * np.abs(sigma_1), theta_1, np.nan)
    branch = np.asarray(branch, float)
    links = chain_links(i, j, branch, mask, candidate, np.nan_to_num(theta_1), angle)
    n_part = np.shape(position)[-2]
    chain = components(np.broadcast_to(i, links.shape), np.broadcast_to(j, links.shape), links, n_part, min_size)
    member = chain >= 0
    si = np.where(links, np.asarray(i), 0)
    link = links & (np.take_along_axis(chain, si, -1) >= 0)

    sizes = chain_sizes(chain)
    n_chains = (sizes > 0).sum(-1)
    n_bins = max_length - min_size + 1
    binned = np.clip(sizes, 0, max_length) - min_size
    rows = _rows(binned, 1)
    where = (np.arange(rows.shape[0])[:, None] * n_bins + rows)[rows >= 0]
    length_count = np.bincount(where, minlength=rows.shape[0] * n_bins).reshape(sizes.shape[:-1] + (n_bins,))

    phi = 2.0 * portable_math.arctan2(branch[..., 1], branch[..., 0])
    s = np.where(link, np.sin(phi), 0.0).sum(-1)
    c = np.where(link, np.cos(phi), 0.0).sum(-1)
    orientation = np.where(link.any(-1), np.mod(0.5 * portable_math.arctan2(s, c), np.pi), np.nan)

    symmetric = 0.5 * (moments + np.swapaxes(moments, -1, -2))
    total = symmetric.sum(-3)
    in_chains = np.where(member[..., None, None], symmetric, 0.0).sum(-3)
    eye = np.eye(2)
    dev_total = total - 0.5 * np.trace(total, axis1=-2, axis2=-1)[..., None, None] * eye
    dev_chains = in_chains - 0.5 * np.trace(in_chains, axis1=-2, axis2=-1)[..., None, None] * eye
    norm = (dev_total * dev_total).sum((-2, -1))
    share = (dev_chains * dev_total).sum((-2, -1))
    with np.errstate(invalid="ignore", divide="ignore"):
        deviator_fraction = np.where(member.any(-1), share / np.where(norm > 0, norm, np.nan), 0.0)
        pressure = np.trace(total, axis1=-2, axis2=-1)
        chains_trace = np.trace(in_chains, axis1=-2, axis2=-1)
        pressure_fraction = np.where(member.any(-1), chains_trace / np.where(pressure != 0, pressure, np.nan), 0.0)
    particle_fraction = member.mean(-1)
    return (chain, link, sigma_1, sigma_2, theta_1, n_chains, length_count, orientation, particle_fraction,
            deviator_fraction, pressure_fraction)


def follow_chains(chain):
    """Chains followed from snapshot to snapshot by their shared members.

    Chain a of snapshot t-1 continues as chain b of snapshot t when they share particles and
    each is the other's best match (b shares more of a's members than any other chain of t, and
    a more of b's than any other chain of t-1; ties go to the smaller id). Every other chain
    starts a new track (:func:`grainview.analysis._kernels.force_chains.follow_tracks`).

    Parameters
    ----------
    chain : array_like of int, (T, P)
        Chain ids (:func:`force_chains`), -1 outside chains.

    Returns
    -------
    track : numpy.ndarray of int64, (T, P)
        Track id of each particle's chain, -1 outside chains; tracks numbered in the order
        they start.
    first, last : numpy.ndarray of int64, (K,)
        First and last snapshot index of each of the K tracks.
    size : numpy.ndarray of float, (K,)
        Mean number of particles of each track over its snapshots.
    """
    chain = np.ascontiguousarray(chain, dtype=np.int64)
    if chain.ndim != 2:
        raise ValueError(f"chain: expected (time, particle) ids, got shape {chain.shape}")
    track, first, last, total = follow_tracks(chain)
    return track, first, last, total / np.maximum(last - first + 1, 1)


__all__ = ["particle_moments", "periodic_points", "chain_particles", "chain_links", "components", "chain_sizes", "force_chains",
           "follow_chains", "ISOTROPY_TOLERANCE"]
