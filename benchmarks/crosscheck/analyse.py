"""Analysis of the cross-check's runs with the project's accessors: series, window means, checks,
the figure.

Every number comes from ``ds.grain`` on the contract files (``grainview.open_dataset``):

* eps_1, eps_q: ``strains()`` (log strains against the first snapshot);
* q/p, p: ``stress_invariants()``; sigma_xx (Pa): ``stress_tensor()`` -- from the contacts,
  wall contacts included;
* a: ``fabric_anisotropy()``; a_n, a_t: ``harmonic_prediction()`` (signed, particle pairs);
* z: ``coordination()`` (rattlers excluded); k_d: ``contact_proportions()`` (share of double
  contacts, ``kind == 2``, among the force-bearing particle pairs).

One quantity is not an accessor's: ``k_d2``, the share of force-bearing particle pairs whose
two points both carry force (``normal_impulse`` > 0 at both; :func:`two_point_share`). The
engines mark a pair double by different geometric tests (this solver: near-parallel edges
within its alert distance, whether or not the second point is loaded; Box2D and pymunk: two
points in the manifold, i.e. both overlapping), so k_d compares definitions as much as
packings; k_d2 is defined the same way for all.

The first snapshot (the initial state, step 0) is left out of every mean and plot: the peer
engines have no contact forces before their first step (the project's solver writes none there
either, a loaded sample carrying only its warm start).
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

WINDOWS = ((0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.5))
"""eps_q windows of the table (lower bound included, upper excluded)."""
QUANTITIES = {  # name: (label on the figure, units)
    "q_over_p": ("q/p", "1"),
    "a": ("fabric anisotropy a", "1"),
    "a_n": ("normal force anisotropy a_n", "1"),
    "a_t": ("tangential force anisotropy a_t", "1"),
    "z": ("coordination number z", "contacts per particle"),
    "k_d": ("proportion of double contacts k_d", "1"),
    "k_d2": ("pairs with two loaded points k_d2", "1"),
}


def series(path) -> xr.Dataset:
    """Per-snapshot series (time,) of one contract file, computed, first snapshot dropped:
    eps_1, eps_q, p (Pa), q_over_p, sigma_xx (Pa), a, a_n, a_t, z, k_d, right_stress (Pa: the
    particles' force on the right wall over the sample height and thickness), right_x (m:
    the right wall's position) and overlap (largest interpenetration over the smallest
    diameter, when the file records it)."""
    import grainview

    ds = grainview.open_dataset(path)
    g = ds.grain
    eps = g.strains()
    inv = g.stress_invariants()
    harmonic = g.harmonic_prediction()
    height = ds["box_max"].sel(xy="y") - ds["box_min"].sel(xy="y")
    columns = {
        "eps_1": eps["eps_1"], "eps_q": eps["eps_q"], "p": inv["p"], "q_over_p": inv["q_over_p"],
        "sigma_xx": g.stress_tensor().isel(xy_a=0, xy_b=0, drop=True),
        "a": g.fabric_anisotropy()["a"], "a_n": harmonic["a_n"], "a_t": harmonic["a_t"],
        "z": g.coordination()["z"], "k_d": g.contact_proportions()["k_d"],
    }
    # the accessors' results carry the strains as coordinates: keep only time, so that eps_1
    # and eps_q are variables of the series like the others
    out = xr.Dataset({name: v.drop_vars([c for c in v.coords if c != "time"]) for name, v in columns.items()})
    if "wall_force" in ds and "wall_position" in ds:
        thickness = float(ds.attrs.get("thickness_m", 1.0))
        out["right_stress"] = ds["wall_force"].sel(wall="right", xy="x", drop=True) / (height * thickness)
        out["right_x"] = ds["wall_position"].sel(wall="right", xy="x", drop=True)
    if "normal_impulse" in ds:
        out["k_d2"] = two_point_share(ds)
    else:
        out["k_d2"] = xr.full_like(out["eps_q"], np.nan)
    if "max_interpenetration" in ds:
        out["overlap"] = ds["max_interpenetration"] / (2 * float(ds["radius"].min()))
    out = out.drop_vars([c for c in out.coords if c != "time"])
    with warnings.catch_warnings():  # the initial snapshot has no contacts: 0/0 there
        warnings.filterwarnings("ignore", "invalid value encountered", RuntimeWarning)
        out = out.compute()
    out.attrs = {"sigma0_Pa": float(ds.attrs.get("sigma0_Pa", np.nan)), "path": str(path)}
    ds.close()
    return out.isel(time=slice(1, None))


def two_point_share(ds) -> xr.DataArray:
    """k_d2 (time,): among the particle pairs with f_n > 0, the share whose two contact points
    both have a positive normal impulse (``normal_impulse``, N s)."""
    n = ds.sizes["particle"]
    slot = xr.DataArray(np.arange(ds.sizes["contact"]), dims="contact")
    pairs = (slot < ds["contact_count"]) & (ds["j"] < n) & (ds["fn"] > 0)
    loaded = (ds["normal_impulse"] > 0).all("contact_point") & pairs
    return loaded.sum("contact") / pairs.sum("contact")


def window_means(s: xr.Dataset, windows=WINDOWS) -> list[dict]:
    """Means of the table's quantities over the snapshots of each eps_q window: a list of
    dicts (window, snapshots, and one mean per quantity; NaN for an empty window)."""
    rows = []
    for lo, hi in windows:
        inside = (s["eps_q"] >= lo) & (s["eps_q"] < hi)
        row = {"window": (lo, hi), "snapshots": int(inside.sum())}
        for name in QUANTITIES:
            row[name] = float(s[name].where(inside).mean()) if row["snapshots"] else np.nan
        rows.append(row)
    return rows


def residual_q_over_p(s: xr.Dataset, start: float = 0.2) -> float:
    """Mean q/p over eps_q >= ``start`` to the end of the test: the residual shear strength
    (the plateau of q/p), used to check that the peers' iteration budgets suffice."""
    return float(s["q_over_p"].where(s["eps_q"] >= start).mean())


