"""The xi-network: the contacts with f_n < xi <f_n> (paper Sec. V.C, Figs. 15 and 16;
docs/conventions.md §5).

For K values of xi the subsets are nested, so one sort of each snapshot's forces and cumulative
sums of the contacts' stress terms f_a l_b and fabric terms n_a n_b give every subset's sums
at once: the subset of xi is a prefix of the sorted contacts, whose length a binary search
finds. Cost O(C log C + K log C) per snapshot instead of K passes over the contacts.
"""

from __future__ import annotations

import numpy as np

from .._kernels.xi_network import count_below
from .vectors import force_vectors
from .force_pdf import mean_normal_force
from .tensors import principal, signed_anisotropy
from .signature import CONTACT, CONTACT_XY, SCALAR, core_dims


def prefix_lengths(sorted_forces, thresholds):
    """Number of entries of each row of ``sorted_forces`` (..., C), ascending, strictly below
    each threshold of ``thresholds`` (..., K): a batched ``np.searchsorted(side="left")``."""
    lead = sorted_forces.shape[:-1]
    rows = np.ascontiguousarray(np.asarray(sorted_forces, np.float64).reshape(-1, sorted_forces.shape[-1]))
    thr = np.ascontiguousarray(np.broadcast_to(thresholds, lead + thresholds.shape[-1:]).reshape(rows.shape[0], -1),
                               dtype=np.float64)
    return count_below(rows, thr).reshape(lead + thr.shape[-1:])


def subset_sums(fn, ft, normal, branch, mask, xi):
    """Sums over the subsets f_n < xi <f_n> of the selected contacts, for every xi at once.

    ``fn, ft, mask`` (..., C), ``normal, branch`` (..., C, 2), ``xi`` (K,); <f_n> is the mean
    of ``fn`` over ``mask``. Returns ``(count (..., K), stress_sum (..., K, 2, 2),
    fabric_sum (..., K, 2, 2))`` with stress_sum_ab = sum f_a l_b (N m) and
    fabric_sum_ab = sum n_a n_b over each subset.
    """
    mask = np.asarray(mask, bool)
    key = np.where(mask, fn, np.inf)  # unselected slots sort last and are never below
    order = np.argsort(key, axis=-1, kind="stable")
    sorted_forces = np.take_along_axis(key, order, axis=-1)

    force = np.where(mask[..., None], force_vectors(fn, ft, normal), 0.0)
    arm = np.where(mask[..., None], branch, 0.0)
    n = np.where(mask[..., None], normal, 0.0)
    terms = np.stack([force[..., 0] * arm[..., 0], force[..., 0] * arm[..., 1],
                      force[..., 1] * arm[..., 0], force[..., 1] * arm[..., 1],
                      n[..., 0] * n[..., 0], n[..., 0] * n[..., 1], n[..., 1] * n[..., 1]], axis=-1)
    terms = np.take_along_axis(terms, order[..., None], axis=-2)
    cumulative = np.cumsum(terms, axis=-2)
    zeros = np.zeros(cumulative.shape[:-2] + (1, cumulative.shape[-1]))
    cumulative = np.concatenate([zeros, cumulative], axis=-2)  # row m: sum of the m smallest

    xi = np.asarray(xi, float)
    thresholds = xi * mean_normal_force(fn, mask)[..., None]
    count = prefix_lengths(sorted_forces, thresholds)
    sums = np.take_along_axis(cumulative, count[..., None], axis=-2)  # (..., K, 7)
    stress_sum = sums[..., 0:4].reshape(sums.shape[:-1] + (2, 2))
    fabric_sum = np.stack([sums[..., 4], sums[..., 5], sums[..., 5], sums[..., 6]], axis=-1)
    return count, stress_sum, fabric_sum.reshape(sums.shape[:-1] + (2, 2))


@core_dims(CONTACT, CONTACT, CONTACT_XY, CONTACT_XY, CONTACT, SCALAR, SCALAR, SCALAR, out=(("xi",),) * 4)
def xi_network(fn, ft, normal, branch, mask, volume, p, theta_sigma, xi):
    """q(xi)/p, a'(xi), N(xi)/N_c and N(xi) of the xi-networks (docs/conventions.md §5).

    For each xi, the subset holds the contacts of ``mask`` with f_n < xi <f_n> (strict):

    * sigma(xi) = (1/V) sum_subset f (x) l (Pa); q(xi) = (s1 - s2)/2 of its symmetric part;
      ``q_over_p = q(xi)/p`` with ``p`` (...) the mean stress of the whole sample (Pa);
    * F(xi) = (1/N(xi)) sum_subset n (x) n (normalised by the subset's own count, tr F = 1);
      ``a_prime = 2 (F_1 - F_2) cos 2(theta_F - theta_sigma)`` with ``theta_sigma`` (...) the
      whole sample's major principal stress direction (rad); NaN for an empty subset;
    * ``fraction = N(xi)/N_c``.

    ``volume`` (...) in m^3. Returns ``(q_over_p, a_prime, fraction, count)``, each (..., K).
    """
    count, stress_sum, fabric_sum = subset_sums(fn, ft, normal, branch, mask, xi)
    volume = np.asarray(volume, float)[..., None, None, None]
    s1, s2, _ = principal(stress_sum / volume)
    with np.errstate(invalid="ignore", divide="ignore"):
        q_over_p = 0.5 * (s1 - s2) / np.asarray(p, float)[..., None]
        fabric = fabric_sum / count[..., None, None]
        f1, f2, theta_f = principal(fabric)
        a_prime = signed_anisotropy(f1, f2, theta_f, np.asarray(theta_sigma, float)[..., None], normalisation=1.0)
        fraction = count / np.asarray(mask, bool).sum(-1)[..., None]
    return q_over_p, a_prime, fraction, count
