"""The fidelity study: which preparation and counting reproduce which of the paper's values.

    python -m benchmarks.fidelity                      # every section (hours on 2 cores)
    python -m benchmarks.fidelity --only relations     # the twelve relations
    python -m benchmarks.fidelity --quick              # tiny sizes: checks the script
    python -m benchmarks.fidelity --large              # adds 4000 particles to 'sizes'
    python -m benchmarks.fidelity --large pentagon     # ... of one shape only
    python -m benchmarks.fidelity --only periodic --large   # periodic cells beside walls

Sections (each a table in ``benchmarks/fidelity/RESULTS.md``, read with docs/fidelity.md):

* ``preparations``: initial states (solid fraction, z) of each preparation, both shapes;
* ``rates``: q/p, a, z against the top wall's speed (is the test quasi-static?);
* ``sizes``: residual values at 400 and 1000 particles (and 4000 with ``--large``);
* ``counting``: z, very weak fraction, fabric a with near pairs counted up to a gap;
* ``relations``: the paper's twelve pentagon-versus-disk relations, N = 1000, eps_q >= 0.4,
  three seeds (mean ± spread), per preparation and counting convention;
* ``periodic``: the same compacted samples sheared in their biperiodic cell (no walls) beside
  their biaxial test between walls, N = 1000, three seeds (and 4000 with ``--large``), with
  the twelve relations of the periodic runs.

Runs are cached in ``benchmarks/_data/fidelity`` (``runs.py``), so sections share them and a
second call only recomputes the tables.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.fidelity import figures, measure, relations
from benchmarks.fidelity import runs as runs_module
from benchmarks.fidelity.runs import Run, ensure

SECTIONS = ["preparations", "rates", "sizes", "counting", "relations", "periodic"]
D_MIN = 0.025  # m, the smallest circumscribed diameter of the paper's size mix
NEAR = (0.0025, 0.005, 0.01, 0.02)
"""Near-contact gap thresholds as fractions of D_MIN (0.02 = the solver's alert distance)."""
RELATION_NEAR = 0.01
"""The near-contact threshold (fraction of D_MIN) of the relations' second counting column."""
RESIDUAL = (0.4, np.inf)
"""Residual window of the sizes, counting and relations sections (eps_q)."""


class Config:
    """Sizes of every section; ``quick`` shrinks them to check the script in minutes."""

    def __init__(self, quick=False, large=()):
        self.quick = quick
        self.large_shapes = tuple(large)
        """Shapes that the sizes section also runs at 4000 particles."""
        self.strain = 0.02 if quick else 0.2
        self.residual = (0.0, np.inf) if quick else RESIDUAL
        self.relation_particles = 60 if quick else 1000
        self.seeds = (0, 1) if quick else (0, 1, 2)
        self.preparation_particles = (60,) if quick else (400, 1000)
        self.preparations = (("paper", "frictionless") if quick else
                             ("paper", "frictionless", "quasistatic", "mu0.1", "mu0.2"))
        self.rate_particles = 60 if quick else 400
        self.velocities = {"pentagon": (0.01, 0.04) if quick else (0.005, 0.01, 0.02, 0.04, 0.08),
                           "disk": (0.01, 0.04) if quick else (0.01, 0.02, 0.04, 0.08)}
        self.sizes = (30, 60) if quick else (400, 1000)
        self.every = 20 if quick else 400
        self.shear_strain = 0.04 if quick else 0.8
        """gamma at the end of the periodic shears (the biaxial tests reach eps_q ~0.6)."""

    def velocity(self, particles):
        """Top-wall speed (m s-1) that shears ``particles`` at the study's strain rate: the rate
        of 400 particles at the paper's 1 cm/s, about 0.01 s-1 (the box height grows as the
        square root of N at a fixed aspect ratio), rounded to 1 mm/s."""
        return round(0.01 * np.sqrt(particles / 400), 3)

    def run(self, **kw) -> Run:
        """A :class:`Run` with this configuration's defaults; a test faster than the study's
        strain rate writes snapshots proportionally more often, so that every test has about
        as many snapshots per unit of strain."""
        kw.setdefault("strain", self.strain)
        kw.setdefault("velocity", self.velocity(kw.get("particles", Run.particles)))
        reference = self.velocity(kw.get("particles", Run.particles))
        kw.setdefault("every", max(1, round(self.every * min(1.0, reference / kw["velocity"]))))
        return Run(**kw)


def _table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _f(value, digits=3):
    return "-" if value is None or (isinstance(value, float) and not np.isfinite(value)) else f"{value:.{digits}f}"


# -- sections -----------------------------------------------------------------------------------

def section_preparations(cfg, jobs):
    runs = [cfg.run(shape=shape, particles=n, preparation=prep, seed=seed)
            for n in cfg.preparation_particles for prep in cfg.preparations for shape in ("pentagon", "disk")
            for seed in (cfg.seeds if n == cfg.preparation_particles[0] else cfg.seeds[:1])]
    from benchmarks.fidelity.runs import make_sample
    from concurrent.futures import ProcessPoolExecutor

    missing = [r for r in runs if not os.path.exists(r.sample_path())]
    if missing:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(make_sample, missing))
    rows, points = [], []
    near = 0.01 * D_MIN
    frictions = {"paper": 0.4, "quasistatic": None, "frictionless": 0.0, "mu0.1": 0.1, "mu0.2": 0.2}
    for r in runs:
        s = measure.initial_state(r.sample_path(), near=near)
        if frictions.get(r.preparation) is not None and r.particles == cfg.preparation_particles[0]:
            points.append({"shape": r.shape, "friction": frictions[r.preparation], **s})
        rows.append([r.shape, r.particles, r.preparation, r.seed, _f(s["solid fraction"]), _f(s["z"], 2),
                     _f(s["z near"], 2), _f(s["z points"], 2), _f(s["k_d"], 2), s["compaction steps"],
                     "yes" if s["settled"] else "NO", f"{s['largest I']:.1e}", _f(s["compaction s"], 0)])
    text = ("Initial states after isotropic compaction at 10 kPa (paper: S1 pentagons solid fraction 0.80, "
            "z 3.20; S2 disks 0.82, z 3.95). Preparations: 'paper' compacts with the test's friction 0.4, walls "
            "closing at up to 5 cm/s; 'frictionless' with friction 0; 'mu0.1', 'mu0.2' with friction 0.1, 0.2; "
            "'quasistatic' as 'paper' with the closing walls capped at I = 2e-4. z: force-bearing contacts (the paper's rule); z near: also the "
            f"pairs within {near * 1e3:g} mm (1% of the smallest diameter); z points: a double contact counts "
            "twice; largest I: the largest inertia number I = (v/L) d sqrt(rho/sigma0) of a closing wall.\n\n")
    figure = figures.preparations(points, figures.figure_path(cfg.output, "preparations"))
    return (text + f"![initial states]({os.path.basename(figure)})\n\n"
            + _table(["shape", "N", "preparation", "seed", "solid fraction", "z", "z near", "z points", "k_d",
                      "steps", "settled", "largest I", "time (s)"], rows))