def checks(s: xr.Dataset, sigma0: float) -> dict:
    """Sanity checks of one run (the export and the protocol), over the sheared snapshots:

    * ``sxx``: sigma_xx from the contacts over sigma0 (mean, min, max): the right wall holds
      sigma0, so this is 1 within a few % in a quasi-static test. (p is not: with
      sigma_2 = sigma_xx = sigma0, p = sigma0 / (1 - q/p), 1.5 sigma0 at q/p = 1/3.)
    * ``right``: the particles' mean force on the right wall over h t, over sigma0 (the wall's
      momentum balance: the applied force sigma0 h t against the contacts' push);
    * ``p0``: p over sigma0 at the first sheared snapshot (isotropic start: close to 1);
    * ``eps_1``, ``eps_q`` reached, ``dx``: the right wall's displacement (m, > 0 outward),
      ``overlap``: the largest interpenetration over the smallest diameter.
    """
    out = {"sxx": (float(s["sigma_xx"].mean() / sigma0), float(s["sigma_xx"].min() / sigma0),
                   float(s["sigma_xx"].max() / sigma0)),
           "p0": float(s["p"].isel(time=0) / sigma0),
           "eps_1": float(s["eps_1"].isel(time=-1)), "eps_q": float(s["eps_q"].isel(time=-1))}
    if "right_stress" in s:
        out["right"] = float(s["right_stress"].mean() / sigma0)
        out["dx"] = float(s["right_x"].isel(time=-1) - s["right_x"].isel(time=0))
    if "overlap" in s:
        out["overlap"] = float(s["overlap"].max())
    return out


def smooth(values, width=9):
    """Centred running mean over ``width`` snapshots (shorter at the ends), NaN-aware."""
    values = np.asarray(values, float)
    valid = np.isfinite(values)
    kernel = np.ones(width)
    total = np.convolve(np.where(valid, values, 0.0), kernel, mode="same")
    count = np.convolve(valid.astype(float), kernel, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count


def figure(runs, path, styles, colours, sigma0, width=9):
    """The table's quantities and sigma_xx/sigma0 against eps_q, one panel each, engines as
    line styles and shapes as colours, each series smoothed by a running mean over ``width``
    snapshots. ``runs`` maps (shape, engine label) to a :func:`series` dataset, ``styles``
    engine label to a line style, ``colours`` shape to a colour, ``sigma0`` shape to its
    confining stress (Pa). Writes ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    panels = dict(QUANTITIES, sigma_xx=("horizontal stress sigma_xx / sigma0", "1"))
    fig, axes = plt.subplots(2, 4, figsize=(17, 7.5), constrained_layout=True)
    for ax, (name, (label, units)) in zip(axes.flat, panels.items()):
        for (shape, engine), s in runs.items():
            values = s[name] / sigma0[shape] if name == "sigma_xx" else s[name]
            ax.plot(s["eps_q"], smooth(values, width), linestyle=styles[engine], color=colours[shape], lw=1.3)
        ax.set_xlabel("shear strain eps_q = eps_1 - eps_2 (1)")
        ax.set_ylabel(f"{label} ({units})")
        ax.grid(alpha=0.3)
    engines = list(dict.fromkeys(engine for _, engine in runs))
    shapes = list(dict.fromkeys(shape for shape, _ in runs))
    axes.flat[0].legend(handles=[Line2D([], [], color="k", linestyle=styles[e], label=e) for e in engines],
                        title="engine", fontsize=8, loc="lower right")
    axes.flat[1].legend(handles=[Line2D([], [], color=colours[s], label=s) for s in shapes],
                        title="shape", fontsize=8, loc="lower right")
    fig.suptitle(f"Biaxial test of the same compacted samples in three engines "
                 f"(running mean over {width} snapshots)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
