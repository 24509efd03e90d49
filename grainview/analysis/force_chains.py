"""Force chains: the particles that carry the sample's major load in quasi-linear columns, found
by the method of Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005), and
followed from snapshot to snapshot (docs/analysis.md, "Force chains").

The physics on plain arrays is :mod:`grainview.analysis.arrays.force_chains`; here it is lifted to the
labelled dataset, lazily along ``time`` (one snapshot's contacts and particles whole in each
chunk).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import force_chains as _chains
from .contacts import selection
from ..contract.errors import ParameterError
from ..contract.shapes import particle_area
from .sample import thickness
from .snapshots import select_snapshots
from ._docs import fill_doc

__all__ = ["force_chains", "chain_length_pdf", "chain_survival", "particle_volume", "DEFAULT_ANGLE"]

DEFAULT_ANGLE = 45.0
"""Largest angle (degrees) between a link's branch vector and the major stress direction of
each of its two particles, Peters et al. (2005)'s value."""


def particle_volume(ds: xr.Dataset) -> xr.DataArray:
    """Volume of each particle (particle,), m^3: its area times the slab thickness.

        V_p = A_p t,

    A_p = pi R^2 for a disk and the polygon's area otherwise
    (:func:`grainview.contract.shapes.particle_area`; from the file's ``vertices`` when it holds
    them), t the slab thickness ``thickness_m`` (docs/schema.md). Lazy on dask input.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract (docs/schema.md), eager or chunked.

    Returns
    -------
    xarray.DataArray
        ``particle_volume`` (particle,), m^3.
    """
    args = [ds["radius"], ds["n_vertices"]]
    dims = [["particle"], ["particle"]]
    if "vertices" in ds.variables:
        args.append(ds["vertices"])
        dims.append(list(ds["vertices"].dims))
    area = xr.apply_ufunc(particle_area, *args, input_core_dims=dims, output_core_dims=[["particle"]],
                          dask="parallelized", output_dtypes=[float])
    return with_attrs(area * thickness(ds), "particle_volume", "m3", "particle volume (area x slab thickness)")


def _check(angle, min_size, max_length):
    if isinstance(angle, bool) or not isinstance(angle, (int, float, np.integer, np.floating)) \
            or not 0 < float(angle) <= 90:
        raise ParameterError(f"angle={angle!r}: expected an angle in degrees, 0 < angle <= 90")
    for name, value, low in (("min_size", min_size, 2), ("max_length", max_length, None)):
        low = min_size if low is None else low
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ParameterError(f"{name}={value!r}: expected an integer >= {low}")


