"""Coarse-grained continuum fields on a grid: density, solid fraction, momentum and velocity,
kinetic and contact stress, fabric (Goldhirsch, Granular Matter 12, 239 (2010); Weinhart,
Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012)); their stress invariants and
profiles across the sample (docs/analysis.md, "Coarse-grained fields").
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from . import sample
from ._lift import apply, with_attrs
from .arrays import coarse_graining as _cg
from .arrays.tensors import principal
from .contacts import selection
from ._docs import fill_doc
from ..contract.errors import ParameterError
from ..contract.shapes import particle_area

__all__ = ["coarse_grained", "field_invariants", "scalar_field", "interior", "profile", "mean_diameter", "KERNELS",
           "QUANTITIES"]

KERNELS = ("gaussian",)
"""The coarse-graining kernels: the Gaussian cut at ``cutoff`` widths and renormalised."""

_FIELDS = {
    "density": ("kg m-3", "coarse-grained density rho = (1/t) sum_i m_i phi(r - r_i)"),
    "solid_fraction": ("1", "coarse-grained solid fraction nu = sum_i A_i phi(r - r_i)"),
    "momentum": ("kg m-2 s-1", "coarse-grained momentum density j = (1/t) sum_i m_i v_i phi(r - r_i)"),
    "velocity": ("m s-1", "coarse-grained velocity V = j / rho"),
    "kinetic_stress": ("Pa", "kinetic stress (1/t) sum_i m_i v'_i (x) v'_i phi(r - r_i), v' = v - V"),
    "contact_stress": ("Pa", "contact stress (1/t) sum_c f (x) l psi_c(r), psi_c the kernel along the branch"),
    "fabric": ("1", "coarse-grained fabric sum_c n (x) n psi_c / sum_c psi_c"),
}


def _positive(value, name, unit):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not np.isfinite(value) or value <= 0:
        raise ParameterError(f"{name}={value!r}: expected a number > 0{unit}")
    return float(value)


def _spacing(spacing):
    values = spacing if isinstance(spacing, (list, tuple, np.ndarray)) else (spacing, spacing)
    if len(values) != 2:
        raise ParameterError(f"spacing={spacing!r}: expected a grid spacing > 0 in m, or a pair (dx, dy)")
    return tuple(_positive(v, "spacing", " in m (or a pair (dx, dy) of them)") for v in values)


def _grid(ds, spacing, x, y, reach):
    """The grid's x and y coordinates (m): given, or cells of ``spacing`` covering every snapshot's
    box widened by ``reach`` (m) on every side."""
    if x is not None and y is not None:
        if spacing is not None:
            raise ParameterError("give either spacing= or the grid's x= and y=, not both")
        return _cg.check_grid(x, "x"), _cg.check_grid(y, "y")
    if (x is None) != (y is None):
        raise ParameterError("the grid: expected spacing= (m), or both x= and y= (coordinates in m)")
    dx, dy = _spacing(spacing)
    box = xr.Dataset({"lo": ds["box_min"].min("time"), "hi": ds["box_max"].max("time")}).compute()  # one read
    widen = reach * (1 - _periodic(ds))  # a periodic direction's fields repeat: the cell's bounds hold them all
    lo, hi = np.asarray(box["lo"].values, dtype=float) - widen, np.asarray(box["hi"].values, dtype=float) + widen
    return _cg.grid_nodes(lo[0], hi[0], dx), _cg.grid_nodes(lo[1], hi[1], dy)


def _periodic(ds: xr.Dataset) -> np.ndarray:
    """(2,) of 0/1: along x and y, whether the file's cell repeats (its ``periodic`` flags; 0, 0
    without a cell). In the restricted form a lies along x, and b's images are h apart in y."""
    if "cell" not in ds.variables:
        return np.zeros(2, dtype=int)
    return np.asarray(ds["periodic"].values, dtype=int)