def _window(w):
    return f"{w[0]:.1f}+" if w[1] == np.inf else f"{w[0]:.1f}-{w[1]:.1f}"


def _windows(path, windows, near=None):
    return [measure.window_means(path, w, near) for w in windows]


def section_rates(cfg, jobs):
    runs = [cfg.run(shape=shape, particles=cfg.rate_particles, velocity=v, every=cfg.every)
            for shape in ("pentagon", "disk") for v in cfg.velocities[shape]]
    paths = ensure(runs, jobs)
    windows = [(0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, np.inf)] if not cfg.quick else [(0.0, np.inf)]
    rows = []
    for r in runs:
        import grainview

        with grainview.open_dataset(paths[r], chunks=None) as ds:
            inertia = float(ds.grain.inertia_number().median())
        for w, s in zip(windows, _windows(paths[r], windows)):
            if s["snapshots"]:
                rows.append([r.shape, f"{r.velocity * 100:g}", f"{inertia:.1e}", _window(w), s["snapshots"],
                             _f(s["q/p"]), _f(s["a"]), _f(s["a_n"]), _f(s["z"], 2), _f(s["solid fraction"])])
    text = (f"Biaxial tests of the same compacted {cfg.rate_particles}-particle samples (preparation 'paper', seed 0) "
            "with the top wall at several speeds; window means over eps_q. I: the median inertia parameter of "
            "the test as the paper defines it (eps_dot sqrt(m/p), m the total mass per unit thickness). Every test "
            f"writes a snapshot every {cfg.every} steps, so the faster tests have fewer snapshots per window.\n\n")
    curves = [(f"{r.shape}s, {r.velocity * 100:g} cm/s", r.shape, measure.strain_series(paths[r])) for r in runs]
    figure = figures.evolutions(curves, figures.figure_path(cfg.output, "rates"),
                                f"{cfg.rate_particles} particles, seed 0: top wall speed")
    return (text + f"![wall speeds]({os.path.basename(figure)})\n\n"
            + _table(["shape", "wall speed (cm/s)", "I", "eps_q", "snapshots", "q/p", "a", "a_n", "z", "solid fraction"], rows))