@fill_doc
def force_chains(ds: xr.Dataset, angle: float = DEFAULT_ANGLE, min_size: int = 3, max_length: int = 50,
                 follow: bool = False) -> xr.Dataset:
    """Force chains of every snapshot (time, particle), their statistics and, with ``follow``,
    their lifetimes (Peters et al. 2005).

    For each snapshot:

    1. each particle's stress from its own force-bearing contacts, wall contacts included,
       compression positive (docs/conventions.md §0: f the force of i on j, n from i to j),

           sigma_p = (1/V_p) sum_{c of p} s_pc f^c (x) (x^c - x_p),

       x^c the contact's ``point``, x_p the particle's centre, s_pc = +1 for body i and -1 for
       body j, V_p its volume (:func:`particle_volume`); sum_p V_p sigma_p = V sigma, the
       sample's stress (:func:`grainview.analysis.stress.stress_tensor` with walls);
    2. its principal stresses sigma_1 >= sigma_2 and major direction theta_1;
    3. the chain particles: sigma_1 above the snapshot's mean of sigma_1 over all particles,
       with a major direction (an isotropic particle stress has none,
       :data:`grainview.analysis.arrays.force_chains.ISOTROPY_TOLERANCE`);
    4. a link for each force-bearing contact between two chain particles whose branch vector
       lies within ``angle`` of the major directions of both;
    5. chains: the connected sets of linked particles of at least ``min_size`` particles.

    Parameters
    ----------
    {ds}
    angle : float, default 45
        Largest angle between a link's branch vector and each particle's major direction,
        degrees, in (0, 90].
    min_size : int, default 3
        Fewest particles of a chain (>= 2).
    max_length : int, default 50
        Last bin of ``length_count`` and ``length_pdf``, which counts every chain of
        ``max_length`` particles or more.
    follow : bool, default False
        Also follow the chains from snapshot to snapshot by their shared members
        (:func:`grainview.analysis.arrays.force_chains.follow_chains`) and give their lifetimes. The
        tracks need every snapshot's chains, so the result is then computed (in one pass over
        the data, one time chunk at a time).

    Returns
    -------
    xarray.Dataset
        Over (time, particle): ``chain`` (chain id, -1 outside chains; ids 0, 1, ... per
        snapshot in the order of their smallest particle), ``sigma_1``, ``sigma_2`` (Pa),
        ``theta_1`` (rad, in [0, pi), NaN for an isotropic particle stress);
        over (time, contact): ``link`` (the contacts joining two members of a chain);
        over time: ``n_chains``, ``mean_length`` (particles per chain), ``orientation``
        (axial mean of the chains' link directions, rad in [0, pi)), ``particle_fraction``,
        ``deviator_fraction`` ((D_chains : D)/(D : D) with D the deviator of
        sum_p V_p sigma_p: the chains' contribution to q in units of q, signed and above 1
        where the other particles' deviator opposes the sample's, since the two contributions
        add up to 1), ``pressure_fraction`` (their share of p);
        over (time, length): ``length_count`` and ``length_pdf`` (the number and fraction of
        chains of each length, in particles; NaN without chains). With ``follow``:
        ``chain_track`` (time, particle), the track id of the particle's chain (-1 outside
        chains), and over ``track``: ``first``, ``last`` (snapshot indices), ``birth``,
        ``death`` (s), ``lifetime`` (snapshots seen), ``duration`` (death - birth, s),
        ``mean_size`` (particles) and ``censored`` (seen in the first or last snapshot, so
        its life may be longer). Lazy on dask input unless ``follow``.

        In a periodic cell (``cell``) the links and chains read only the pairs (i, j) and
        their minimum-image branches, so a chain across the cell's boundary is one chain; each
        particle's stress takes its levers from one image of each pair
        (:func:`grainview.analysis.arrays.force_chains.periodic_points`).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``angle`` is not in (0, 90], ``min_size`` not an integer >= 2 or ``max_length``
        not an integer >= ``min_size``.

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005) (the particle
    stress, the above-average criterion, the quasi-linear alignment, chains of three or more);
    docs/conventions.md §0 and §1; docs/analysis.md, "Force chains".
    """
    _check(angle, min_size, max_length)
    mask = selection(ds, walls=True)
    n_bins = max_length - min_size + 1
    outputs = apply(_chains.force_chains, ds["i"], ds["j"], ds["fn"], ds["ft"], ds["normal"], ds["point"],
                    ds["branch"], mask, ds["position"], particle_volume(ds),
                    kwargs={"angle": float(angle), "min_size": int(min_size), "max_length": int(max_length),
                            "periodic": "cell" in ds.variables},
                    output_sizes={"length": n_bins},
                    output_dtypes=[np.int64, bool, float, float, float, np.int64, np.int64, float, float, float,
                                   float])
    (chain, link, sigma_1, sigma_2, theta_1, n_chains, length_count, orientation, particle_fraction,
     deviator_fraction, pressure_fraction) = outputs
    mean_length = (chain >= 0).sum("particle") / n_chains.where(n_chains > 0)
    out = xr.Dataset({
        "chain": with_attrs(chain, "chain", "1", "force chain id of the particle (-1: in no chain)",
                            flag_values=-1, flag_meanings="no_chain"),
        "sigma_1": with_attrs(sigma_1, "sigma_1", "Pa", "major principal stress of the particle (compression > 0)"),
        "sigma_2": with_attrs(sigma_2, "sigma_2", "Pa", "minor principal stress of the particle (compression > 0)"),
        "theta_1": with_attrs(theta_1, "theta_1", "rad", "major principal direction of the particle's stress"),
        "link": with_attrs(link, "link", "1", "contact linking two particles of a force chain"),
        "n_chains": with_attrs(n_chains, "n_chains", "1", "number of force chains"),
        "mean_length": with_attrs(mean_length, "mean_length", "1", "mean number of particles per chain"),
        "orientation": with_attrs(orientation, "orientation", "rad", "mean orientation of the chains' links"),
        "particle_fraction": with_attrs(particle_fraction, "particle_fraction", "1",
                                        "fraction of the particles in force chains"),
        "deviator_fraction": with_attrs(deviator_fraction, "deviator_fraction", "1",
                                        "the chains' particles' contribution to the deviatoric stress, in units "
                                        "of the sample's (above 1 where the other particles' deviator opposes it)"),
        "pressure_fraction": with_attrs(pressure_fraction, "pressure_fraction", "1",
                                        "share of the mean stress carried by the chains' particles"),
        "length_count": with_attrs(length_count, "length_count", "1", "number of chains of each length"),
        "length_pdf": with_attrs(length_count / n_chains.where(n_chains > 0), "length_pdf", "1",
                                 "fraction of the chains of each length"),
    })
    lengths = np.arange(min_size, max_length + 1)
    out = out.assign_coords(length=("length", lengths, {
        "units": "1", "long_name": f"chain length, particles (the last bin: {max_length} or more)"}))
    out.attrs.update(angle_deg=float(angle), min_size=int(min_size), max_length=int(max_length))
    if follow:  # the tracks need every snapshot's ids: compute everything in one pass
        out = out.compute()
        out = out.merge(_tracks(out["chain"], ds["time"]))
    return out


