"""The numbers the fidelity study compares, measured on one run with the project's accessors.

:func:`window_means` averages every descriptor over the snapshots of a shear-strain window;
:func:`initial_state` reads the compacted sample. ``near`` is the counting convention: None
counts the force-bearing contacts (the paper's stated rule), a gap in m adds the pairs within
that gap (``grainview.analysis.contacts.in_network``).
"""

from __future__ import annotations

import numpy as np

import grainview


def _mean(da, keep):
    return float(da.isel(time=keep).mean("time").compute())


def points_coordination(ds, near=None):
    """z counting each contact POINT (a double contact twice), rattlers left out (time,)."""
    c_all = ds.grain.contact_numbers(near=near)
    c_double = ds.grain.contact_numbers(kind="double", near=near)
    active = c_all >= 1
    return ((c_all + c_double).where(active).sum("particle") / active.sum("particle")).compute()


def window_means(path, window=(0.4, np.inf), near=None) -> dict:
    """Means over the snapshots with window[0] <= eps_q < window[1] (|gamma| in a sheared
    periodic cell: :func:`grainview.analysis.strain.shear_strain`) of: q/p, the harmonic
    prediction and a', a (fabric), a_n, a_t, z (with and without walls, and counting points),
    alpha, the weak, very weak (simple, double) fractions, k_d, f_s, f_d, k_s^S, k_d^S, q_s/p,
    q_d/p, q(xi = 1)/p (the weak network's deviator), a'(xi = 0.1) (the signed fabric
    anisotropy of the very weak contacts: < 0 when they lie across the major principal
    stress), the solid fraction, the mean stress p (Pa; and its 10th and 90th percentiles
    over the window, "p 10-90%"); plus the window's snapshot count and eps_q range. ``near``:
    the counting convention (module docstring)."""
    from grainview.analysis.force_pdf import pooled_force_pdf, strong_force_exponent
    from grainview.analysis.strain import shear_strain

    ds = grainview.open_dataset(path, chunks=None)
    eps_q = shear_strain(ds).values  # |gamma| in a sheared periodic cell
    keep = np.flatnonzero((eps_q >= window[0]) & (eps_q < window[1]))
    out = {"snapshots": int(keep.size), "eps_q max": float(eps_q.max())}
    if keep.size == 0:
        ds.close()
        return out
    res = ds.isel(time=keep)
    inv = res.grain.stress_invariants()
    hp = res.grain.harmonic_prediction(near=near)
    prop = res.grain.contact_proportions(near=near)
    xi = res.grain.xi_network(xi=[0.1, 1.0], near=near)
    alpha = strong_force_exponent(pooled_force_pdf(res, scale="linear", bins=40, range=(0.0, 6.0), near=near))
    everything = slice(None)
    out.update({
        "eps_q": (float(eps_q[keep].min()), float(eps_q[keep].max())),
        "q/p": _mean(inv["q_over_p"], everything),
        "prediction": _mean(hp["prediction"], everything),
        "prediction cross": _mean(hp["prediction_cross_term"], everything),
        "a'": _mean(hp["a_prime"], everything),
        "a": _mean(res.grain.fabric_anisotropy(near=near)["a"], everything),
        "a_n": _mean(hp["a_n"], everything),
        "a_t": _mean(hp["a_t"], everything),
        "z": _mean(res.grain.coordination(near=near)["z"], everything),
        "z with walls": _mean(res.grain.coordination(walls=True, near=near)["z"], everything),
        "z points": float(points_coordination(res, near).mean()),
        "alpha": float(alpha),
        "weak": _mean(prop["weak_fraction"], everything),
        "very weak": _mean(prop["very_weak_fraction"], everything),
        "very weak simple": _mean(prop["very_weak_simple"], everything),
        "very weak double": _mean(prop["very_weak_double"], everything),
        "k_d": _mean(prop["k_d"], everything),
        "f_s": _mean(prop["f_s"], everything),
        "f_d": _mean(prop["f_d"], everything),
        "k_s^S": _mean(prop["k_s_strong"], everything),
        "k_d^S": _mean(prop["k_d_strong"], everything),
        "k_s^W": _mean(prop["k_s_weak"], everything),
        "k_d^W": _mean(prop["k_d_weak"], everything),
        "q_s/p": _mean(res.grain.stress_invariants(kind="simple")["q_over_p"], everything),
        "q_d/p": _mean(res.grain.stress_invariants(kind="double")["q_over_p"], everything),
        "q(xi<1)/p": _mean(xi["q_over_p"].sel(xi=1.0), everything),
        "a'(very weak)": float(xi["a_prime"].sel(xi=0.1).mean("time", skipna=True)),
        "solid fraction": _mean(res.grain.solid_fraction(), everything),
        "p": _mean(inv["p"], everything),
        "p 10-90%": tuple(float(v) for v in np.percentile(inv["p"].values, [10, 90])),
    })
    ds.close()
    return out


