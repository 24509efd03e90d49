"""What the stress-controlled right wall does while a walled biaxial test's stress swings.

For each walled test file (``solver.biaxial_test``: the top wall driven at a speed, the right
wall pushed by sigma0 with the mass the file records) and the snapshots of its residual window
(eps_q >= ``--window``), the table gives

* the right wall's mass M in units of the sample's, and its free-flight time
  t_w = sqrt(M d / (sigma0 H)) (d the mean diameter, H the height: the time sigma0 alone takes
  to move the wall by a diameter, from rest; the time a wall left behind by a collapse of the
  sample takes to catch up with it), in ms and in time steps;
* sigma_xx / sigma0 from the contacts (``ds.grain.stress_tensor``) and the grains' stress on
  the right wall (its force over its length) / sigma0: the share of snapshots below one half;
* the right wall's velocity u (outward positive, in units of the top wall's speed; the sample
  dilates, so u is positive on average): its spread (10th and 90th percentiles) and, for the
  snapshots whose wall stress is below one half, the share with u above its median: a wall
  that the sample pushed out keeps moving out after the push, the grains losing contact with
  it, while sigma0 alone slows it down;
* p across the sample: the coarse-grained contact stress (``ds.grain.coarse_grained``, width one
  mean diameter) over the left, middle and right thirds of the box's width (:func:`thirds_p`); the
  median and 90th percentile over the snapshots of max/min of the three, and its median over
  the snapshots whose sigma_xx is below sigma0/2.

    python -m benchmarks.wall_motion                 # the walled tests of benchmarks/_data/fidelity/runs
    python -m benchmarks.wall_motion FILE [FILE ...] [--labels A,B] [--window 0.4]
    python -m benchmarks.wall_motion CARRY/pentagons.measures.nc   # a test carried over sittings
    python -m benchmarks.wall_motion --quick         # two short tests of 60 pentagons, printed only

It only reads the files, or a test's measures (``benchmarks.fidelity.measure.snapshot_measures``,
which hold :func:`wall_series`: the same numbers); benchmarks/results/wall-motion.md holds a run.
"""

from __future__ import annotations

import argparse
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "wall-motion.md")


def thirds_p(ds) -> np.ndarray:
    """p (Pa) of the left, middle and right thirds of the box's width, per snapshot (time, 3):
    the coarse-grained contact p (width and spacing one mean diameter) integrated over the
    grid's columns of each third, the outer thirds taking what the kernels spill past the side
    walls and every third what they spill past the top and bottom, over the third's area. The
    three thirds' mean is then the whole sample's contact p, up to the grid's quadrature."""
    from grainview.analysis.coarse_graining import field_invariants, mean_diameter

    d = mean_diameter(ds)
    fields = ds.grain.coarse_grained(width=d, spacing=d)
    p = np.nan_to_num(field_invariants(fields, stress="contact")["p"].values)  # (time, y, x)
    x, y = fields["x"].values, fields["y"].values
    cell = float(np.diff(x[:2])[0] * np.diff(y[:2])[0])
    lo, hi = ds["box_min"].values, ds["box_max"].values
    out = np.empty((ds.sizes["time"], 3))
    for k in range(ds.sizes["time"]):
        width, height = hi[k] - lo[k]
        edges = lo[k, 0] + width * np.array([1, 2]) / 3
        third = np.digitize(x, edges)  # 0, 1, 2: left, middle, right
        columns = p[k].sum(axis=0) * cell
        out[k] = [columns[third == t].sum() / (width * height / 3) for t in range(3)]
    return out


def check_walled(ds, source) -> int:
    """The right wall's index in a walled biaxial test's dataset; ValueError in one line otherwise."""
    walls = [str(w) for w in ds["wall"].values] if "wall" in ds else []
    if ds.attrs.get("scene", "biaxial") != "biaxial" or "right" not in walls:
        raise ValueError(f"{source}: scene {ds.attrs.get('scene', 'unknown')}, walls {walls or 'none'}; expected a "
                         "walled biaxial test (solver.biaxial_test)")
    return walls.index("right")


def wall_series(ds, source="the dataset") -> dict:
    """Per snapshot of a walled biaxial test's dataset, arrays over ``time``: sigma_xx / sigma0
    from the contacts, the grains' stress on the right wall / sigma0, the right wall's velocity
    / the top wall's speed (outward positive), and p (Pa) of the left, middle and right thirds
    (:func:`thirds_p`)."""
    right = check_walled(ds, source)
    sigma0 = float(ds.attrs["sigma0_Pa"])
    height = (ds["box_max"] - ds["box_min"]).values[:, 1]
    thirds = thirds_p(ds)
    return {"sigma_xx_over_sigma0": ds.grain.stress_tensor().values[:, 0, 0] / sigma0,
            "right_wall_stress_over_sigma0":
                ds["wall_force"].values[:, right, 0] / (height * float(ds.attrs["thickness_m"])) / sigma0,
            "right_wall_velocity_over_v": ds["wall_velocity"].values[:, right, 0] / float(ds.attrs["wall_velocity_m_s"]),
            "p_left": thirds[:, 0], "p_middle": thirds[:, 1], "p_right": thirds[:, 2]}