def _cell_arguments(ds: xr.Dataset):
    """The cell (time, cell_vector, xy), its rate of change (m s-1; the tilt made continuous
    across a code's flips first) and its origin ``box_min``, for the periodic fields."""
    from .strain import _continuous_cell, time_derivative

    continuous = xr.DataArray(_continuous_cell(ds), dims=ds["cell"].dims, coords={"time": ds["time"].values})
    # one snapshot (or two at one time) has no rate: its images move as the particle does
    rate = time_derivative(continuous).fillna(0.0) if "velocity" in ds.variables else xr.zeros_like(continuous)
    rate = rate.assign_coords(time=ds["time"])
    if ds["cell"].chunks is not None:
        rate = rate.chunk(dict(zip(ds["cell"].dims, ds["cell"].chunks)))
    return ds["cell"], rate, ds["box_min"]


def _areas(ds: xr.Dataset) -> xr.DataArray:
    """Each particle's area A_i (particle,), m2, from its shape (:func:`grainview.contract.shapes.particle_area`)."""
    args, core = [ds["radius"], ds["n_vertices"]], [[], []]
    if "vertices" in ds.variables:
        args.append(ds["vertices"])
        core.append(list(ds["vertices"].dims[1:]))
    return xr.apply_ufunc(particle_area, *args, input_core_dims=core, dask="parallelized", output_dtypes=[float])


@fill_doc
def mean_diameter(ds: xr.Dataset) -> float:
    """The particles' mean diameter 2 <R> (m), R the circumscribed radius: the default kernel width.

    Parameters
    ----------
    {ds_short}

    Returns
    -------
    float
        2 <R>, m.
    """
    return 2.0 * float(ds["radius"].mean())


