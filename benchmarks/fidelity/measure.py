"""The numbers the fidelity study compares, measured on one run with the project's accessors.

:func:`snapshot_measures` measures every descriptor per snapshot; :func:`window_means`,
:func:`boundary_checks` and :func:`strain_series` reduce those measures over a shear-strain
window, from a run's file or from measures kept on their own (``carry.py``);
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


MEASURES = {
    "q/p": "q_over_p", "prediction": "prediction", "prediction cross": "prediction_cross", "a'": "a_prime",
    "a": "a", "a_n": "a_n", "a_t": "a_t", "z": "z", "z with walls": "z_with_walls", "z points": "z_points",
    "weak": "weak", "very weak": "very_weak", "very weak simple": "very_weak_simple",
    "very weak double": "very_weak_double", "k_d": "k_d", "f_s": "f_s", "f_d": "f_d", "k_s^S": "k_s_strong",
    "k_d^S": "k_d_strong", "k_s^W": "k_s_weak", "k_d^W": "k_d_weak", "q_s/p": "q_s_over_p",
    "q_d/p": "q_d_over_p", "q(xi<1)/p": "q_weak_over_p", "a'(very weak)": "a_prime_very_weak",
    "solid fraction": "solid_fraction", "p": "p",
}
"""The descriptors :func:`window_means` averages: its key -> the variable of
:func:`snapshot_measures` that holds it per snapshot."""

FORCE_BINS = dict(scale="linear", bins=40, range=(0.0, 6.0))
"""The bins of the pooled force pdf whose tail gives alpha."""


def snapshot_measures(path, near=None, window=None, margin=3.0):
    """Every descriptor the study compares, per snapshot of a run: an xarray Dataset (dim time).

    ``eps_q`` (|gamma| in a sheared periodic cell: :func:`grainview.analysis.strain.shear_strain`),
    ``step``, ``inertia_number``, the variables of :data:`MEASURES`, each snapshot's force
    histogram (``count`` over ``bin``, ``n_contacts``, ``zero_fraction``:
    :func:`grainview.analysis.force_pdf.force_pdf` with :data:`FORCE_BINS`, pooled by
    :func:`window_means`), and, between walls, :func:`boundary_checks`' ``q_over_p_central``,
    ``central_particles`` and ``q_over_p_walls`` and, in a biaxial test, the right wall's
    stress and motion and p across the sample (:func:`benchmarks.wall_motion.wall_series`).
    Attributes: the run's particles, top-wall speed, compaction steps, ``eps_q_max`` (the
    run's largest eps_q), ``near_m`` (``near``: the counting convention, module docstring; -1
    for force-bearing contacts) and, in a biaxial test, the right wall's constants
    (:func:`benchmarks.wall_motion.wall_constants`). ``window``: only the snapshots with
    window[0] <= eps_q < window[1] (default all).

    The means, percentiles and pooled pdfs of :func:`window_means`, :func:`boundary_checks` and
    :func:`strain_series` are taken from it, so a run's measures written to a small file (a run
    carried over several sittings keeps only them and its last snapshot: ``carry.py``) give the
    same numbers as the run's file.
    """
    import xarray as xr

    from grainview.analysis.force_pdf import force_pdf
    from grainview.analysis.strain import shear_strain

    with grainview.open_dataset(path, chunks=None) as ds:
        eps_q = shear_strain(ds).values
        keep = np.arange(eps_q.size) if window is None else np.flatnonzero((eps_q >= window[0]) & (eps_q < window[1]))
        inertia = ds.grain.inertia_number().values
        attrs = {"particles": int(ds.sizes["particle"]), "velocity": float(ds.attrs.get("wall_velocity_m_s", np.nan)),
                 "compaction_steps": int(ds.attrs.get("compaction_steps", -1)),
                 "near_m": -1.0 if near is None else float(near), "scale": FORCE_BINS["scale"],
                 "eps_q_max": float(eps_q.max())}
        steps = ds["step"].values if "step" in ds else np.full(eps_q.size, -1)
        res = ds.isel(time=keep)
        inv = res.grain.stress_invariants()
        hp = res.grain.harmonic_prediction(near=near)
        prop = res.grain.contact_proportions(near=near)
        xi = res.grain.xi_network(xi=[0.1, 1.0], near=near)
        values = {
            "q/p": inv["q_over_p"], "prediction": hp["prediction"], "prediction cross": hp["prediction_cross_term"],
            "a'": hp["a_prime"], "a": res.grain.fabric_anisotropy(near=near)["a"], "a_n": hp["a_n"], "a_t": hp["a_t"],
            "z": res.grain.coordination(near=near)["z"], "z with walls": res.grain.coordination(walls=True, near=near)["z"],
            "z points": points_coordination(res, near), "weak": prop["weak_fraction"],
            "very weak": prop["very_weak_fraction"], "very weak simple": prop["very_weak_simple"],
            "very weak double": prop["very_weak_double"], "k_d": prop["k_d"], "f_s": prop["f_s"], "f_d": prop["f_d"],
            "k_s^S": prop["k_s_strong"], "k_d^S": prop["k_d_strong"], "k_s^W": prop["k_s_weak"],
            "k_d^W": prop["k_d_weak"], "q_s/p": res.grain.stress_invariants(kind="simple")["q_over_p"],
            "q_d/p": res.grain.stress_invariants(kind="double")["q_over_p"],
            "q(xi<1)/p": xi["q_over_p"].sel(xi=1.0), "a'(very weak)": xi["a_prime"].sel(xi=0.1),
            "solid fraction": res.grain.solid_fraction(), "p": inv["p"],
        }
        pdf = force_pdf(res, near=near, **FORCE_BINS)
        data = {MEASURES[key]: ("time", np.asarray(da.values, dtype=float)) for key, da in values.items()}
        data.update(eps_q=("time", eps_q[keep]), step=("time", steps[keep]), inertia_number=("time", inertia[keep]),
                    count=(("time", "bin"), pdf["count"].values), n_contacts=("time", pdf["n_contacts"].values),
                    zero_fraction=("time", pdf["zero_fraction"].values))
        walls = {str(w) for w in ds["wall"].values} if "wall" in ds else set()
        if {"top", "bottom", "left", "right"} <= walls:
            data.update({name: ("time", column) for name, column in _boundary_series(res, margin).items()})
            if ds.attrs.get("scene", "biaxial") == "biaxial":
                from benchmarks.wall_motion import wall_constants, wall_series

                data.update({name: ("time", column) for name, column in wall_series(res, path).items()})
                attrs.update(wall_constants(ds, path))
        coords = {"bin_edges": ("edge", pdf["bin_edges"].values), "f_over_mean": ("bin", pdf["f_over_mean"].values)}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _is_file(source) -> bool:
    return isinstance(source, (str, bytes)) or hasattr(source, "__fspath__")


def _measures(source, near=None, window=None):
    """:func:`snapshot_measures` of a run's file, or ``source`` itself when it is such a Dataset
    (the snapshots of ``window`` selected)."""
    if _is_file(source):
        return snapshot_measures(source, near, window)
    if window is None:
        return source
    eps_q = source["eps_q"].values
    return source.isel(time=np.flatnonzero((eps_q >= window[0]) & (eps_q < window[1])))


def window_means(source, window=(0.4, np.inf), near=None) -> dict:
    """Means over the snapshots with window[0] <= eps_q < window[1] (|gamma| in a sheared
    periodic cell: :func:`grainview.analysis.strain.shear_strain`) of: q/p, the harmonic
    prediction and a', a (fabric), a_n, a_t, z (with and without walls, and counting points),
    alpha, the weak, very weak (simple, double) fractions, k_d, f_s, f_d, k_s^S, k_d^S, q_s/p,
    q_d/p, q(xi = 1)/p (the weak network's deviator), a'(xi = 0.1) (the signed fabric
    anisotropy of the very weak contacts: < 0 when they lie across the major principal
    stress), the solid fraction, the mean stress p (Pa; and its 10th and 90th percentiles
    over the window, "p 10-90%"); plus the window's snapshot count and eps_q range. alpha is
    fitted to the pdf pooled over the window's snapshots. ``source``: a run's file, or its
    :func:`snapshot_measures` (then ``near`` is the one they were measured with). ``near``: the
    counting convention (module docstring)."""
    from grainview.analysis.force_pdf import pool_force_pdf, strong_force_exponent

    m = _measures(source, near, window)
    out = {"snapshots": int(m.sizes["time"]), "eps_q max": float(m.attrs["eps_q_max"])}
    if not m.sizes["time"]:
        return out
    out["eps_q"] = (float(m["eps_q"].min()), float(m["eps_q"].max()))
    for key, name in MEASURES.items():
        if key == "weak":  # alpha after the coordinations, as the tables read
            out["alpha"] = float(strong_force_exponent(pool_force_pdf(m)))
        out[key] = float(m[name].mean("time"))  # NaN snapshots skipped
    out["p 10-90%"] = tuple(float(v) for v in np.percentile(m["p"].values, [10, 90]))
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


def strain_series(source, quantities=("q/p", "a", "z"), near=None):
    """eps_q and the time series of a few descriptors (keys of :data:`MEASURES`) of a run, numpy
    arrays for figures; ``source``: a run's file or its :func:`snapshot_measures`."""
    m = _measures(source, near)
    series = {"eps_q": m["eps_q"].values}
    series.update({name: m[MEASURES[name]].values for name in quantities})
    return series


def boundary_checks(source, window=(0.4, np.inf), margin=3.0) -> dict:
    """Two computations of q/p independent of the contact stress of the whole sample, means
    over the snapshots of a shear-strain window:

    * ``q/p central``: the stress of the particles whose centres lie farther than ``margin``
      largest diameters from every wall, sum over those particles p and their contacts c of
      f_c(on p) (x) (x_c - x_p) (the volume cancels in q/p);
    * ``q/p walls``: sigma_1 = mean force of the top and bottom walls over the box width,
      sigma_2 = mean force of the left and right walls over the box height (walls named as
      the solver names them), q/p = (sigma_1 - sigma_2)/(sigma_1 + sigma_2).

    ``source``: a run's file or its :func:`snapshot_measures` (measured with ``margin``).
    """
    m = snapshot_measures(source, window=window, margin=margin) if _is_file(source) else _measures(source, window=window)
    if not m.sizes["time"] or "q_over_p_central" not in m:
        return {"q/p central": np.nan, "q/p walls": np.nan, "central particles": 0}
    return {"q/p central": float(m["q_over_p_central"].mean()), "q/p walls": float(m["q_over_p_walls"].mean()),
            "central particles": int(m["central_particles"].mean())}


def _boundary_series(ds, margin):
    """Per snapshot of ``ds`` (walls named as the solver names them): q/p of the central
    particles' stress, their number, and q/p from the wall forces (:func:`boundary_checks`)."""
    n_particles = ds.sizes["particle"]
    walls = [str(w) for w in ds["wall"].values]
    d_max = 2 * float(ds["radius"].max())
    central, at_walls, inside_counts = [], [], []
    for k in range(ds.sizes["time"]):
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
        central.append((high - low) / (high + low) if high + low > 0 else np.nan)  # no central particle: none
        inside_counts.append(int(inside.sum()))

        def wall_force(name):
            w = n_particles + walls.index(name)
            return float(np.nan_to_num(s["fn"].values[used][j == w]).sum())
        width, height = hi - lo
        sigma_1 = (wall_force("top") + wall_force("bottom")) / 2 / width
        sigma_2 = (wall_force("left") + wall_force("right")) / 2 / height
        at_walls.append((sigma_1 - sigma_2) / (sigma_1 + sigma_2))
    return {"q_over_p_central": np.array(central, float), "central_particles": np.array(inside_counts, float),
            "q_over_p_walls": np.array(at_walls, float)}