def wall_constants(ds, source="the dataset") -> dict:
    """A walled biaxial test's right wall: its mass / the sample's, its free-flight time t_w (s,
    module docstring; H the box's height at the test's first snapshot, the dataset's), the
    time step (s), and the test's inertia number in the paper's definition at its start,
    I = (v / H) sqrt(m / (sigma0 t)) (m the particles' mass, t the slab's thickness)."""
    from grainview.analysis.coarse_graining import mean_diameter

    right = check_walled(ds, source)
    mass = float(np.asarray(ds.attrs["wall_mass_kg"])[right])
    height0 = float(ds["box_max"].values[0, 1] - ds["box_min"].values[0, 1])
    sigma0, thickness, sample = float(ds.attrs["sigma0_Pa"]), float(ds.attrs["thickness_m"]), float(ds["mass"].sum())
    flight = mass * mean_diameter(ds) / (sigma0 * thickness * height0)
    inertia = float(ds.attrs["wall_velocity_m_s"]) / height0 * np.sqrt(sample / (sigma0 * thickness))
    return {"right_wall_mass_ratio": mass / sample, "t_w": float(np.sqrt(flight)),
            "time_step": float(ds.attrs["solver_time_step"]), "inertia_number_start": float(inertia)}


def _named(source) -> str:
    return os.fspath(source) if isinstance(source, (str, os.PathLike)) else "the measures"


def wall_motion(source, window=0.4) -> dict:
    """The numbers of the module docstring for one walled test: its file, or its measures
    (:func:`benchmarks.fidelity.measure.snapshot_measures`, which hold :func:`wall_series`)."""
    from benchmarks.fidelity.measure import snapshot_measures

    if isinstance(source, (str, os.PathLike)):
        import grainview

        with grainview.open_dataset(source, chunks=None) as ds:
            check_walled(ds, source)  # before measuring: one line for a file of another scene
        m = snapshot_measures(source)
    else:
        m = source
    if "sigma_xx_over_sigma0" not in m:
        raise ValueError(f"{_named(source)}: no right wall "
                         "measured; expected a walled biaxial test (solver.biaxial_test)")
    keep = np.flatnonzero(m["eps_q"].values >= window)
    if not keep.size:
        raise ValueError(f"{_named(source)}: no snapshot with eps_q >= {window:g} (its largest is {m.attrs['eps_q_max']:.3g}); "
                         "expected a lower --window")
    res = m.isel(time=keep)
    sxx, wall = res["sigma_xx_over_sigma0"].values, res["right_wall_stress_over_sigma0"].values
    u = res["right_wall_velocity_over_v"].values
    thirds = np.stack([res[f"p_{t}"].values for t in ("left", "middle", "right")], axis=1)
    low = wall < 0.5
    ratio = thirds.max(axis=1) / thirds.min(axis=1)
    return {"particles": int(m.attrs["particles"]), "velocity": float(m.attrs["velocity"]),
            "mass ratio": float(m.attrs["right_wall_mass_ratio"]), "t_w": float(m.attrs["t_w"]),
            "time step": float(m.attrs["time_step"]),
            "snapshots": len(keep), "sxx<1/2": float(np.mean(sxx < 0.5)), "wall<1/2": float(np.mean(low)),
            "u10": float(np.percentile(u, 10)), "u90": float(np.percentile(u, 90)),
            "out|low": float(np.mean(u[low] > np.median(u))) if low.any() else np.nan,
            "thirds50": float(np.median(ratio)), "thirds90": float(np.percentile(ratio, 90)),
            "thirds|low": float(np.median(ratio[sxx < 0.5])) if (sxx < 0.5).any() else np.nan,
            "wall": wall, "sxx": sxx}


HEADER = ["sample", "N", "v (cm/s)", "M / sample", "t_w (ms, steps)", "snapshots", "sigma_xx < sigma0/2",
          "wall < sigma0/2", "u 10-90% (of v)", "u above its median when wall < 1/2",
          "p thirds max/min: median, 90%, median when sigma_xx < 1/2"]


def row(label, r) -> list:
    """The table's cells (:data:`HEADER`) for the numbers ``r`` of :func:`wall_motion`."""
    out = "-" if np.isnan(r["out|low"]) else f"{100 * r['out|low']:.0f}%"
    return [label, r["particles"], f"{100 * r['velocity']:.2g}", f"{r['mass ratio']:.3g}",
            f"{1e3 * r['t_w']:.0f}, {r['t_w'] / r['time step']:.0f}", r["snapshots"], f"{100 * r['sxx<1/2']:.0f}%",
            f"{100 * r['wall<1/2']:.0f}%", f"{r['u10']:+.2f} .. {r['u90']:+.2f}", out,
            f"{r['thirds50']:.2f}, {r['thirds90']:.2f}, {r['thirds|low']:.2f}"]