@fill_doc
def coarse_grained(ds: xr.Dataset, width=None, spacing=None, kernel: str = "gaussian", cutoff: float = 3.0,
                   x=None, y=None) -> xr.Dataset:
    """Coarse-grained fields of every snapshot on a regular grid (time, y, x).

    Each particle is spread with a Gaussian kernel of standard deviation w = ``width``, cut at
    c = ``cutoff`` w and renormalised to integral 1,
    phi(r) = exp(-|r|^2/(2 w^2)) / (2 pi w^2 (1 - exp(-c^2/(2 w^2)))) (m^-2); each contact
    along its branch vector l (from the centre of i to the centre of j; to the contact point for
    a wall contact) with the kernel integrated exactly along it, psi_c(r) = int_0^1
    phi(r - r_i - u l) du. With t the slab thickness (attribute ``thickness_m``):

        rho     = (1/t) sum_i m_i phi            nu = sum_i A_i phi
        j       = (1/t) sum_i m_i v_i phi        V  = j / rho
        sigma^k = (1/t) sum_i m_i (v_i - V) (x) (v_i - V) phi
        sigma^c = (1/t) sum_c f (x) l psi_c      F  = sum_c n (x) n psi_c / sum_c psi_c

    f = f_n n + f_t t the force of i on j, so that both stresses are positive in compression
    (docs/conventions.md §1). The contact stress integrates exactly:
    (1/A) int sigma^c dA = (1/V) sum_c f (x) l, the Love–Weber stress of
    :func:`grainview.analysis.stress.stress_tensor` (V = A t), and int rho dA t = sum_i m_i, where the grid
    covers every kernel (the default grid does); on the grid these integrals are sums times the
    cell area, exact up to the quadrature of the kernel by the grid (docs/analysis.md).
    The contact stress sums every contact the file holds, wall contacts included, as
    :func:`grainview.analysis.stress.stress_tensor`; the fabric the force-bearing particle–particle
    contacts, as :func:`grainview.analysis.fabric.fabric_tensor`. Masses are the file's, areas those of
    the particles' shapes (:func:`grainview.contract.shapes.particle_area`).

    In a periodic cell (``cell``) the fields are those of the infinite periodic packing: every
    particle and every contact's segment (its minimum-image branch from the centre of i) is
    spread with all its images ``+ m a + n b`` that reach the grid, so a particle near one
    edge counts near the opposite one and a contact across the boundary is spread on both
    sides; an image's velocity adds ``m da/dt + n db/dt`` (Lees–Edwards; the rates from the
    cell's series, the tilt made continuous across flips, zero for a single snapshot). The
    default grid then covers the cell's bounds box_min..box_max along each periodic direction,
    not widened: that rectangle l x h tiles the plane under the lattice, a tilted cell's
    included (its rows of images are shifted by the tilt, not stacked), so the fields on it
    are one whole cell, and when ``spacing`` divides l and h their sums times the cell area
    of the grid are the integrals over the cell (sum_c f (x) l / t for the contact stress,
    the particles' mass and area). Given ``x`` and ``y`` may lie anywhere: the fields are
    periodic over the plane. :func:`interior` counts every node as inside along a periodic
    direction; the derivatives of ``scalar_field("shear_rate")`` are one-sided at the grid's
    edges, as for a bounded sample.

    Parameters
    ----------
    {ds}
    width : float, optional
        Kernel width w (standard deviation of the Gaussian), m; about a particle diameter
        resolves the packing's structure, a few diameters its continuum fields. Default: the
        mean particle diameter (:func:`mean_diameter`).
    spacing : float or (float, float), optional
        Grid spacing (dx, dy) in m: cells of that side covering the union of the snapshots' boxes
        widened by the kernel's radius c on every side (so that the grid holds every kernel whole
        and its integrals are exact; along a periodic direction of a cell not widened), nodes at
        their centres (reads ``box_min`` and ``box_max``). Default w/2. Or give ``x`` and ``y``.
    kernel : {"gaussian"}, default "gaussian"
        The kernel (:data:`KERNELS`).
    cutoff : float, default 3
        Kernel radius c in widths; the kernel is zero beyond it.
    x, y : array_like, optional
        The grid's coordinates in m (strictly increasing), instead of ``spacing``; nothing is
        read to build the grid then.

    Returns
    -------
    xarray.Dataset
        Over (time, y, x), with coordinates ``x``, ``y`` in m: ``density`` (kg m-3),
        ``solid_fraction`` (1), ``contact_stress`` (xy_a, xy_b; Pa), ``fabric`` (xy_a, xy_b; 1,
        NaN where no contact reaches), and, when the file has particle velocities, ``momentum``
        (xy; kg m-2 s-1), ``velocity`` (xy; m s-1, NaN where rho = 0) and ``kinetic_stress``
        (xy_a, xy_b; Pa). The snapshots' boxes as coordinates ``box_min``, ``box_max`` (time,
        xy; m). Attributes: the kernel, its width and cutoff, the grid spacing, and for a
        periodic cell ``periodic`` (along x, y). Lazy on dask input (a cell's four numbers per
        snapshot are read).

    Raises
    ------
    grainview.contract.errors.ParameterError
        For a width, spacing or cutoff that is not a number > 0, an unknown kernel, or a grid
        given both ways or neither.

    References
    ----------
    Goldhirsch, Granular Matter 12, 239 (2010); Weinhart, Thornton, Luding & Bokhove,
    Granular Matter 14, 289 (2012); docs/analysis.md, "Coarse-grained fields".
    """
    width = mean_diameter(ds) if width is None else _positive(width, "width", " (kernel width in m)")
    if spacing is None and x is None and y is None:
        spacing = width / 2
    cutoff = _positive(cutoff, "cutoff", " (kernel radius in widths)")
    if not isinstance(kernel, str) or kernel not in KERNELS:
        raise ParameterError(f"kernel={kernel!r}: expected one of {', '.join(map(repr, KERNELS))}")
    gx, gy = _grid(ds, spacing, x, y, _cg.kernel_radius(width, cutoff))
    has_velocity = "velocity" in ds.variables
    velocity = ds["velocity"] if has_velocity else xr.zeros_like(ds["position"])
    area = _areas(ds)
    args = [ds["position"], velocity, ds["mass"], area, ds["i"], ds["fn"], ds["ft"], ds["normal"], ds["branch"],
            selection(ds, walls=True, near=np.inf), selection(ds, walls=False), sample.thickness(ds)]
    kwargs = {"x": gx, "y": gy, "width": width, "cutoff": cutoff}
    core_dims = _cg.coarse_grained_fields.core_dims
    if "cell" in ds.variables:
        args += list(_cell_arguments(ds))
        core_dims = core_dims + (_cg.CELL, _cg.CELL, _cg.XY)
        kwargs["periodic"] = np.asarray(ds["periodic"].values, bool)
    outputs = apply(_cg.coarse_grained_fields, *args, core_dims=core_dims,
                    output_sizes={"y": gy.size, "x": gx.size}, kwargs=kwargs)
    fields = {}
    for name, da in zip(_FIELDS, outputs):
        if name in ("momentum", "velocity", "kinetic_stress") and not has_velocity:
            continue
        units, long_name = _FIELDS[name]
        fields[name] = with_attrs(da, name, units, long_name)
    out = xr.Dataset(fields).assign_coords(
        x=("x", gx, {"units": "m", "long_name": "grid node x"}),
        y=("y", gy, {"units": "m", "long_name": "grid node y"}))
    out = out.assign_coords(xy=ds["xy"], box_min=ds["box_min"], box_max=ds["box_max"])
    out.attrs = {"kernel": kernel, "width_m": width, "cutoff_widths": cutoff,
                 "spacing_m": [float(np.diff(gx).mean()) if gx.size > 1 else np.nan,
                               float(np.diff(gy).mean()) if gy.size > 1 else np.nan],
                 "thickness_m": sample.thickness(ds)}
    if "cell" in ds.variables:
        out.attrs["periodic"] = [int(v) for v in _periodic(ds)]
    return out