def section_sizes(cfg, jobs):
    runs = [cfg.run(shape=shape, particles=n) for n in cfg.sizes for shape in ("pentagon", "disk")]
    runs += [cfg.run(shape=shape, particles=4000) for shape in cfg.large_shapes]
    paths = ensure(runs, jobs)
    rows = []
    windows = [(0.3, 0.4), cfg.residual] if not cfg.quick else [cfg.residual]
    for r in runs:
        for w, s in zip(windows, _windows(paths[r], windows)):
            if s["snapshots"]:
                checks = measure.boundary_checks(paths[r], w)
                rows.append([r.shape, r.particles, _window(w),
                             s["snapshots"], _f(s["q/p"]), _f(checks["q/p central"]), checks["central particles"],
                             _f(checks["q/p walls"]), _f(s["prediction"]), _f(s["prediction cross"]),
                             _f(s["a"]), _f(s["a_n"]),
                             _f(s["a_t"]), _f(s["z"], 2), _f(s["k_d"], 2), _f(s["very weak"])])
    sizes = sorted({r.particles for r in runs})
    speeds = ", ".join(f"{cfg.velocity(n) * 100:g} cm/s for {n}" for n in sizes[1:])
    text = ("Residual values against the number of particles (preparation 'paper', seed 0, force-bearing "
            f"contacts), all sheared at the same strain rate (~0.01 s-1: the top wall at "
            f"{cfg.velocity(sizes[0]) * 100:g} cm/s for {sizes[0]} particles, {speeds}). Paper: "
            "N = 14,400 pentagons (q/p 0.35, z 3.75) and 10,000 disks "
            "(q/p 0.28, z 3.85). q/p central: the stress of the particles farther than three largest diameters "
            "from every wall; q/p walls: from the wall forces alone (measure.boundary_checks).\n\n")
    curves = [(f"{r.shape}s, N = {r.particles}", r.shape, measure.strain_series(paths[r])) for r in runs]
    figure = figures.evolutions(curves, figures.figure_path(cfg.output, "sizes"),
                                "Number of particles (same strain rate, seed 0)")
    return (text + f"![sizes]({os.path.basename(figure)})\n\n"
            + _table(["shape", "N", "eps_q", "snapshots", "q/p", "q/p central", "central particles", "q/p walls",
                      "(a'+a_n+a_t)/2", "(a'+a_n+a_t)/(2+a'a_n)",
                      "a", "a_n", "a_t", "z", "k_d",
                      "very weak"], rows))


def _relation_runs(cfg, preparation="paper"):
    return {shape: [cfg.run(shape=shape, particles=cfg.relation_particles, preparation=preparation, seed=seed)
                    for seed in cfg.seeds] for shape in ("pentagon", "disk")}