def chain_length_pdf(ds: xr.Dataset, time="residual", angle: float = DEFAULT_ANGLE, min_size: int = 3,
                     max_length: int = 50) -> xr.Dataset:
    """P(L): the chains of the snapshots ``time`` pooled, by their length L in particles.

        P(L) = n(L) / sum_L' n(L'),

    n(L) the number of chains of L particles over the snapshots (``length_count`` of
    :func:`force_chains` summed over them; the last bin counts every chain of ``max_length``
    particles or more).

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract, eager or chunked along ``time``.
    time : str, int, slice or sequence of int, default "residual"
        The snapshots pooled (:func:`grainview.analysis.snapshots.select_snapshots`):
        ``"residual"`` the residual state, eps_q >= 0.3 (for a run that stops short of it, the
        last part of the run), ``"all"`` or None every snapshot, a snapshot index, a slice or a
        sequence of indices.
    angle, min_size, max_length
        As in :func:`force_chains`.

    Returns
    -------
    xarray.Dataset
        Over ``length``: ``length_count`` (chains) and ``length_pdf`` (dimensionless; NaN
        without any chain). Lazy on dask input (``time="residual"`` reads the boxes to find
        the window).

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    out = force_chains(select_snapshots(ds, time), angle=angle, min_size=min_size, max_length=max_length)
    count = out["length_count"].sum("time")
    total = count.sum("length")
    return xr.Dataset({
        "length_count": with_attrs(count, "length_count", "1", "number of chains of each length, pooled"),
        "length_pdf": with_attrs(count / total.where(total > 0), "length_pdf", "1",
                                 "fraction of the pooled chains of each length"),
    }, attrs=dict(out.attrs, pooled_snapshots=int(out.sizes["time"])))


@fill_doc
def chain_survival(ds: xr.Dataset, angle: float = DEFAULT_ANGLE, min_size: int = 3) -> xr.DataArray:
    """The fraction of the chains seen in at least n snapshots, for n = 1, 2, ..., of the chains
    born and gone within the record.

        S(n) = #{tracks k uncensored : lifetime_k >= n} / #{tracks k uncensored},

    the tracks and their lifetimes (snapshots seen) those of :func:`force_chains` with
    ``follow=True``; a censored track (seen in the first or the last snapshot) may live longer
    than seen and is left out. Computed (the tracks need every snapshot).

    Parameters
    ----------
    {ds_short}
    angle, min_size
        As in :func:`force_chains`.

    Returns
    -------
    xarray.DataArray
        ``survival`` over ``lifetime`` n = 1 ... the longest uncensored lifetime (snapshots),
        dimensionless; empty without an uncensored chain.

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    out = force_chains(ds, angle=angle, min_size=min_size, follow=True)
    lives = np.asarray(out["lifetime"].values)[~np.asarray(out["censored"].values, bool)]
    n = np.arange(1, (lives.max() if lives.size else 0) + 1)
    surviving = (lives[None, :] >= n[:, None]).mean(1) if lives.size else np.zeros(0)
    return with_attrs(xr.DataArray(surviving, dims="lifetime", coords={"lifetime": n}), "survival", "1",
                      "fraction of the uncensored chains seen in at least n snapshots",
                      angle_deg=float(angle), min_size=int(min_size), chains=int(lives.size))


def _tracks(chain: xr.DataArray, time: xr.DataArray) -> xr.Dataset:
    """The tracks of :func:`grainview.analysis.arrays.force_chains.follow_chains` as a Dataset."""
    ids = np.asarray(chain.transpose("time", "particle").values)
    track, first, last, size = _chains.follow_chains(ids)
    times = np.asarray(time.values, float)
    n_time = ids.shape[0]
    return xr.Dataset({
        "chain_track": with_attrs(xr.DataArray(track, dims=("time", "particle"), coords={"time": chain["time"]}),
                                  "chain_track", "1",
                                  "track id of the particle's chain, followed by shared members (-1: no chain)"),
        "first": with_attrs(xr.DataArray(first, dims="track"), "first", "1", "first snapshot of the chain"),
        "last": with_attrs(xr.DataArray(last, dims="track"), "last", "1", "last snapshot of the chain"),
        "birth": with_attrs(xr.DataArray(times[first], dims="track"), "birth", "s",
                            "time of the chain's first snapshot"),
        "death": with_attrs(xr.DataArray(times[last], dims="track"), "death", "s", "time of the chain's last snapshot"),
        "lifetime": with_attrs(xr.DataArray(last - first + 1, dims="track"), "lifetime", "1",
                               "snapshots in which the chain is seen"),
        "duration": with_attrs(xr.DataArray(times[last] - times[first], dims="track"), "duration", "s",
                               "time from the chain's first to its last snapshot"),
        "mean_size": with_attrs(xr.DataArray(size, dims="track"), "mean_size", "1",
                                "mean number of particles of the chain over its snapshots"),
        "censored": with_attrs(xr.DataArray((first == 0) | (last == n_time - 1), dims="track"), "censored", "1",
                               "seen in the first or the last snapshot (its life may be longer)"),
    })