def _stress_of(fields: xr.Dataset, stress: str) -> xr.DataArray:
    """The stress tensor field named by ``stress`` (see :func:`field_invariants`), Pa."""
    if stress not in ("total", "contact", "kinetic"):
        raise ParameterError(f"stress={stress!r}: expected 'total', 'contact' or 'kinetic'")
    if stress == "kinetic" and "kinetic_stress" not in fields:
        raise ParameterError("stress='kinetic': these fields have no kinetic stress (the file has no velocities)")
    if stress == "contact" or (stress == "total" and "kinetic_stress" not in fields):
        return fields["contact_stress"]
    if stress == "kinetic":
        return fields["kinetic_stress"]
    return fields["contact_stress"] + fields["kinetic_stress"]


def field_invariants(fields: xr.Dataset, stress: str = "total") -> xr.Dataset:
    """p, q, q/p and the major direction of a coarse-grained stress field, node by node.

        p = (s1 + s2)/2,    q = (s1 - s2)/2

    with s1 >= s2 the principal values of the symmetric part of the stress (Pa), as
    :func:`grainview.analysis.stress.stress_invariants` for the whole sample.

    Parameters
    ----------
    fields : xarray.Dataset
        The result of :func:`coarse_grained`.
    stress : {"total", "contact", "kinetic"}, default "total"
        Which stress: contact + kinetic (the contact stress alone when the fields have no
        kinetic stress), or one of the two.

    Returns
    -------
    xarray.Dataset
        ``p``, ``q`` (Pa), ``q_over_p`` (1; NaN where p <= 0) and ``theta_sigma`` (rad, in
        [0, pi)) over (time, y, x); lazy when ``fields`` is.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For another ``stress``, or "kinetic" of fields without velocities.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007), Sec. III;
    docs/conventions.md §1.
    """
    sigma = _stress_of(fields, stress)
    s1, s2, theta = apply(principal, sigma)
    p = (s1 + s2) / 2
    q = (s1 - s2) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = q / p.where(p > 0)
    return xr.Dataset({
        "p": with_attrs(p, "p", "Pa", f"mean stress p = (s1 + s2)/2 of the {stress} stress"),
        "q": with_attrs(q, "q", "Pa", f"stress deviator q = (s1 - s2)/2 of the {stress} stress"),
        "q_over_p": with_attrs(ratio, "q_over_p", "1", "normalised shear stress q/p"),
        "theta_sigma": with_attrs(theta, "theta_sigma", "rad", "major principal stress direction"),
    }, attrs={"stress": stress})