def section_counting(cfg, jobs):
    groups = _relation_runs(cfg)
    paths = ensure([r for runs in groups.values() for r in runs], jobs)
    rows, points = [], []
    for shape, runs in groups.items():
        for near in (None, *NEAR):
            gap = None if near is None else near * D_MIN
            summaries = [measure.window_means(paths[r], cfg.residual, gap) for r in runs]
            points.append({"shape": shape, "near": near or 0.0,
                           **{k: relations.stats(summaries, k) for k in ("z", "very weak", "a")}})
            rows.append([shape, "force-bearing" if near is None else f"gap <= {near:.2%} d_min ({gap * 1e3:.2g} mm)",
                         relations.fmt(summaries, "z"), relations.fmt(summaries, "z points"),
                         relations.fmt(summaries, "very weak"), relations.fmt(summaries, "a'(very weak)"),
                         relations.fmt(summaries, "weak"),
                         relations.fmt(summaries, "a"), relations.fmt(summaries, "prediction"),
                         relations.fmt(summaries, "prediction cross"), relations.fmt(summaries, "q/p")])
    text = (f"Residual state (eps_q >= {cfg.residual[0]:g}) of {cfg.relation_particles} particles, "
            f"{len(cfg.seeds)} seeds (mean ± spread), preparation 'paper', counted four ways: force-bearing contacts only, "
            "or also every pair whose gap is within a threshold (written by the solver up to its alert distance, "
            f"2% of d_min = {0.02 * D_MIN * 1e3:g} mm). a' of very weak: the signed fabric anisotropy of the "
            "contacts with f_n < 0.1 <f_n> (negative: across the major principal stress). Paper (pentagons): "
            "z 3.75, very weak 0.32 with a' < 0, weak 0.58, a small; (disks): z 3.85, weak 0.62, a ~0.3.\n\n")
    figure = figures.counting(points, figures.figure_path(cfg.output, "counting"))
    return (text + f"![counting]({os.path.basename(figure)})\n\n"
            + _table(["shape", "counted", "z", "z points", "very weak", "a' of very weak", "weak", "a",
                      "(a'+a_n+a_t)/2", "(a'+a_n+a_t)/(2+a'a_n)", "q/p"], rows))


def _summaries(cfg, runs, paths, near):
    out = []
    for r in runs:
        s = measure.window_means(paths[r], cfg.residual, near)
        s["solid fraction initial"] = measure.initial_state(r.sample_path())["solid fraction"]
        out.append(s)
    return out


RELATION_COLUMNS = [
    ("paper", "paper", None), ("paper", "paper", RELATION_NEAR),
    ("paper", "frictionless", None), ("paper", "frictionless", RELATION_NEAR),
]
"""(pentagons' preparation, disks' preparation, near-contact threshold as a fraction of D_MIN) of
each column: both shapes prepared alike, and the mix that gives the paper's S1 and S2 initial
states (pentagons compacted with friction, disks without; see the preparations section)."""


def _engine_summaries(cfg):
    """Per-shape summaries of the independent engines' runs of benchmarks/crosscheck (the largest
    iteration budget of each engine), when that command has been run; else {}."""
    import glob

    root = os.path.join(os.path.dirname(HERE), "_data", "crosscheck", "runs")
    out = {}
    for engine in ("box2d", "pymunk"):
        per_shape = {}
        for shape in ("pentagon", "disk"):
            files = sorted(glob.glob(os.path.join(root, f"{shape}400_seed0_strain0.2*_every*", f"{engine}_*.nc")))
            files = [f for f in files if os.path.isfile(f)]
            if not files:
                break
            best = max(files, key=lambda f: int("".join(c for c in os.path.basename(f).split("_")[1] if c.isdigit())))
            summary = measure.window_means(best, cfg.residual)
            summary["solid fraction initial"] = measure.initial_state(best)["solid fraction"]
            per_shape[shape] = ([summary], os.path.basename(best)[:-3])
        if len(per_shape) == 2:
            out[engine] = per_shape
    return out


