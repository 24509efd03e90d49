"""Weak and strong force networks and the proportions of simple and double contacts
(paper Secs. V.C and VI, Figs. 17, 19 and 25; docs/conventions.md §4)."""

from __future__ import annotations

import numpy as np

from ...contract.schema import KIND_DOUBLE, KIND_SIMPLE
from .force_pdf import mean_normal_force
from .signature import CONTACT, SCALAR, core_dims

UNSELECTED, VERY_WEAK, WEAK, STRONG = 0, 1, 2, 3
"""Labels of :func:`force_classes`."""


@core_dims(CONTACT, CONTACT, out=(CONTACT,))
def force_classes(fn, mask, very_weak=0.1, strong=1.0):
    """Force class of each contact (..., C) as int8, with <f_n> the mean over ``mask``:

    0 not selected; 1 very weak f_n < very_weak <f_n>; 2 weak (intermediate)
    very_weak <f_n> <= f_n <= strong <f_n>; 3 strong f_n > strong <f_n> (paper Fig. 17).
    """
    mask = np.asarray(mask, bool)
    mean = mean_normal_force(fn, mask)[..., None]
    with np.errstate(invalid="ignore"):
        label = np.where(fn < very_weak * mean, VERY_WEAK, np.where(fn > strong * mean, STRONG, WEAK))
    return np.where(mask, label, UNSELECTED).astype(np.int8)


PROPORTIONS = (
    "n_contacts", "k_s", "k_d", "f_s", "f_d", "k_s_strong", "k_s_weak", "k_d_strong", "k_d_weak",
    "weak_fraction", "very_weak_fraction", "very_weak_simple", "very_weak_double",
    "mean_fn", "mean_fn_simple", "mean_fn_double",
)
"""Names of the outputs of :func:`proportions`, in order."""


@core_dims(CONTACT, CONTACT, CONTACT, out=(SCALAR,) * len(PROPORTIONS))
def proportions(fn, kind, mask, very_weak=0.1, strong=1.0):
    """Proportions of simple (s) and double (d), weak and strong contacts (docs/conventions.md §4).

    With N_c the contacts of ``mask`` (..., C), N_s and N_d those of kind simple and double,
    <f_n> the mean normal force over all of them and <f_n>_s, <f_n>_d over each kind:

    * k_s = N_s/N_c, k_d = N_d/N_c;
    * f_s = k_s <f_n>_s/<f_n> and f_d = k_d <f_n>_d/<f_n> (the paper's printed formulas swap s
      and d; docs/conventions.md §4), computed as sum_s f_n / sum f_n (the same by algebra, and 0 rather
      than NaN when a kind is absent), so f_s + f_d = 1;
    * k_s_strong, k_s_weak, k_d_strong, k_d_weak: fractions of all N_c contacts that are simple
      or double and strong (f_n > strong <f_n>) or weak (f_n <= strong <f_n>);
    * weak_fraction = k_s_weak + k_d_weak; very_weak_fraction: fraction of contacts with
      f_n < very_weak <f_n>, and very_weak_simple, very_weak_double its split by kind (each a
      fraction of all N_c contacts; paper: 32 %, 25 % and 7 % for pentagons);
    * mean_fn, mean_fn_simple, mean_fn_double in N.

    Returns a tuple in the order of :data:`PROPORTIONS`, each (...).
    """
    mask = np.asarray(mask, bool)
    label = force_classes(fn, mask, very_weak, strong)
    simple = mask & (kind == KIND_SIMPLE)
    double = mask & (kind == KIND_DOUBLE)
    strong_c = label == STRONG
    weak_c = mask & ~strong_c
    very_weak_c = label == VERY_WEAK
    force = np.where(mask, fn, 0.0)
    n_c = mask.sum(-1)

    def frac(m):
        with np.errstate(invalid="ignore", divide="ignore"):
            return m.sum(-1) / n_c

    with np.errstate(invalid="ignore", divide="ignore"):
        total = force.sum(-1)
        f_s = np.where(simple, force, 0.0).sum(-1) / total
        f_d = np.where(double, force, 0.0).sum(-1) / total
    return (
        n_c, frac(simple), frac(double), f_s, f_d,
        frac(simple & strong_c), frac(simple & weak_c), frac(double & strong_c), frac(double & weak_c),
        frac(weak_c), frac(very_weak_c), frac(simple & very_weak_c), frac(double & very_weak_c),
        mean_normal_force(fn, mask), mean_normal_force(fn, simple), mean_normal_force(fn, double),
    )
