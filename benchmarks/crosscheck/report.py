"""The cross-check's report: RESULTS.md (settings, summary, window means, checks, iteration
budgets) and crosscheck.png, from the runs' contract files through ``analyse.py``."""

from __future__ import annotations

import os

from benchmarks.crosscheck import analyse

LABELS = {"project": "project", "box2d": "Box2D", "pymunk": "pymunk"}
STYLES = {"project": "-", "Box2D": "--", "pymunk": ":"}
COLOURS = {"pentagon": "tab:red", "disk": "tab:blue"}


def fmt(x, digits=3):
    """A number with ``digits`` decimals, or a dash for None/NaN."""
    return "–" if x is None or x != x else f"{x:.{digits}f}"


def write_report(args, jobs, sigma0, record, out_dir, reused_by=None):
    """Analyse every run and write RESULTS.md and crosscheck.png into ``out_dir``. ``sigma0``
    maps each shape to its sample's confining stress (Pa); ``record`` is the run's record
    (``run.run_record``: command, machine, wall time); ``reused_by``: the command line that
    regenerated the report from existing runs (``--reuse``), if any."""
    import platform

    from benchmarks.common import markdown_table

    os.makedirs(out_dir, exist_ok=True)
    data = {job.out: analyse.series(job.out) for job in jobs}
    main_runs = {(job.shape, LABELS[job.engine]): data[job.out] for job in jobs if not job.doubled}
    analyse.figure(main_runs, os.path.join(out_dir, "crosscheck.png"), STYLES, COLOURS, sigma0)

    versions = {job.engine: job.meta.get("version", "?") for job in jobs}
    lines = [
        "# Cross-check: one biaxial test in three engines", "",
        record["machine"] + " Peers: " + ", ".join(f"{LABELS[e]} {v}" for e, v in versions.items()
                                                   if e != "project") + ".", "",
        f"Command (wall time {record['wall_s'] / 60:.1f} min in all):", "", "```", record["command"], "```", "",
        *([f"This report was regenerated from that command's runs by `{reused_by}`.", ""] if reused_by else []),
        "Read with `benchmarks/crosscheck/__main__.py`'s docstring (protocol) and `export.py` (contract conventions). "
        f"Samples: {args.particles} particles, seed {args.seed}, compacted by `grainview run isotropic` under "
        "sigma0 = 10 kPa; every engine starts from the same last snapshot (positions, angles, velocities, walls) "
        f"and shears it to eps_1 = {args.strain:g} with a snapshot every {args.every} steps (dt = 5e-4 s, top wall "
        "0.01 m/s down, sigma0 h (1 m) on the right wall, friction 0.4 between grains, 0 on walls, zero gravity).", "",
        "Engine settings:", "",
        "- project: `solver.load_sample` + `solver.biaxial_test`, the solver's defaults (NLGS to the tolerance "
        "1.7e-4, at most 2000 sweeps, theta = 0.5, alert 2% of the smallest diameter).",
        f"- Box2D {versions.get('box2d', '')}: units of 2.5 cm (lengths, velocities, forces scaled; masses in kg), "
        f"{args.box2d[0]} velocity and {args.box2d[1]} position iterations per step, warm starting, no sleeping, no "
        "continuous collision; polygon cores shrunk by Box2D's 0.25 mm skin so that the edges are the sample's; "
        "top wall a kinematic body; right wall a dynamic body (the sample's wall mass, fixed rotation) on a "
        "prismatic joint along x, `ApplyForceToCenter` every step; friction mixed by geometric mean (grains 0.4, "
        "walls 0).",
        f"- pymunk {versions.get('pymunk', '')}: SI units, {args.pymunk_iterations} iterations per step, "
        "collision_slop 1e-5 m, default collision_bias; top wall kinematic; right wall a dynamic body (wall mass, "
        "infinite moment) on a `GrooveJoint` along x, `body.force` set every step; friction mixed by product "
        "(grains sqrt(0.4), walls 0).",
        "- Masses and moments of inertia are the sample's in every engine. Contacts: one entry per body pair, "
        "resultant force of its points; kind 2 (double) when the engine's manifold has two points "
        "(Box2D `pointCount == 2`, pymunk two points in `contact_point_set`; the project: its edge-to-edge test).", "",
    ]
    # summary: the residual strength of each shape across the engines
    residual = {shape: [analyse.residual_q_over_p(data[job.out]) for job in jobs
                        if job.shape == shape and not job.doubled] for shape in args.shapes}
    crossing = [c for c in (float(d["eps_1"].where(d["eps_q"] >= 0.5).min()) for d in data.values()) if c == c]
    crossing = crossing or [float("nan")]  # a short test may not reach eps_q = 0.5
    final = [float(d["eps_q"].isel(time=-1)) for d in data.values()]
    lines += ["## Summary", "",
              "Residual q/p (mean over eps_q >= 0.2 to the end of the test) across the engines: " + "; ".join(
                  f"{shape}s {min(v):.3f}–{max(v):.3f}" for shape, v in residual.items()) + ".", "",
              "Notes. (1) k_d counts the pairs each engine marks double, by different tests (this solver: "
              "near-parallel edges within its alert distance, loaded at one point or two; Box2D and pymunk: two "
              "overlapping manifold points); k_d2 applies one definition (both points loaded) to every engine. "
              "(2) Box2D keeps overlaps of up to its linear slop (0.125 mm here) and creates a contact only once "
              "shapes overlap, so its pentagon sample (whose polygons start just touching) first settles by "
              "about a millimetre (eps_q starts slightly negative, the stress builds up over the first ~100 "
              "steps); its polygons' rounded corners add ~0.06 mm at vertex contacts: hence its larger "
              f"overlaps. (3) The samples dilate strongly: eps_q passes 0.5 at eps_1 = {min(crossing):.2f}–"
              f"{max(crossing):.2f} and ends at {min(final):.2f}–{max(final):.2f}; the figure shows the whole "
              "test.", ""]
    # the table
    rows = []
    for shape in args.shapes:
        for lo_hi in analyse.WINDOWS:
            for job in jobs:
                if job.shape != shape or job.doubled:
                    continue
                row = next(r for r in analyse.window_means(data[job.out]) if r["window"] == lo_hi)
                rows.append([shape, f"{lo_hi[0]:.1f}–{lo_hi[1]:.1f}", LABELS[job.engine], row["snapshots"],
                             *(fmt(row[q]) for q in analyse.QUANTITIES)])
    lines += ["## Means per eps_q window", "",
              "Means over the snapshots whose eps_q lies in the window (the initial snapshot left out); "
              "q/p from the stress of all contacts (walls included), a, a_n, a_t (signed), z (rattlers "
              "excluded) and k_d (pairs of kind 2) from the particle pairs, all by the project's accessors; "
              "k_d2: the share of loaded particle pairs whose two points both carry force (from "
              "`normal_impulse`, the same definition for every engine; see `analyse.py`). "
              "Figure: [crosscheck.png](crosscheck.png).", "",
              markdown_table(["shape", "eps_q", "engine", "snapshots", "q/p", "a", "a_n", "a_t", "z", "k_d", "k_d2"],
                             rows), ""]
    # checks
    rows = []
    for job in jobs:
        s = data[job.out]
        c = analyse.checks(s, sigma0[job.shape])
        steps = job.meta.get("n_steps", float("nan"))
        rows.append([job.shape, LABELS[job.engine] + (" x2" if job.doubled else ""), job.settings,
                     fmt(analyse.residual_q_over_p(s)),
                     f"{c['sxx'][0]:.3f} ({c['sxx'][1]:.2f}–{c['sxx'][2]:.2f})", fmt(c.get("right")),
                     fmt(c["p0"]), fmt(c["eps_1"]), fmt(c["eps_q"]), f"{1e3 * c.get('dx', float('nan')):.1f}",
                     f"{100 * c.get('overlap', float('nan')):.2f}", f"{job.wall_s:.0f}",
                     f"{1e3 * job.wall_s / steps:.1f}"])
    lines += ["## Checks and timings", "",
              "Residual q/p: the mean q/p over eps_q >= 0.2 to the end of the test (the plateau). "
              "sigma_xx/sigma0: the horizontal stress from the contacts (the accessors' stress tensor) over sigma0, "
              "mean (min–max) over the sheared snapshots; right wall: the particles' mean force on the right wall "
              "over h (1 m) and sigma0 (its momentum balance against the applied force). p/sigma0 at the first "
              "sheared snapshot (isotropic start). p itself grows with the shear: p = sigma0/(1 - q/p) once "
              "sigma_xx = sigma0. dx: the right wall's displacement (mm, > 0 outward). Overlap: the largest "
              "interpenetration over the run, by this project's narrow phase, in % of the smallest diameter. "
              "Wall time: the whole run (peers: with the export), on a machine shared with other work.", "",
              markdown_table(["shape", "engine", "settings", "residual q/p", "sigma_xx/sigma0", "right wall/sigma0",
                              "p0/sigma0",
                              "eps_1", "eps_q", "dx (mm)", "overlap (% d)", "wall time (s)", "ms/step"], rows), ""]
    # iteration check
    if args.check_iterations:
        rows = []
        for shape in args.shapes:
            for engine in ("box2d", "pymunk"):
                pair = [j for j in jobs if j.shape == shape and j.engine == engine]
                if len(pair) != 2:
                    continue
                base, doubled = (analyse.residual_q_over_p(data[j.out]) for j in pair)
                rows.append([shape, LABELS[engine], pair[0].settings, fmt(base), pair[1].settings, fmt(doubled),
                             fmt(doubled - base)])
        if rows:
            lines += ["## Iteration budgets", "",
                      "Residual q/p (mean over eps_q >= 0.2 to the end of the test) with the peers' iteration "
                      "budget and with twice that budget; the budget is enough when the change stays below "
                      "~0.02, bearing in mind that a 400-particle sample's residual q/p also moves by a few "
                      "hundredths between runs that differ by any detail (see the spread between engines).", "",
                      markdown_table(["shape", "engine", "budget", "q/p", "doubled", "q/p", "change"], rows), ""]
    lines += [f"Written by `python -m benchmarks.crosscheck` on {platform.node() or 'this machine'}; the runs are "
              f"under `benchmarks/_data/crosscheck/runs/` (not committed).", ""]
    with open(os.path.join(out_dir, "RESULTS.md"), "w") as fh:
        fh.write("\n".join(lines))