def section_relations(cfg, jobs):
    groups = {prep: _relation_runs(cfg, prep) for prep in {p for column in RELATION_COLUMNS for p in column[:2]}}
    needed = [groups[p_prep]["pentagon"] + groups[d_prep]["disk"] for p_prep, d_prep, _ in RELATION_COLUMNS]
    paths = ensure([r for runs in needed for r in runs], jobs)
    columns = []
    for p_prep, d_prep, near in RELATION_COLUMNS:
        gap = None if near is None else near * D_MIN
        prep = f"'{p_prep}'" if p_prep == d_prep else f"P '{p_prep}', D '{d_prep}' (S1/S2)"
        label = f"{prep}, " + ("force-bearing" if near is None else f"near {near:.0%} d_min")
        results = relations.evaluate(_summaries(cfg, groups[p_prep]["pentagon"], paths, gap),
                                     _summaries(cfg, groups[d_prep]["disk"], paths, gap))
        columns.append((label, results))
    if not cfg.quick:
        for engine, per_shape in _engine_summaries(cfg).items():
            label = f"{engine} ({per_shape['pentagon'][1]}, 400 particles, 1 seed)"
            columns.append((label, relations.evaluate(per_shape["pentagon"][0], per_shape["disk"][0])))
    header = ["relation", "paper"] + [label for label, _ in columns]
    rows = []
    for k, (name, paper, *_rest) in enumerate(columns[0][1]):
        rows.append([name, paper] + [f"{'holds' if res[k][3] else 'FAILS'}: {res[k][2]}" for _, res in columns])
    held = "; ".join(f"{label}: {sum(r[3] for r in res)}/12" for label, res in columns)
    text = (f"N = {cfg.relation_particles} per shape, residual window eps_q >= {cfg.residual[0]:g}, seeds "
            f"{', '.join(map(str, cfg.seeds))} (mean ± sample standard deviation), top wall at "
            f"{cfg.velocity(cfg.relation_particles) * 100:g} cm/s (strain rate ~0.01 s-1). Columns: the preparation "
            "of each shape and the counting convention; the last columns, where present, are the independent "
            "engines of benchmarks/crosscheck on this solver's 400-particle samples. Relations that hold: "
            f"{held}.\n\n")
    return text + _table(header, rows)


def _spread(summaries, key, digits=3):
    values = np.array([s[key] for s in summaries], float)
    if values.size == 1:
        return _f(values[0], digits)
    return f"{values.mean():.{digits}f} ± {values.std(ddof=1):.{digits}f}"


PERIODIC_KEYS = [("q/p", 3), ("a", 3), ("a_n", 3), ("a_t", 3), ("z", 2), ("alpha", 2), ("very weak", 3),
                 ("solid fraction", 3)]
"""The residual descriptors of the periodic section's tables, with their digits."""


