"""Coarse-grained fields throughput (ds.grain.coarse_grained, Goldhirsch 2010, Weinhart et al.
2012), against the target: 14,400 particles x 100 snapshots on a 200 x 100 grid in
under a minute on 2 cores.

Samples: a paper-size packing of 14,400 pentagons made from the study's pentagon run
(``grainview study``: 400 pentagons, 201 snapshots; GRAINVIEW_STUDY=folder, default
/work/runs/study, else study/) by tiling its last 100 snapshots 12 x 3 (each tile a copy of the
400 particles with their velocities and contacts, wall contacts kept in their tile; the tiling
of benchmarks/force_chains.py, laid out wide so that a 200 x 100 grid has square-ish cells),
written one snapshot at a time with the contract's writer to benchmarks/_data/ (made when
absent); and the study's two runs themselves. The grid: 200 x 100 cells over the union of the
boxes (cell centres as ``x``, ``y``); kernel width: the mean particle diameter (the default),
cutoff 3 widths (the default).

Each case runs in a fresh process, medians of ``repeats`` runs after one warm-up (which also
loads or compiles the numba kernels): lazy (opened with dask, 10 snapshots per chunk, computed
with the threaded scheduler on every core, or with the synchronous scheduler on one), and eager
(loaded into memory first, the loading not timed). The rate counts particles x snapshots and
contacts x snapshots per second.

Usage: ``python -m benchmarks.coarse_graining [--quick]``; writes benchmarks/results/coarse-graining.md.
"""

from __future__ import annotations

import os
import time

import numpy as np

from benchmarks.common import in_fresh_process, machine_description, markdown_table, median_time, run_and_record

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET_S = 60.0  # 14,400 particles x 100 snapshots on a 200 x 100 grid
GRID = (200, 100)  # nx, ny


def study_folder() -> str:
    for folder in (os.environ.get("GRAINVIEW_STUDY"), "/work/runs/study", os.path.join(HERE, "..", "study")):
        if folder and os.path.exists(os.path.join(folder, "pentagons.nc")):
            return folder
    raise SystemExit("no study files: run `grainview study` (or set GRAINVIEW_STUDY=folder)")


def write_tiled(source: str, path: str, tiles=(12, 3), n_snapshots: int = 100) -> None:
    """Write the last ``n_snapshots`` of ``source`` tiled ``tiles`` (along x, along y) to ``path``,
    velocities included."""
    import grainview
    from grainview.contract.writer import SnapshotWriter

    ds = grainview.open_dataset(source).isel(time=slice(-n_snapshots, None)).load()
    n = ds.sizes["particle"]
    n_walls = ds.sizes.get("wall", 0)
    size = (ds["box_max"] - ds["box_min"]).values.max(0) * 1.05
    shifts = np.array([[a, b] for a in range(tiles[0]) for b in range(tiles[1])], float) * size
    m = len(shifts)
    total = n * m
    static = {name: np.tile(ds[name].values, m) for name in ("radius", "n_vertices", "mass", "inertia")}
    tmp = path + ".part"
    with SnapshotWriter.create(tmp, **static, n_walls=n_walls, overwrite=True, optional=("velocity",),
                               attrs={"thickness_m": float(ds.attrs.get("thickness_m", 1.0))}) as w:
        for k in range(ds.sizes["time"]):
            snap = ds.isel(time=k)
            count = int(snap["contact_count"])
            c = snap.isel(contact=slice(0, count))
            i, j = c["i"].values.astype(np.int64), c["j"].values.astype(np.int64)
            wall = j >= n
            contacts = {name: np.concatenate([c[name].values] * m) for name in ("kind", "normal", "fn", "ft", "branch")}
            contacts["i"] = np.concatenate([i + t * n for t in range(m)])
            contacts["j"] = np.concatenate([np.where(wall, j - n + total, j + t * n) for t in range(m)])
            contacts["point"] = np.concatenate([c["point"].values + shifts[t] for t in range(m)])
            position = np.concatenate([snap["position"].values + shifts[t] for t in range(m)])
            w.append(time=float(snap["time"]), position=position, angle=np.tile(snap["angle"].values, m),
                     velocity=np.tile(snap["velocity"].values, (m, 1)), contacts=contacts,
                     box_min=snap["box_min"].values, box_max=snap["box_min"].values + shifts.max(0) + size)
    os.replace(tmp, path)


def grid_of(ds, shape=GRID):
    """Cell centres of ``shape`` = (nx, ny) cells over the union of the snapshots' boxes (m)."""
    lo = ds["box_min"].min("time").values
    hi = ds["box_max"].max("time").values
    x = lo[0] + (np.arange(shape[0]) + 0.5) * (hi[0] - lo[0]) / shape[0]
    y = lo[1] + (np.arange(shape[1]) + 0.5) * (hi[1] - lo[1]) / shape[1]
    return x, y


