"""Strains of a biaxial test and the angles and numbers derived from them
(paper Sec. III, Eqs. for eps_1, eps_p, phi, psi and I; docs/conventions.md §6).

Compression is positive for eps_1 and eps_2, dilation positive for eps_p, as docs/conventions.md
§6 states. The reference state is the snapshot ``reference`` (default the first).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..contract import portable_math
from ..contract.cell import unwrap_tilt
from . import sample
from ._lift import ratio, with_attrs
from .arrays.strain import RESIDUAL_STRAIN, log_strain
from ..contract.errors import ParameterError
from .stress import stress_invariants
from ._docs import fill_doc

__all__ = ["time_derivative", "strains", "deformation_gradient", "residual_window", "shear_strain",
           "friction_and_dilatancy", "friction_offset", "inertia_number"]

def time_derivative(da: xr.DataArray) -> xr.DataArray:
    """d(da)/dt by centred differences (one-sided at both ends), lazily on any chunking.

        d(da)/dt (t_k) = (da_(k+1) - da_(k-1)) / (t_(k+1) - t_(k-1))

    with da_(k+1) replaced by da_k at the last snapshot and da_(k-1) by da_k at the first. Built
    from ``shift`` so dask handles the chunk overlaps (``differentiate`` cannot work on
    one-snapshot chunks). NaN when there is a single snapshot, and where two snapshots share a
    time.

    Parameters
    ----------
    da : xarray.DataArray
        A quantity over ``time`` (its ``time`` coordinate in s).

    Returns
    -------
    xarray.DataArray
        The derivative, in the units of ``da`` per second, over the same dims.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Eq. 3 (the strain rate of the inertia parameter); docs/analysis.md,
    "Conventions worth knowing".
    """
    if da.sizes["time"] < 2:  # one snapshot: no rate (dask cannot shift a single snapshot)
        return xr.full_like(da, np.nan, dtype=float)
    t = da["time"].astype(float)
    ahead, behind = da.shift(time=-1).fillna(da), da.shift(time=1).fillna(da)
    t_ahead, t_behind = t.shift(time=-1), t.shift(time=1)
    dt = t_ahead.fillna(t) - t_behind.fillna(t)
    return (ahead - behind) / dt.where(dt != 0)


def _log_strain(size, reference):
    return log_strain(size, size.isel(time=reference))


def _continuous_cell(ds: xr.Dataset) -> np.ndarray:
    """The lattice vectors (T, 2, 2) of a file's cell, its tilt made continuous across the
    flips of the code that wrote it (:func:`grainview.contract.cell.unwrap_tilt`): read at once
    (four numbers per snapshot)."""
    cell = np.array(ds["cell"].values, dtype=float)
    cell[:, 1, 0] = unwrap_tilt(cell[:, 1, 0], cell[:, 0, 0])
    return cell


@fill_doc
def deformation_gradient(ds: xr.Dataset, reference: int = 0) -> xr.DataArray:
    """The deformation gradient F (time, xy_a, xy_b) of the sample from the snapshot
    ``reference``, dimensionless.

    With a periodic cell (``cell``), F maps the reference cell's lattice vectors onto the
    current ones, ``a = F a_0`` and ``b = F b_0``:

        F = C^T (C_0^T)^-1,

    C the matrix whose rows are ``a`` and ``b`` (docs/schema.md, "The periodic cell"), the tilt
    made continuous first where the code flipped the cell
    (:func:`grainview.contract.cell.unwrap_tilt`). In the restricted form a = (l, 0),
    b = (tilt, h):

        F = [[l/l_0, (tilt - tilt_0 l/l_0)/h_0], [0, h/h_0]],

    so a simple shear of the cell at fixed l and h has F_xy = (tilt - tilt_0)/h, the shear
    strain gamma. Without a cell F is that of the box, diag(l/l_0, h/h_0).

    Parameters
    ----------
    {ds}
    reference : int, default 0
        Index of the reference snapshot along ``time``.

    Returns
    -------
    xarray.DataArray
        ``deformation_gradient`` (time, xy_a, xy_b), F[a, b] = d x_a / d X_b, dimensionless.
        With a cell, the cell is read (four numbers per snapshot) and the result is eager;
        otherwise lazy on dask input.
    """
    if "cell" not in ds.variables:
        l, h = sample.width(ds), sample.height(ds)
        sx, sy = l / l.isel(time=reference), h / h.isel(time=reference)
        zero = xr.zeros_like(sx)
        rows = [xr.concat([sx, zero], "xy_b"), xr.concat([zero, sy], "xy_b")]
        f = xr.concat(rows, "xy_a").transpose("time", "xy_a", "xy_b")
    else:
        cell = _continuous_cell(ds)
        c0 = cell[reference]
        # columns of A = C^T are the lattice vectors; F = A A0^-1, A0^-1 by its adjugate
        det0 = c0[0, 0] * c0[1, 1] - c0[1, 0] * c0[0, 1]
        inv = np.array([[c0[1, 1], -c0[1, 0]], [-c0[0, 1], c0[0, 0]]]) / det0  # A0^-1
        a = np.swapaxes(cell, -1, -2)  # (T, 2, 2): A[x, k] = vector k's component x
        f_values = a[..., :, 0, None] * inv[None, 0, :] + a[..., :, 1, None] * inv[None, 1, :]
        f = xr.DataArray(f_values, dims=("time", "xy_a", "xy_b"), coords={"time": ds["time"].values})
    f = f.assign_coords(xy_a=["x", "y"], xy_b=["x", "y"])
    return with_attrs(f, "deformation_gradient", "1", "deformation gradient F of the sample from the reference "
                      "snapshot")


@fill_doc
def strains(ds: xr.Dataset, reference: int = 0) -> xr.Dataset:
    """eps_1, eps_2, eps_p, eps_q (dimensionless) of every snapshot.

        eps_1 = ln(1 + dh/h0) with dh = h0 - h (vertical, compression positive);
        eps_2 = ln(1 + dl/l0) with dl = l0 - l (horizontal);
        eps_p = ln(1 + dV/V0) with dV = V - V0 (volumetric, dilation positive);
        eps_q = eps_1 - eps_2 (shear strain). docs/conventions.md §6.

    h, l are the box height and width (m) and V the box area l h (m2) of each snapshot; h0, l0,
    V0 those of the snapshot ``reference``.

    A file with a periodic cell (``cell``) has the same four from the cell's widths (the box is
    the cell's bounds, so V = l h whatever its tilt) and also ``gamma``, the simple-shear
    strain of the cell, the xy component of its deformation gradient
    (:func:`deformation_gradient`):

        gamma = (tilt - tilt_0 l/l_0) / h_0,

    which is (tilt - tilt_0)/h at fixed l and h; the tilt is made continuous first where the
    code flipped the cell (LAMMPS's flips, :func:`grainview.contract.cell.unwrap_tilt`). The
    widths do not see a simple shear: eps_q = eps_1 - eps_2 measures the biaxial part of the
    deformation only (0 in a simple shear at fixed l and h), and ``gamma`` is its shear strain.

    Parameters
    ----------
    {ds}
    reference : int, default 0
        Index of the reference snapshot (h0, l0, V0) along ``time``.

    Returns
    -------
    xarray.Dataset
        ``eps_1``, ``eps_2``, ``eps_p``, ``eps_q`` over ``time``, dimensionless; lazy on dask
        input; with a cell also ``gamma`` (the cell is read).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III; docs/conventions.md §6.
    """
    h, l, v = sample.height(ds), sample.width(ds), sample.area(ds)
    eps_1 = _log_strain(h, reference)
    eps_2 = _log_strain(l, reference)
    v0 = v.isel(time=reference)
    eps_p = portable_math.log(1 + (v - v0) / v0)
    out = xr.Dataset({
        "eps_1": with_attrs(eps_1, "eps_1", "1", "vertical strain eps_1 (compression positive)"),
        "eps_2": with_attrs(eps_2, "eps_2", "1", "horizontal strain eps_2 (compression positive)"),
        "eps_p": with_attrs(eps_p, "eps_p", "1", "volumetric strain eps_p (dilation positive)"),
        "eps_q": with_attrs(eps_1 - eps_2, "eps_q", "1", "shear strain eps_q = eps_1 - eps_2"),
    })
    if "cell" in ds.variables:
        gamma = deformation_gradient(ds, reference).sel(xy_a="x", xy_b="y", drop=True)
        out["gamma"] = with_attrs(gamma.assign_coords(time=ds["time"]), "gamma", "1",
                                  "simple-shear strain of the periodic cell, F_xy")
    return out.drop_vars([c for c in out.coords if c != "time"])


@fill_doc
def residual_window(ds: xr.Dataset, start: float = RESIDUAL_STRAIN) -> xr.DataArray:
    """Boolean (time,): the snapshots of the residual state, eps_q >= ``start`` (computed).

    A run that stops short of ``start`` has no residual snapshot (all False): its residual
    values are "not reached" rather than those of another state.

    A periodic cell that is sheared (its continuous tilt changes over the run) is in simple
    shear, where eps_q, which reads the widths only, stays near 0: its window is
    |gamma| >= ``start`` instead, gamma the cell's shear strain (:func:`strains`; a simple
    shear gamma has principal strains +-gamma/2, so gamma plays eps_q's part).

    Parameters
    ----------
    {ds}
    start : float, default 0.3
        Shear strain eps_q (dimensionless, >= 0) from which the state is residual
        (:data:`RESIDUAL_STRAIN`).

    Returns
    -------
    xarray.DataArray
        ``residual`` (time,), boolean, computed (eps_q is read).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``start`` is not a finite number >= 0.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Figs. 7, 8 and 10 (residual values read at eps_q >= 0.3); docs/conventions.md §6.
    """
    if isinstance(start, bool) or not isinstance(start, (int, float, np.integer, np.floating)) \
            or not np.isfinite(start) or start < 0:
        raise ParameterError(f"residual strain start={start!r}: expected a shear strain eps_q >= 0")
    strain = shear_strain(ds)
    window = strain >= start
    return window.rename("residual").assign_attrs(long_name=f"residual state, {strain.name} >= {start:g}", units="1")


@fill_doc
def shear_strain(ds: xr.Dataset) -> xr.DataArray:
    """The shear strain a test is read in (time,), computed: eps_q, or |gamma| in a periodic
    cell sheared over the run (:func:`residual_window`).

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        (time,), dimensionless, named ``eps_q`` or ``|gamma|``.
    """
    eps = strains(ds)
    if "gamma" in eps and _sheared(ds):
        return abs(eps["gamma"].compute()).rename("|gamma|")
    return eps["eps_q"].compute().rename("eps_q")


def _sheared(ds: xr.Dataset) -> bool:
    """Whether a file's periodic cell is sheared over the run: its continuous tilt changes."""
    tilt = _continuous_cell(ds)[:, 1, 0]
    return bool(tilt.size and np.ptp(tilt) > 0)


@fill_doc
def friction_and_dilatancy(ds: xr.Dataset, reference: int = 0) -> xr.Dataset:
    """Friction angle phi, cumulative and incremental dilatancy angles psi (rad).

        sin phi = q/p;
        sin psi = eps_p/eps_q (cumulative; NaN where eps_q = 0);
        sin psi_incremental = d eps_p / d eps_q (centred differences in time).

    Values of the sines outside [-1, 1] give NaN rather than a clipped angle. q/p is that of
    the whole sample, wall contacts included (:func:`grainview.analysis.stress.stress_invariants`).

    Parameters
    ----------
    {ds}
    reference : int, default 0
        Index of the reference snapshot (h0, l0, V0) along ``time``.

    Returns
    -------
    xarray.Dataset
        ``phi``, ``psi`` and ``psi_incremental`` over ``time``, in rad; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 5 (the stress–dilatancy diagram); docs/conventions.md §6.
    """
    eps = strains(ds, reference)
    q_over_p = stress_invariants(ds)["q_over_p"]
    sine_psi = ratio(eps["eps_p"], eps["eps_q"])
    rate = ratio(time_derivative(eps["eps_p"]), time_derivative(eps["eps_q"]))
    def asin(sine):  # NaN outside [-1, 1], without warnings when dask computes later
        return portable_math.arcsin(sine.where(abs(sine) <= 1))

    return xr.Dataset({
        "phi": with_attrs(asin(q_over_p), "phi", "rad", "friction angle, sin phi = q/p"),
        "psi": with_attrs(asin(sine_psi), "psi", "rad", "dilatancy angle, sin psi = eps_p/eps_q"),
        "psi_incremental": with_attrs(asin(rate), "psi_incremental", "rad",
                                      "incremental dilatancy angle, sin psi = d eps_p/d eps_q"),
    })


def inertia_number(ds: xr.Dataset) -> xr.DataArray:
    """Inertia parameter I = eps_dot sqrt(m/p) (paper Eq. 3), dimensionless.

        I = eps_dot sqrt(m / p),    eps_dot = |dh/dt| / h

    eps_dot is the vertical strain rate (s-1), m the total mass of the particles (kg) and p the
    mean stress times the slab thickness (N m-1), as in the paper's 2D setting. In a periodic
    cell sheared over the run, eps_dot is the shear rate |d gamma/dt| (gamma of
    :func:`strains`): there the height only follows the normal stress's control, and its rate
    says nothing of the shear.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract (docs/schema.md), eager or chunked along ``time``.
        The slab thickness is the global attribute ``thickness_m`` (m, default 1).

    Returns
    -------
    xarray.DataArray
        ``inertia_number`` (time,), dimensionless; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. 3 (Sec. III); docs/conventions.md §6.
    """
    if "cell" in ds.variables and _sheared(ds):
        rate = abs(time_derivative(strains(ds)["gamma"]))
    else:
        h = sample.height(ds)
        rate = ratio(abs(time_derivative(h)), h)
    p_line = stress_invariants(ds)["p"] * sample.thickness(ds)
    total_mass = ds["mass"].sum()
    per_load = ratio(total_mass, p_line.where(p_line > 0))  # no load (no contacts): NaN
    return with_attrs(rate * np.sqrt(per_load), "inertia_number", "1", "inertia parameter I")


EARLY_STRAIN = 0.02
"""Snapshots below this shear strain are left out of the stress–dilatancy relation: there
psi = arcsin(eps_p/eps_q) divides two strains that both start from zero, so it swings through
large values that say nothing about dilatancy."""


@fill_doc
def friction_offset(ds: xr.Dataset, min_strain: float = EARLY_STRAIN, incremental: bool = False) -> float:
    """phi_0 of the stress–dilatancy relation phi ~ phi_0 + psi, in rad: the median of phi - psi.

        phi_0 = median over the snapshots with eps_q >= min_strain of (phi - psi),

    sin phi = q/p, sin psi = eps_p/eps_q (or d eps_p/d eps_q with ``incremental``;
    :func:`friction_and_dilatancy`). It is the friction angle at zero dilatancy of Taylor's
    relation, which the paper's Fig. 5 shows both shapes follow. A median, not a fit: the
    slope is 1 by assumption. It reads the whole run (computed).

    Parameters
    ----------
    {ds_short}
    min_strain : float, default 0.02
        Snapshots with a smaller eps_q are left out (:data:`EARLY_STRAIN`).
    incremental : bool, default False
        Use the incremental dilatancy angle.

    Returns
    -------
    float
        phi_0, rad (NaN when no snapshot has both angles).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 5; docs/conventions.md §6.
    """
    angles = friction_and_dilatancy(ds).compute()
    early = np.asarray(strains(ds)["eps_q"].values, float) < min_strain
    phi = np.asarray(angles["phi"].values, float)
    psi = np.asarray(angles["psi_incremental" if incremental else "psi"].values, float)
    both = ~early & np.isfinite(phi) & np.isfinite(psi)
    return float(np.median(phi[both] - psi[both])) if both.any() else float("nan")