QUANTITIES = {
    "sigma_xx": ("Pa", "sigma_xx", "normal stress sigma_xx"),
    "sigma_yy": ("Pa", "sigma_yy", "normal stress sigma_yy"),
    "sigma_xy": ("Pa", "sigma_xy", "shear stress (sigma_xy + sigma_yx)/2"),
    "p": ("Pa", "p", "mean stress p = (s1 + s2)/2"),
    "q": ("Pa", "q", "stress deviator q = (s1 - s2)/2"),
    "q_over_p": ("1", "q/p", "normalised shear stress q/p"),
    "solid_fraction": ("1", "nu", "solid fraction"),
    "density": ("kg m-3", "rho", "density"),
    "speed": ("m s-1", "|V|", "speed of the coarse-grained velocity |V|"),
    "fabric_anisotropy": ("1", "a", "fabric anisotropy a = 2 (F_1 - F_2)"),
    "shear_rate": ("s-1", "gamma_dot", "shear rate sqrt((dVx/dx - dVy/dy)^2 + (dVx/dy + dVy/dx)^2)"),
}
"""The scalar fields :func:`scalar_field` derives: name -> (units, symbol, long name)."""


def scalar_field(fields: xr.Dataset, name: str, stress: str = "total") -> xr.DataArray:
    """One scalar field (time, y, x) of the coarse-grained fields, by name (:data:`QUANTITIES`).

        sigma_xx, sigma_yy, sigma_xy = (sigma_xy + sigma_yx)/2,  p, q, q/p (:func:`field_invariants`),
        solid_fraction nu,  density rho,  speed |V|,  fabric anisotropy a = 2 (F_1 - F_2),
        shear rate gamma_dot = sqrt((dV_x/dx - dV_y/dy)^2 + (dV_x/dy + dV_y/dx)^2)

    gamma_dot (s-1) is twice the largest shear rate of the symmetric velocity gradient, by
    central differences on the grid (:meth:`xarray.DataArray.differentiate`): shear bands show
    as its ridges.

    the stresses of ``stress`` (contact + kinetic by default), in Pa.

    Parameters
    ----------
    fields : xarray.Dataset
        The result of :func:`coarse_grained`.
    name : str
        One of :data:`QUANTITIES`.
    stress : {"total", "contact", "kinetic"}, default "total"
        Which stress the stress quantities are of (:func:`field_invariants`).

    Returns
    -------
    xarray.DataArray
        The field, named ``name``, with its ``units`` and ``long_name``; lazy when ``fields`` is.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For an unknown ``name``, or ``speed`` or ``shear_rate`` of fields without velocities.

    References
    ----------
    Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012); docs/conventions.md §1-2.
    """
    if name not in QUANTITIES:
        raise ParameterError(f"name={name!r}: expected one of {', '.join(QUANTITIES)}")
    units, _, long_name = QUANTITIES[name]
    if name in ("p", "q", "q_over_p"):
        da = field_invariants(fields, stress)[name]
    elif name.startswith("sigma_"):
        sigma = _stress_of(fields, stress)
        a, b = {"sigma_xx": ("x", "x"), "sigma_yy": ("y", "y"), "sigma_xy": ("x", "y")}[name]
        da = 0.5 * (sigma.sel(xy_a=a, xy_b=b, drop=True) + sigma.sel(xy_a=b, xy_b=a, drop=True))
        long_name = f"{long_name} of the {stress} stress"
    elif name in ("speed", "shear_rate"):
        if "velocity" not in fields:
            raise ParameterError(f"name={name!r}: these fields have no velocity (the file has no velocities)")
        vx, vy = fields["velocity"].sel(xy="x", drop=True), fields["velocity"].sel(xy="y", drop=True)
        if name == "speed":
            da = np.hypot(vx, vy)
        else:
            da = np.hypot(vx.differentiate("x") - vy.differentiate("y"), vx.differentiate("y") + vy.differentiate("x"))
    elif name == "fabric_anisotropy":
        f1, f2, _ = apply(principal, fields["fabric"])
        da = 2 * (f1 - f2)
    else:
        da = fields[name]
    return with_attrs(da, name, units, long_name)


