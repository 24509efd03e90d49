"""A reader's summary of a dataset of the contract, in a few lines: what the report's index
says of each run and, read from the file without xarray (:mod:`grainview.app.file_summary`), what
``grainview info`` prints (numpy alone when imported, so that ``info`` loads no xarray). Which
particles are regular polygons, and one name for a sample's shapes, are the analysis's
(:func:`grainview.analysis.sample.regular_of`, :func:`grainview.analysis.sample.shape_name`)."""

from __future__ import annotations

import numpy as np


def describe(ds) -> list:
    """A reader's summary of a dataset of the contract: size and shapes, snapshots, strain and
    q/p reached, and the settings a physicist asks for first, in readable units (what the
    report's index says of each run; ``grainview info`` prints the same lines from the file,
    :func:`grainview.app.file_summary.describe_file`)."""
    from ..analysis.sample import regular_of

    snapshots = ds.sizes.get("time", 0)
    facts = {"n_vertices": ds["n_vertices"].values, "n_walls": ds.sizes.get("wall", 0), "regular": regular_of(ds),
             "n_slots": ds.sizes["contact"], "snapshots": snapshots}
    if snapshots:
        facts.update(time=ds["time"].values, contact_count=ds["contact_count"].values)
        if "box_min" in ds:
            facts["solid_fraction"] = ds.grain.solid_fraction().values
            if snapshots > 1:
                eps = ds.grain.strains()
                facts.update(eps_1=float(eps["eps_1"][-1]), eps_q=float(eps["eps_q"][-1]),
                             q_over_p=ds.grain.stress_invariants()["q_over_p"].values)
    return summary_lines(facts, ds.attrs)


def shape_counts(n_vertices, regular=None) -> str:
    """The particles' shapes in words, with their counts: disks, regular polygons by vertex
    count ("400 5-gons") and the irregular convex polygons together with the range of their
    vertex counts ("100 irregular convex polygons with 4-9 vertices"); ``regular`` (per
    particle, :func:`grainview.contract.shapes.regular_polygons`) absent: every polygon is
    regular."""
    n_vertices = np.asarray(n_vertices).reshape(-1)
    regular = n_vertices >= 3 if regular is None else np.asarray(regular, bool).reshape(-1)
    irregular = (n_vertices >= 3) & ~regular
    counts = [(int(k), int(((n_vertices == k) & ~irregular).sum())) for k in np.unique(n_vertices[~irregular])]
    words = [f"{c} {'disks' if k == 0 else f'{k}-gons'}" for k, c in counts]
    if irregular.any():
        low, high = int(n_vertices[irregular].min()), int(n_vertices[irregular].max())
        words.append(f"{int(irregular.sum())} irregular convex polygons with "
                     f"{low if low == high else f'{low}-{high}'} vertices")
    return ", ".join(words)


def summary_lines(facts: dict, attrs: dict) -> list:
    """The summary's lines from its numbers: ``facts`` holds ``n_vertices`` (per particle),
    optionally ``regular`` (per particle: which polygons are regular; all of them when absent),
    ``n_walls``, ``n_slots``, ``snapshots`` and, when there are snapshots, ``time`` (s),
    ``contact_count``, optionally ``solid_fraction`` (per snapshot) and, with more than one
    snapshot, ``eps_1``, ``eps_q`` (last snapshot) and ``q_over_p`` (per snapshot); ``attrs``
    the file's global attributes."""
    a = attrs
    lines = [f"{np.size(facts['n_vertices'])} particles ({shape_counts(facts['n_vertices'], facts.get('regular'))}), "
             f"{facts['n_walls']} walls, {facts['n_slots']} contact slots"]
    snapshots = facts["snapshots"]
    if snapshots:
        t = facts["time"]
        count = facts["contact_count"]
        phi = facts.get("solid_fraction")
        lines.append(f"{snapshots} snapshot{'s' * (snapshots > 1)}, t = {t[0]:g} .. {t[-1]:g} s; contacts per "
                     f"snapshot {int(count.min())} .. {int(count.max())}"
                     + (f"; solid fraction {phi[0]:.3f} .. {phi[-1]:.3f}" if phi is not None else ""))
        if "eps_1" in facts:
            q_over_p = facts["q_over_p"]
            finite = q_over_p[np.isfinite(q_over_p)]
            lines.append(f"strain reached: eps_1 {facts['eps_1']:.3f}, eps_q {facts['eps_q']:.3f}"
                         + (f"; q/p {finite.min():.3f} .. {finite.max():.3f}, last {q_over_p[-1]:.3f}"
                            if finite.size else ""))

    def number(key, scale=1.0):
        try:
            return float(a[key]) * scale
        except (KeyError, TypeError, ValueError):  # absent, or "none"
            return None

    settings = [f"scene {a['scene']}"] if "scene" in a else []
    for key, scale, text in (("sigma0_Pa", 1e-3, "sigma0 {:g} kPa"), ("wall_velocity_m_s", 100, "top wall {:g} cm/s")):
        if number(key) is not None:
            settings.append(text.format(number(key, scale)))
    if "preparation_name" in a:
        settings.append(f"preparation {a['preparation_name']} (seed {a.get('preparation_seed', '?')})")
    if settings:
        lines.append("test: " + ", ".join(settings))
    solver = []
    if number("solver_friction") is not None:
        solver.append(f"friction {number('solver_friction'):g} (walls {number('solver_wall_friction') or 0:g})")
    for key, scale, text in (("solver_time_step", 1e3, "time step {:g} ms"),
                             ("solver_tolerance", 1, "NLGS tolerance {:.2g}"),
                             ("solver_alert", 1e3, "alert distance {:.3g} mm"),
                             ("near_contacts_m", 1e3, "near contacts written up to {:.3g} mm")):
        if number(key) is not None:
            solver.append(text.format(number(key, scale)))
    if solver:
        lines.append("solver: " + ", ".join(solver))
    lines.append(f"{len(a)} global attributes (--attrs lists them)")
    return lines