def _measure(path, mode, repeats, on_grid=True):
    """In a fresh process: median time of the fields of the whole file on the 200 x 100 grid
    (``on_grid``), or on the default grid (cells of half the width)."""
    import dask

    import grainview

    ds = grainview.open_dataset(path, chunks={"time": 10})
    if mode == "eager":
        ds = ds.load()
    x, y = grid_of(ds) if on_grid else (None, None)
    n_contacts = int(ds["contact_count"].sum())
    scheduler = "synchronous" if mode == "dask, 1 core" else "threads"

    def run():
        with dask.config.set(scheduler=scheduler):
            fields = ds.grain.coarse_grained(x=x, y=y).compute()
        return fields

    start = time.perf_counter()
    fields = run()  # the warm-up: loads (or compiles) the kernels
    first = time.perf_counter() - start
    median, times = median_time(run, repeats=repeats, warmup=0)
    return (median, first, n_contacts, ds.sizes["particle"], ds.sizes["time"], fields.attrs["width_m"],
            *fields.attrs["spacing_m"], fields.sizes["x"], fields.sizes["y"])


def run(quick=False):
    folder = study_folder()
    os.makedirs(os.path.join(HERE, "_data"), exist_ok=True)
    n_snapshots = 10 if quick else 100
    tiled = os.path.join(HERE, "_data", f"cg_tiled_14400{'_quick' if quick else ''}.nc")
    if not os.path.exists(tiled):
        start = time.perf_counter()
        write_tiled(os.path.join(folder, "pentagons.nc"), tiled, n_snapshots=n_snapshots)
        print(f"wrote {tiled} in {time.perf_counter() - start:.0f} s", flush=True)
    samples = {"tiled pentagons (14,400)": tiled,
               "study pentagons (400)": os.path.join(folder, "pentagons.nc"),
               "study disks (400)": os.path.join(folder, "disks.nc")}
    repeats = 1 if quick else 3
    load_before = os.getloadavg()[0]
    rows = []
    for name, path in samples.items():
        tiled_sample = name.startswith("tiled")
        for mode in ("dask, 2 threads", "dask, 1 core", "eager") if tiled_sample else ("dask, 2 threads",):
            (median, first, n_c, n_p, n_t, width, dx, dy, nx, ny), peak = in_fresh_process(
                _measure, path, mode, repeats, tiled_sample)
            verdict = "-" if not tiled_sample else (
                f"{'met' if median * 100 / n_t < TARGET_S else 'missed'} ({median * 100 / n_t:.1f} s per 100 snapshots)")
            rows.append([name, f"{n_t} x {n_p:,}", mode, f"{n_c:,}", f"{1e3 * width:.1f}",
                         f"{nx} x {ny} of {1e3 * dx:.1f} x {1e3 * dy:.1f}",
                         f"{median:.2f}", f"{first:.2f}", f"{n_p * n_t / median / 1e6:.2f}",
                         f"{n_c / median / 1e6:.2f}", verdict, f"{peak:.0f}"])
            print(rows[-1], flush=True)
    header = ["sample", "snapshots x particles", "mode", "contacts", "width (mm)", "grid: cells of (mm)", "median time (s)",
              "first run (s)", "M particle-snapshots/s", "M contacts/s", "target: < 60 s", "peak RSS (MiB)"]
    return (f"# Coarse-grained fields throughput\n\n`python -m benchmarks.coarse_graining{' --quick' if quick else ''}`: "
            f"ds.grain.coarse_grained(x=..., y=...) computed on whole runs, the tiled sample on a {GRID[0]} x {GRID[1]} "
            f"grid over the union of the boxes, the study's runs on the default grid (cells of half a width); kernel "
            f"width the mean particle diameter, cutoff 3 widths (the defaults); every "
            f"field (density, solid fraction, momentum, velocity, kinetic and contact stress, fabric). Medians of "
            f"{repeats} runs after one warm-up (its time: 'first run'), each sample and mode in a fresh process; "
            f"dask: opened lazily, 10 snapshots per chunk, threaded scheduler (2 threads) or synchronous (1 core); "
            f"eager: loaded into memory first, the loading not timed. The tiled sample is the study's last "
            f"{n_snapshots} pentagon snapshots repeated 12 x 3 (module docstring).\n\n{machine_description()}\n\n"
            + markdown_table(header, rows) + f"\n\nLoad average (1 min) of the machine, other jobs included: "
            f"{load_before:.1f} before the measurements, {os.getloadavg()[0]:.1f} after.\n")


def main(argv=None):
    """Run the benchmark (all of it, or ``--quick``) and write its results
    (:func:`common.run_and_record`)."""
    run_and_record(__doc__.split("\n\n")[0], run, "results/coarse-graining.md", argv)


if __name__ == "__main__":
    main()