def interior(fields: xr.Dataset, margin: float | None = None) -> xr.DataArray:
    """Boolean (time, y, x): the grid nodes at least ``margin`` inside each snapshot's box.

        box_min + margin <= (x, y) <= box_max - margin

    along each direction that has walls; along a periodic direction of a cell (the fields'
    attribute ``periodic``) every node is inside.

    Within a few kernel widths of the walls the fields fall off (the kernel reaches past the
    packing: 2.3% of it at two widths), so profiles and averages of the bulk leave that layer out.

    Parameters
    ----------
    fields : xarray.Dataset
        The result of :func:`coarse_grained` (its ``box_min``, ``box_max`` coordinates).
    margin : float, optional
        Distance from the box's edges, m; default two kernel widths.

    Returns
    -------
    xarray.DataArray
        Boolean (time, y, x); lazy when ``fields`` is.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``margin`` is not a number >= 0.
    """
    margin = 2 * fields.attrs["width_m"] if margin is None else margin
    if isinstance(margin, bool) or not isinstance(margin, (int, float, np.integer, np.floating)) \
            or not np.isfinite(margin) or margin < 0:
        raise ParameterError(f"margin={margin!r}: expected a distance >= 0 in m")
    lo, hi = fields["box_min"] + margin, fields["box_max"] - margin
    periodic = fields.attrs.get("periodic", (0, 0))
    inside_x = (fields["x"] >= lo.sel(xy="x", drop=True)) & (fields["x"] <= hi.sel(xy="x", drop=True))
    inside_y = (fields["y"] >= lo.sel(xy="y", drop=True)) & (fields["y"] <= hi.sel(xy="y", drop=True))
    if periodic[0]:  # no wall along a periodic direction: every node is in the bulk
        inside_x = xr.ones_like(inside_x, dtype=bool)
    if periodic[1]:
        inside_y = xr.ones_like(inside_y, dtype=bool)
    inside = inside_x & inside_y
    return inside.transpose(..., "y", "x").rename("interior")


def profile(field: xr.DataArray, across: str = "x", inside=None) -> xr.DataArray:
    """A field averaged along the grid's other axis: its profile across the sample along ``across``.

        <g>(x) = (1/n_y) sum_y g(x, y)    (across="x")

    over the nodes where ``g`` is defined (NaN skipped), optionally only those of ``inside``
    (a boolean field, e.g. ``fields.solid_fraction > 0.5`` to leave out the boundary layer).
    A shear band along the other axis shows as a peak or a dip of the profile; an inclined one
    only in a profile along its own direction (:func:`grainview.analysis.shear_bands.profile_along`,
    :func:`grainview.analysis.shear_bands.find_shear_band`).

    Parameters
    ----------
    field : xarray.DataArray
        A field over (..., y, x), e.g. ``coarse_grained(...)["solid_fraction"]``.
    across : {"x", "y"}, default "x"
        The axis the profile runs along; the average runs over the other one.
    inside : xarray.DataArray of bool, optional
        The nodes averaged (broadcast against ``field``).

    Returns
    -------
    xarray.DataArray
        The profile over (..., across), in the field's units; lazy when ``field`` is.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``across`` is not "x" or "y".

    References
    ----------
    Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012) (depth profiles);
    docs/analysis.md, "Coarse-grained fields".
    """
    if across not in ("x", "y"):
        raise ParameterError(f"across={across!r}: expected 'x' or 'y'")
    other = "y" if across == "x" else "x"
    values = field if inside is None else field.where(inside)
    out = values.mean(other, skipna=True)
    out.attrs = dict(field.attrs)
    if "long_name" in out.attrs:
        out.attrs["long_name"] = f"{out.attrs['long_name']}, averaged over {other}"
    return out