RUN_NAME = re.compile(r"(pentagon|disk)_(\d+)_\w+?_s(\d+)_v")
"""A walled test's file name in the fidelity study's runs folder: shape, N, seed
(``pentagon_1000_paper_s0_v1.6cm_e0.2.nc``; a periodic shear's ``..._s0_shear_v...`` does not match)."""


def walled_files(folder) -> list[str]:
    """The walled biaxial tests of the fidelity study's runs folder (:data:`RUN_NAME`), pentagons
    before disks, then by size and seed."""
    import glob

    found = []
    for path in glob.glob(os.path.join(folder, "*_e*.nc")):
        match = RUN_NAME.match(os.path.basename(path))
        if match:
            found.append(((match[1] != "pentagon", int(match[2]), int(match[3])), path))
    return [path for _, path in sorted(found)]


def label_of(path) -> str:
    """``pentagons s0`` for ``pentagon_1000_paper_s0_v1.6cm_e0.2.nc``; the file's name otherwise."""
    match = RUN_NAME.match(os.path.basename(path))
    return f"{match[1]}s s{match[3]}" if match else os.path.basename(path)


def quick_files(folder) -> list[str]:
    """Two short walled tests of 60 pentagons, the right wall of the sample's mass and of a fifth of it."""
    import warnings

    from solver import biaxial_test, compaction_sample, isotropic_compaction

    paths = []
    for ratio in (None, 0.2):
        sim = compaction_sample(60, "pentagon", seed=1)
        path = os.path.join(folder, f"pentagon_60_quick_s1_v1cm_e0.02{'' if ratio is None else '_m0.2'}.nc")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            isotropic_compaction(sim, max_steps=3000, progress=False)
            biaxial_test(sim, path, strain=0.02, every=20, wall_mass=ratio, progress=False)
        paths.append(path)
    return paths


def carried_or_file(path):
    """A test's measures where ``path`` names the measures a carry folder keeps
    (``<label>.measures.nc``, :mod:`benchmarks.fidelity.carry`), else ``path`` itself."""
    suffix = ".measures.nc"
    if not os.fspath(path).endswith(suffix):
        return path
    from benchmarks.fidelity.carry import load_measures

    folder, name = os.path.split(os.fspath(path))
    return load_measures(folder or ".", name[: -len(suffix)])


def _short_names(files) -> list:
    """Each file's name, with its folder's where two files share a name."""
    names = [os.path.basename(f) for f in files]
    return [os.path.join(os.path.basename(os.path.dirname(os.path.abspath(f))), name) if names.count(name) > 1
            else name for f, name in zip(files, names)]


def main(argv=None) -> int:
    import tempfile

    from benchmarks.common import markdown_table, print_or_write
    from grainview.contract.errors import GrainviewError
    from benchmarks.fidelity.runs import CACHE

    parser = argparse.ArgumentParser(prog="python -m benchmarks.wall_motion", description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", help="walled biaxial test files (the solver's); default: those of "
                        "--runs")
    parser.add_argument("--runs", default=os.path.join(CACHE, "runs"),
                        help="the fidelity study's runs folder (python -m benchmarks.fidelity; default %(default)s)")
    parser.add_argument("--labels", default=None, help="comma-separated, one per file (default from the names)")
    parser.add_argument("--window", type=float, default=0.4, help="the residual window's first eps_q (default 0.4)")
    parser.add_argument("--quick", action="store_true", help="two short tests of 60 pentagons, printed only")
    parser.add_argument("--out", default=None, help=f"the results file (default {RESULTS}; a --quick run prints only)")
    args = parser.parse_args(argv)
    if not (np.isfinite(args.window) and args.window >= 0):
        parser.error(f"--window {args.window:g}: expected a finite eps_q >= 0")
    with tempfile.TemporaryDirectory(prefix="wall_motion_") as scratch:
        if args.quick:
            args.files, args.window = quick_files(scratch), 0.0
        files = args.files or walled_files(args.runs)
        if not files:
            parser.error(f"no walled test in {args.runs}: run python -m benchmarks.fidelity (and --only periodic "
                         "--large for 4000 particles) first, or give the files")
        labels = args.labels.split(",") if args.labels else [label_of(f) for f in files]
        if len(labels) != len(files):
            parser.error(f"--labels: {len(labels)} labels for {len(files)} files")
        try:
            rows = [row(label, wall_motion(carried_or_file(path), args.window)) for label, path in zip(labels, files)]
        except (ValueError, GrainviewError) as exc:  # not a walled test, an empty window, an unreadable file
            parser.error(str(exc))
    table = markdown_table(HEADER, rows)
    source = (f"the files {', '.join(_short_names(files))}" if args.files else
              f"the fidelity study's ({args.runs})")
    intro = (f"Walled biaxial tests, {source}, at their own speeds and wall masses; snapshots with eps_q >= "
             f"{args.window:g}; what each column is: the module's docstring.")
    print_or_write(args.out or (None if args.quick else RESULTS), "The right wall's motion in the walled tests",
                   intro, [table], quick=args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
