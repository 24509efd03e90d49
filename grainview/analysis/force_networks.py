"""Very weak, weak and strong force networks, and the proportions of simple and double
contacts in them (paper Sec. V.C Fig. 17, Sec. VI Figs. 19 and 25; docs/conventions.md §4).

<f_n> is each snapshot's mean normal force over the selected contacts; contacts default to
particle–particle ones (``walls=False``).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import force_networks as _net
from .contacts import near_attr, selection
from ..contract.errors import ParameterError
from ._docs import fill_doc

__all__ = ["force_class", "contact_proportions"]


def _check_thresholds(very_weak, strong):
    for name, value in (("very_weak", very_weak), ("strong", strong)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                or not np.isfinite(value) or value < 0:
            raise ParameterError(f"{name}={value!r}: expected a finite number >= 0 (a multiple of <f_n>)")
    if very_weak > strong:
        raise ParameterError(f"very_weak={very_weak!r} > strong={strong!r}: expected very_weak <= strong")
    return float(very_weak), float(strong)


@fill_doc
def force_class(ds: xr.Dataset, very_weak: float = 0.1, strong: float = 1.0, walls: bool = False,
                near=None) -> xr.DataArray:
    """Force class of each contact slot (time, contact), int8 (paper Fig. 17's tricolor map).

        0 not selected (empty slot, or a wall contact with ``walls=False``);
        1 very weak, f_n < very_weak <f_n>;
        2 weak (intermediate), very_weak <f_n> <= f_n <= strong <f_n>;
        3 strong, f_n > strong <f_n>.

    <f_n> is the snapshot's mean normal force over the selected contacts. Defaults 0.1 and 1 as
    in the paper (Secs. V.B and V.C). ``near``: which pairs are contacts
    (:func:`grainview.analysis.contacts.in_network`; default the force-bearing ones; with a gap threshold
    the near pairs, f_n = 0, are very weak).

    Parameters
    ----------
    {ds}
    very_weak : float, default 0.1
        Very weak threshold, a multiple of <f_n> (finite, >= 0, <= ``strong``).
    strong : float, default 1.0
        Strong threshold, a multiple of <f_n> (finite, >= 0).
    {walls}
    {near}

    Returns
    -------
    xarray.DataArray
        ``force_class`` (time, contact), int8 codes 0-3 (``flag_values``, ``flag_meanings``
        attributes); lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When a threshold is not a finite number >= 0, or ``very_weak > strong``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Secs. V.B and V.C, Fig. 17; docs/conventions.md §4.
    """
    very_weak, strong = _check_thresholds(very_weak, strong)
    da = apply(_net.force_classes, ds["fn"], selection(ds, walls=walls, near=near),
               kwargs={"very_weak": very_weak, "strong": strong},
               output_dtypes=[np.int8])
    return with_attrs(da, "force_class", "1", "force class of the contact",
                      flag_values=np.array([0, 1, 2, 3], dtype="i1"),
                      flag_meanings="not_selected very_weak weak strong",
                      comment=f"very weak: f_n < {very_weak} <f_n>; weak: {very_weak} <f_n> <= f_n <= "
                              f"{strong} <f_n>; strong: f_n > {strong} <f_n>")


_ATTRS = {
    "n_contacts": ("1", "number of selected contacts N_c"),
    "k_s": ("1", "proportion of simple contacts k_s = N_s/N_c"),
    "k_d": ("1", "proportion of double contacts k_d = N_d/N_c"),
    "f_s": ("1", "relative force average of simple contacts f_s = k_s <f_n>_s/<f_n>"),
    "f_d": ("1", "relative force average of double contacts f_d = k_d <f_n>_d/<f_n>"),
    "k_s_strong": ("1", "fraction of contacts that are simple and strong k_s^S"),
    "k_s_weak": ("1", "fraction of contacts that are simple and weak k_s^W"),
    "k_d_strong": ("1", "fraction of contacts that are double and strong k_d^S"),
    "k_d_weak": ("1", "fraction of contacts that are double and weak k_d^W"),
    "weak_fraction": ("1", "fraction of weak contacts k_s^W + k_d^W"),
    "very_weak_fraction": ("1", "fraction of very weak contacts"),
    "very_weak_simple": ("1", "fraction of contacts that are simple and very weak"),
    "very_weak_double": ("1", "fraction of contacts that are double and very weak"),
    "mean_fn": ("N", "mean normal force <f_n>"),
    "mean_fn_simple": ("N", "mean normal force of simple contacts <f_n>_s"),
    "mean_fn_double": ("N", "mean normal force of double contacts <f_n>_d"),
}


@fill_doc
def contact_proportions(ds: xr.Dataset, walls: bool = False, very_weak: float = 0.1,
                        strong: float = 1.0, near=None) -> xr.Dataset:
    """Proportions of simple/double and weak/strong contacts per snapshot (time,) (docs/conventions.md §4).

    * k_s = N_s/N_c, k_d = N_d/N_c (paper Fig. 19), over the N_c selected contacts;
    * f_s = k_s <f_n>_s/<f_n>, f_d = k_d <f_n>_d/<f_n> (Fig. 19). The paper prints
      f_s = k_s <f_n>_d/<f_n> and f_d = k_d <f_n>_s/<f_n>, with s and d swapped in the means;
      that is a misprint (docs/conventions.md §4): only the corrected form gives f_s + f_d = 1 and
      f_d = f_s = 0.5 in an isotropic state with equal means;
    * k_s_strong, k_s_weak, k_d_strong, k_d_weak (k_s^S, k_s^W, k_d^S, k_d^W, Fig. 25): fractions
      of all contacts that are simple/double and strong (f_n > strong <f_n>) or weak
      (f_n <= strong <f_n>); weak_fraction = k_s^W + k_d^W (the paper finds about 0.58 for
      pentagons, 0.62 for disks);
    * very_weak_fraction (f_n < very_weak <f_n>) and its simple and double parts, fractions of
      all contacts (the paper finds about 0.32 = 0.25 simple + 0.07 double for pentagons);
    * n_contacts, and the means mean_fn, mean_fn_simple, mean_fn_double in N.

    ``near``: which pairs are contacts (:func:`grainview.analysis.contacts.in_network`): None (default)
    the force-bearing ones; with a gap threshold in m the near pairs count too, with f_n = 0
    (they are very weak). Lazy on dask input.

    Parameters
    ----------
    {ds}
    {walls}
    very_weak : float, default 0.1
        Very weak threshold, a multiple of <f_n> (finite, >= 0, <= ``strong``).
    strong : float, default 1.0
        Strong threshold, a multiple of <f_n> (finite, >= 0).
    {near}

    Returns
    -------
    xarray.Dataset
        The variables above over ``time``: ``n_contacts``, the proportions and fractions
        (dimensionless) and ``mean_fn``, ``mean_fn_simple``, ``mean_fn_double`` (N); the
        attributes ``walls``, ``very_weak``, ``strong`` and ``near`` record the selection.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When a threshold is not a finite number >= 0, or ``very_weak > strong``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Secs. V.C and VI, Figs. 19 and 25 (f_s, f_d with the correction of docs/conventions.md §4).
    """
    very_weak, strong = _check_thresholds(very_weak, strong)
    names = _net.PROPORTIONS
    outputs = apply(_net.proportions, ds["fn"], ds["kind"], selection(ds, walls=walls, near=near),
                    kwargs={"very_weak": very_weak, "strong": strong},
                    output_dtypes=[np.int64] + [float] * (len(names) - 1))
    out = xr.Dataset({name: with_attrs(da, name, *_ATTRS[name]) for name, da in zip(names, outputs)})
    out.attrs.update(walls=int(walls), very_weak=very_weak, strong=strong, near=near_attr(near))
    return out