def section_periodic(cfg, jobs):
    n_large = 120 if cfg.quick else 4000
    sizes = [(cfg.relation_particles, cfg.seeds, ("pentagon", "disk"))]
    sizes += [(n_large, cfg.seeds[:1], cfg.large_shapes)] if cfg.large_shapes else []
    runs = {}
    for n, seeds, shapes in sizes:
        for shape in shapes:
            for seed in seeds:
                walled = cfg.run(shape=shape, particles=n, seed=seed)
                runs[(shape, n, seed)] = (walled, walled.with_(scene="shear", strain=cfg.shear_strain))
    paths = ensure([r for pair in runs.values() for r in pair], jobs)
    rows, summaries = [], {}
    for (shape, n, seed), pair in runs.items():
        for run in pair:
            s = measure.window_means(paths[run], cfg.residual)
            s["solid fraction initial"] = measure.initial_state(run.sample_path())["solid fraction"]
            scene = "periodic" if run.scene == "shear" else "walls"
            summaries.setdefault((shape, n, scene), []).append(s)
            if not s["snapshots"]:
                rows.append([shape, n, seed, scene, 0] + ["-"] * (len(PERIODIC_KEYS) + 1))
                continue
            p10, p90 = s["p 10-90%"]
            rows.append([shape, n, seed, scene, s["snapshots"]] + [_f(s[k], d) for k, d in PERIODIC_KEYS]
                        + [f"{s['p'] / 1e3:.1f} ({p10 / 1e3:.1f}-{p90 / 1e3:.1f})"])
    header = ["shape", "N", "seed", "test", "snapshots"] + [k for k, _ in PERIODIC_KEYS] + ["p kPa (10-90%)"]
    means = [[shape, n, scene, len(group)] + [_spread(group, k, d) for k, d in PERIODIC_KEYS]
             for (shape, n, scene), group in summaries.items() if all(g["snapshots"] for g in group)]
    n_rel = cfg.relation_particles
    relation_rows = []
    if all(summaries.get((shape, n_rel, scene)) for shape in ("pentagon", "disk") for scene in ("walls", "periodic")):
        walls = relations.evaluate(summaries[("pentagon", n_rel, "walls")], summaries[("disk", n_rel, "walls")])
        cells = relations.evaluate(summaries[("pentagon", n_rel, "periodic")], summaries[("disk", n_rel, "periodic")])
        for (name, paper, _c, held_w, *_), (_n, _p, _c2, held_p, *_r) in zip(walls, cells):
            relation_rows.append([name, paper, f"{'holds' if held_w else 'FAILS'}: {_c}",
                                  f"{'holds' if held_p else 'FAILS'}: {_c2}"])
    text = (f"Each compacted sample (preparation 'paper', friction 0.4, sigma0 10 kPa) tested twice: between walls "
            f"(the biaxial test, top wall at {cfg.velocity(n_rel) * 100:g} cm/s for {n_rel} particles"
            + (f", {cfg.velocity(n_large) * 100:g} cm/s for {n_large}" if cfg.large_shapes else "")
            + f") and in the biperiodic cell of its box, sheared to gamma = {cfg.shear_strain:g} under sigma_yy = "
            "sigma0 at gamma_dot = 2 v/h, the biaxial test's pace in eps_q (solver.periodic_shear."
            f"matching_shear_rate). Residual window: eps_q >= {cfg.residual[0]:g} between walls, |gamma| >= "
            f"{cfg.residual[0]:g} in the cell; force-bearing contacts; q/p from the stress tensor "
            "(minimum-image branches in the cell, wall contacts included between walls); p: the window's mean "
            "stress and its 10th-90th percentiles.\n\n")
    out = text + _table(header, rows) + "\n\nMeans ± sample standard deviation over the seeds:\n\n" + \
        _table(["shape", "N", "test", "seeds"] + [k for k, _ in PERIODIC_KEYS], means)
    if relation_rows:
        out += (f"\n\nThe twelve relations at N = {n_rel}, walls against periodic cell (seeds "
                f"{', '.join(map(str, cfg.seeds))}):\n\n"
                + _table(["relation", "paper", "walls", "periodic cell"], relation_rows))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fidelity", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, to check the script")
    parser.add_argument("--only", default=",".join(SECTIONS), help="comma-separated sections: " + ",".join(SECTIONS))
    parser.add_argument("--large", nargs="?", const="pentagon,disk", default="",
                        help="add 4000 particles of these shapes (default both) to the sizes section "
                        "(about 2-2.5 h per pentagon test on one core)")
    parser.add_argument("--jobs", type=int, default=2, help="simulations run side by side (default 2)")
    parser.add_argument("--output", default=None, help="default: benchmarks/fidelity/RESULTS.md for a full run, "
                        "benchmarks/_data/fidelity/RESULTS-*.md otherwise")
    args = parser.parse_args(argv)
    wanted = [s.strip() for s in args.only.split(",") if s.strip()]
    unknown = set(wanted) - set(SECTIONS)
    if unknown:
        parser.error(f"unknown sections {sorted(unknown)}; expected some of {SECTIONS}")
    large = [s.strip() for s in args.large.split(",") if s.strip()]
    if set(large) - {"pentagon", "disk"}:
        parser.error(f"--large {args.large}: expected pentagon, disk or both")
    cfg = Config(quick=args.quick, large=large)
    if args.quick:
        runs_module.CACHE = os.path.join(runs_module.CACHE, "quick")
    output = args.output or (os.path.join(HERE, "RESULTS.md") if not args.quick and wanted == SECTIONS
                             else os.path.join(runs_module.CACHE, f"RESULTS-{'quick-' if args.quick else ''}{'-'.join(wanted)}.md"))
    os.makedirs(os.path.dirname(output), exist_ok=True)
    cfg.output = output
    from benchmarks.common import machine_description

    start = time.perf_counter()
    parts = ["# Fidelity study", "", f"Generated by `python -m benchmarks.fidelity"
             f"{' --quick' if args.quick else ''}{' --large ' + ','.join(large) if large else ''}"
             f"{'' if wanted == SECTIONS else ' --only ' + ','.join(wanted)}`; "
             "read with docs/fidelity.md.", "", machine_description(), ""]
    for name in wanted:
        print(f"== {name}", flush=True)
        t0 = time.perf_counter()
        text = globals()[f"section_{name}"](cfg, args.jobs)
        parts += [f"## {name}", "", text, "", f"_Section time: {time.perf_counter() - t0:.0f} s._", ""]
        with open(output, "w") as fh:
            fh.write("\n".join(parts) + "\n")
    print(f"wrote {output} in {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
