"""Angular averages of the contact forces and the force tensors H^(n), H^(t)
(paper Eqs. fnft, HnHt, anat; docs/conventions.md §3)."""

from __future__ import annotations

import numpy as np

from .binning import batched_bincount
from .fabric import orientation_bins
from .signature import CONTACT, CONTACT_XY, TENSOR, core_dims


@core_dims(CONTACT, CONTACT, CONTACT_XY, CONTACT, out=(("theta",),) * 3)
def angular_averages(fn, ft, normal, mask, n_bins):
    """<f_n>(theta), <f_t>(theta) and N_c(theta) on ``n_bins`` sectors of [0, pi).

    Bin averages over the contacts whose normal falls in each sector (paper Eq. fnft);
    NaN in an empty sector. Returns three (..., n_bins) arrays (N, N, count).
    """
    index = orientation_bins(normal, n_bins)
    count = batched_bincount(index, mask, n_bins)
    sum_n = batched_bincount(index, mask, n_bins, weights=np.where(mask, fn, 0.0))
    sum_t = batched_bincount(index, mask, n_bins, weights=np.where(mask, ft, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        return sum_n / count, sum_t / count, count


def sector_integrals(n_bins):
    """Exact integrals over each sector [theta_k - dtheta/2, theta_k + dtheta/2] of n (x) n and sym(n (x) t).

    With n = (cos x, sin x) and t = (-sin x, cos x): n (x) n = [[cos^2, cs], [cs, sin^2]] and
    sym(n (x) t) = [[-sin 2x, cos 2x], [cos 2x, sin 2x]]/2, integrated with the closed-form
    antiderivatives below. Returns two arrays (n_bins, 2, 2), dimensionless (rad).
    """
    width = np.pi / n_bins
    edges = (np.arange(n_bins + 1) - 0.5) * width  # sectors centred on k pi/n_bins

    def nn(x):  # antiderivative of n (x) n
        s, c = np.sin(2 * x), np.cos(2 * x)
        return np.stack([np.stack([x / 2 + s / 4, -c / 4], -1), np.stack([-c / 4, x / 2 - s / 4], -1)], -2)

    def nt(x):  # antiderivative of sym(n (x) t) = [[-sin2x/2, cos2x/2], [cos2x/2, sin2x/2]]
        s, c = np.sin(2 * x), np.cos(2 * x)
        return np.stack([np.stack([c / 4, s / 4], -1), np.stack([s / 4, -c / 4], -1)], -2)

    return nn(edges[1:]) - nn(edges[:-1]), nt(edges[1:]) - nt(edges[:-1])


@core_dims(CONTACT, CONTACT, CONTACT_XY, CONTACT, out=(TENSOR, TENSOR))
def force_tensors(fn, ft, normal, mask, n_bins):
    """H^(n) and H^(t) (..., 2, 2) in N (docs/conventions.md §3, which corrects the printed H^(t)).

    H^(n)_ab = (1/pi) int_0^pi <f_n>(theta) n_a n_b dtheta and
    H^(t)_ab = sym[(1/pi) int_0^pi <f_t>(theta) n_a t_b dtheta], with the bin averages taken
    as constant on each sector and n (x) n, n (x) t integrated exactly over it; empty sectors
    contribute nothing. tr H^(n) is the angular mean of <f_n>(theta).
    """
    mean_n, mean_t, _ = angular_averages(fn, ft, normal, mask, n_bins)
    j_nn, j_nt = sector_integrals(n_bins)
    h_n = np.einsum("...k,kab->...ab", np.nan_to_num(mean_n), j_nn) / np.pi
    h_t = np.einsum("...k,kab->...ab", np.nan_to_num(mean_t), j_nt) / np.pi
    return h_n, h_t
