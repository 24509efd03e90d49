"""A reader's summary of a dataset of the contract, in a few lines: what ``grainview info``
prints and what the report's index says of each run."""

from __future__ import annotations

import numpy as np


def describe(ds) -> list:
    """A reader's summary of a dataset of the contract: size and shapes, snapshots, strain and
    q/p reached, and the settings a physicist asks for first, in readable units."""
    a = ds.attrs
    n_vertices = ds["n_vertices"].values
    shapes = {int(k): int((n_vertices == k).sum()) for k in sorted(set(n_vertices.tolist()))}
    lines = [f"{ds.sizes['particle']} particles ("
             + ", ".join(f"{c} {'disks' if k == 0 else f'{k}-gons'}" for k, c in shapes.items())
             + f"), {ds.sizes.get('wall', 0)} walls, {ds.sizes['contact']} contact slots"]
    snapshots = ds.sizes.get("time", 0)
    if snapshots:
        t = ds["time"].values
        count = ds["contact_count"].values
        phi = ds.grain.solid_fraction().values if "box_min" in ds else None
        lines.append(f"{snapshots} snapshot{'s' * (snapshots > 1)}, t = {t[0]:g} .. {t[-1]:g} s; contacts per "
                     f"snapshot {int(count.min())} .. {int(count.max())}"
                     + (f"; solid fraction {phi[0]:.3f} .. {phi[-1]:.3f}" if phi is not None else ""))
        if "box_min" in ds and snapshots > 1:
            eps = ds.grain.strains()
            q_over_p = ds.grain.stress_invariants()["q_over_p"].values
            finite = q_over_p[np.isfinite(q_over_p)]
            lines.append(f"strain reached: eps_1 {float(eps['eps_1'][-1]):.3f}, eps_q {float(eps['eps_q'][-1]):.3f}"
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