def initial_state(path, near=None) -> dict:
    """Solid fraction, z (and z with near pairs counted, z counting points) of the first
    snapshot of a file (a compacted sample or a test's start), with the compaction's record."""
    ds = grainview.open_dataset(path, chunks=None)
    first = ds.isel(time=[0])
    out = {
        "solid fraction": float(first.grain.solid_fraction()[0]),
        "z": float(first.grain.coordination()["z"][0]),
        "z near": float(first.grain.coordination(near=near)["z"][0]) if near is not None else np.nan,
        "z points": float(points_coordination(first)[0]),
        "k_d": float(first.grain.contact_proportions()["k_d"][0]),
        "compaction steps": int(ds.attrs.get("compaction_steps", -1)),
        "settled": bool(ds.attrs.get("compaction_settled", 0)),
        "compaction s": float(ds.attrs.get("compaction_seconds", np.nan)),
        "largest I": float(ds.attrs.get("compaction_inertia_number", np.nan)),
    }
    ds.close()
    return out


def strain_series(path, quantities=("q/p", "a", "z"), near=None):
    """eps_q and the time series of a few descriptors of a run (numpy arrays), for figures."""
    ds = grainview.open_dataset(path, chunks=None)
    series = {"eps_q": ds.grain.strains()["eps_q"].values}
    getters = {
        "q/p": lambda: ds.grain.stress_invariants()["q_over_p"],
        "a": lambda: ds.grain.fabric_anisotropy(near=near)["a"],
        "z": lambda: ds.grain.coordination(near=near)["z"],
        "a_n": lambda: ds.grain.harmonic_prediction(near=near)["a_n"],
        "a_t": lambda: ds.grain.harmonic_prediction(near=near)["a_t"],
        "very weak": lambda: ds.grain.contact_proportions(near=near)["very_weak_fraction"],
    }
    for name in quantities:
        series[name] = getters[name]().values
    ds.close()
    return series


def boundary_checks(path, window=(0.4, np.inf), margin=3.0) -> dict:
    """Two computations of q/p independent of the contact stress of the whole sample, means
    over the snapshots of a shear-strain window:

    * ``q/p central``: the stress of the particles whose centres lie farther than ``margin``
      largest diameters from every wall, sum over those particles p and their contacts c of
      f_c(on p) (x) (x_c - x_p) (the volume cancels in q/p);
    * ``q/p walls``: sigma_1 = mean force of the top and bottom walls over the box width,
      sigma_2 = mean force of the left and right walls over the box height (walls named as
      the solver names them), q/p = (sigma_1 - sigma_2)/(sigma_1 + sigma_2).
    """
    with grainview.open_dataset(path, chunks=None) as ds:
        n_particles = ds.sizes["particle"]
        walls = [str(w) for w in ds["wall"].values]
        d_max = 2 * float(ds["radius"].max())
        eps_q = ds.grain.strains()["eps_q"].values
        keep = np.flatnonzero((eps_q >= window[0]) & (eps_q < window[1]))
        central, at_walls, inside_counts = [], [], []
        for k in keep:
            s = ds.isel(time=k)
            x, lo, hi = s["position"].values, s["box_min"].values, s["box_max"].values
            inside = np.all((x - lo > margin * d_max) & (hi - x > margin * d_max), axis=1)
            used = s["kind"].values > 0
            i, j = s["i"].values[used], s["j"].values[used]
            n = s["normal"].values[used]
            force = s["fn"].values[used][:, None] * n + s["ft"].values[used][:, None] * np.stack([-n[:, 1], n[:, 0]], 1)
            point = s["point"].values[used]
            on_j = (j < n_particles) & inside[np.minimum(j, n_particles - 1)]
            on_i = inside[i]
            moment = (np.einsum("ca,cb->ab", force[on_j], point[on_j] - x[j[on_j]])
                      - np.einsum("ca,cb->ab", force[on_i], point[on_i] - x[i[on_i]]))
            low, high = np.linalg.eigvalsh(-(moment + moment.T) / 2)
            central.append((high - low) / (high + low))
            inside_counts.append(int(inside.sum()))

            def wall_force(name):
                w = n_particles + walls.index(name)
                return float(np.nan_to_num(s["fn"].values[used][j == w]).sum())
            width, height = hi - lo
            sigma_1 = (wall_force("top") + wall_force("bottom")) / 2 / width
            sigma_2 = (wall_force("left") + wall_force("right")) / 2 / height
            at_walls.append((sigma_1 - sigma_2) / (sigma_1 + sigma_2))
    return {"q/p central": float(np.mean(central)) if central else np.nan,
            "q/p walls": float(np.mean(at_walls)) if at_walls else np.nan,
            "central particles": int(np.mean(inside_counts)) if inside_counts else 0}
