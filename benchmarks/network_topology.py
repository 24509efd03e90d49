"""Throughput of the force network's topology (ds.grain.network_persistence): seconds per
snapshot against the target of 2 s for a 14,400-particle snapshot.

Samples:

* the study's runs (``grainview study``: 400 pentagons, 400 disks; GRAINVIEW_STUDY=folder,
  default /work/runs/study, else study/): their last snapshot;
* a paper-size snapshot of 14,400 pentagons made from the study's last pentagon snapshot by
  tiling it 6 x 6 in memory (each tile a copy of the 400 particles and of their
  particle–particle contacts, shifted by the box size; the wall contacts, which the analysis
  leaves out by default, are dropped): 36 copies of a real sheared packing, so the same edges,
  triangles and loops per particle as the study's;
* a LAMMPS run of 10,197 settled disks when present (benchmarks/_data/lammps-large/converted.nc,
  made by ``python -m benchmarks.lammps_convert``): its last snapshot, one connected packing.

For each: the whole analysis (dimensions 0 and 1, the Betti curves on 101 thresholds, the cycle
counts, all the project's own code) and dimension 0 alone, eager on one snapshot held in
memory, medians of ``repeats`` calls after one warm-up (which compiles the numba kernels); then
its parts on plain arrays (the edges, the union-find, the project's dimension-1 reduction,
gudhi's persistence of the same complex in dimensions 0 and 1 for comparison, when gudhi is
installed, the cycle counts). The tiled sample is also timed lazily: 4 snapshots (the study's last 4, tiled)
in chunks of one, computed with dask's threaded scheduler on the machine's cores.

Usage: ``python -m benchmarks.network_topology [--repeats 7]``; writes
benchmarks/results/network-topology.md.
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np

from benchmarks.common import markdown_table, median_time, write_results

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET_S = 2.0
TILES = 6


def study_folder() -> str:
    for folder in (os.environ.get("GRAINVIEW_STUDY"), "/work/runs/study", os.path.join(HERE, "..", "study")):
        if folder and os.path.exists(os.path.join(folder, "pentagons.nc")):
            return folder
    raise SystemExit("no study files: run `grainview study` (or set GRAINVIEW_STUDY=folder)")


def tiled(ds, tiles=TILES):
    """``ds`` (loaded) tiled ``tiles`` x ``tiles`` as a dataset of the contract, particle–particle
    contacts only."""
    from grainview.contract.dataset import make_dataset

    n = ds.sizes["particle"]
    size = (ds["box_max"] - ds["box_min"]).values.max(0) * 1.05
    shifts = np.array([[a, b] for a in range(tiles) for b in range(tiles)], float) * size
    m = len(shifts)
    positions, contacts = [], []
    for k in range(ds.sizes["time"]):
        snap = ds.isel(time=k)
        c = snap.isel(contact=slice(0, int(snap["contact_count"])))
        keep = (c["j"].values < n) & (c["fn"].values > 0)
        i, j = c["i"].values[keep].astype(np.int64), c["j"].values[keep].astype(np.int64)
        contacts.append({
            "i": np.concatenate([i + t * n for t in range(m)]), "j": np.concatenate([j + t * n for t in range(m)]),
            **{name: np.concatenate([c[name].values[keep]] * m) for name in ("kind", "normal", "fn", "ft", "branch")},
            "point": np.concatenate([c["point"].values[keep] + shifts[t] for t in range(m)])})
        positions.append(np.concatenate([snap["position"].values + shifts[t] for t in range(m)]))
    lo = ds["box_min"].values
    return make_dataset(radius=np.tile(ds["radius"].values, m), n_vertices=np.tile(ds["n_vertices"].values, m),
                        position=np.stack(positions), angle=np.tile(ds["angle"].values, (1, m)), contacts=contacts,
                        box_min=lo, box_max=lo[0] + shifts.max(0) + size, time=ds["time"].values)


def parts(ds, repeats):
    """Median seconds of each stage on plain arrays, one snapshot."""
    from grainview.analysis.arrays import network_topology as nt
    from grainview.analysis.contacts import selection

    snap = ds.isel(time=0)
    fn, i, j = snap["fn"].values, snap["i"].values, snap["j"].values
    mask = selection(ds).isel(time=0).values
    n = ds.sizes["particle"]
    u, v, value = nt.filtration_edges(fn, i, j, mask)
    out = {"edges": median_time(lambda: nt.filtration_edges(fn, i, j, mask), repeats)[0],
           "union-find": median_time(lambda: nt.diagram_0(u, v, value, n), repeats)[0],
           "dimension 1": median_time(lambda: nt.diagram_1(u, v, value, n), repeats)[0],
           "gudhi": float("nan"),
           "cycles": median_time(lambda: nt.short_cycles(u, v, value, n), repeats)[0]}
    if importlib.util.find_spec("gudhi"):
        out["gudhi"] = median_time(lambda: nt.diagrams_gudhi(u, v, value, n), repeats)[0]
    return out, u.size


def measure(name, ds, repeats):
    """Rows of the table for one snapshot of ``ds`` (loaded)."""
    one = ds.isel(time=[-1])
    whole = median_time(lambda: one.grain.network_persistence().compute(), repeats)[0]
    zero = median_time(lambda: one.grain.network_persistence(dimensions=(0,)).compute(), repeats)[0]
    stages, n_edges = parts(one, repeats)
    out = one.grain.network_persistence(xi=[0.0, 1.0])
    row = [name, f"{ds.sizes['particle']:,}", f"{n_edges:,}", f"{int(out.cycles_3.sum()):,}",
           f"{int(out.beta_1[0, 0]):,}", f"{whole:.3f}", f"{zero:.3f}",
           " / ".join(f"{1e3 * stages[k]:.1f}" for k in ("edges", "union-find", "dimension 1", "gudhi", "cycles"))]
    print(row, flush=True)
    return row, whole, stages


def run(repeats=7, out=None):
    import dask

    import grainview

    folder = study_folder()
    pentagons = grainview.open_dataset(os.path.join(folder, "pentagons.nc"))
    disks = grainview.open_dataset(os.path.join(folder, "disks.nc"))
    samples = {"study pentagons": pentagons.isel(time=[-1]).load(), "study disks": disks.isel(time=[-1]).load(),
               f"study pentagons tiled {TILES} x {TILES}": tiled(pentagons.isel(time=[-1]).load())}
    lammps = os.path.join(HERE, "_data", "lammps-large", "converted.nc")
    if os.path.exists(lammps):
        samples["LAMMPS settled disks"] = grainview.open_dataset(lammps).isel(time=[-1]).load()
    rows, verdict, stages = [], {}, {}
    for name, ds in samples.items():
        row, verdict[name], stages[name] = measure(name, ds, repeats)
        rows.append(row)
    # lazy: 4 tiled snapshots in chunks of one, threaded scheduler
    series = tiled(pentagons.isel(time=slice(-4, None)).load()).chunk({"time": 1})
    with dask.config.set(scheduler="threads"):
        lazy = median_time(lambda: series.grain.network_persistence().compute(), max(repeats // 2, 2))[0]
    big = verdict[f"study pentagons tiled {TILES} x {TILES}"]
    big_parts = stages[f"study pentagons tiled {TILES} x {TILES}"]
    own = big_parts["union-find"] + big_parts["dimension 1"]
    header = ["sample (one snapshot)", "particles", "contacts (edges)", "3-cycles", "beta_1 at xi = 0",
              "whole analysis (s)", "dimension 0 only (s)",
              "edges / union-find / dimension 1 / gudhi dimensions 0 and 1 / cycles (ms)"]
    intro = (f"`python -m benchmarks.network_topology --repeats {repeats}`: ds.grain.network_persistence() on one "
             f"snapshot held in memory, medians of {repeats} calls after one warm-up; the whole analysis is "
             "dimensions 0 and 1 with the Betti curves on 101 thresholds and the 3- and 4-cycle counts; "
             "all of it the project's own code (no gudhi). The parts are the array functions of "
             "grainview.analysis.arrays.network_topology on the same snapshot: the edges, the union-find (dimension 0), "
             "the reduction of the triangles' boundary matrix (dimension 1, diagram_1), gudhi's persistence of "
             "the same complex in dimensions 0 and 1 (diagrams_gudhi, the cross-check; nan without gudhi) and "
             "the cycle counts. Samples: the module docstring (the "
             "14,400-particle one is the study's last pentagon snapshot tiled 6 x 6 in memory, "
             "particle-particle contacts only).")
    verdict_line = (f"**Target: persistence of a 14,400-particle snapshot in under {TARGET_S:g} s: "
                    f"{'met' if big < TARGET_S else 'missed'}** ({big:.3f} s for the whole analysis). Lazily, "
                    f"4 tiled snapshots in chunks of one on dask's threaded scheduler: {lazy:.2f} s, "
                    f"{lazy / 4:.3f} s per snapshot. Both dimensions of that snapshot by the project's code "
                    f"(union-find and reduction): {1e3 * own:.1f} ms; by gudhi: "
                    + (f"{1e3 * big_parts['gudhi']:.1f} ms ({big_parts['gudhi'] / own:.0f} times as long), "
                       "so the analysis uses its own code whether gudhi is installed or not."
                       if np.isfinite(big_parts["gudhi"]) else "not measured (gudhi is not installed)."))
    return write_results(out or os.path.join(HERE, "results", "network-topology.md"),
                         "Topology of the force network: throughput", intro,
                         [markdown_table(header, rows), verdict_line])


def main(argv=None):
    """Run the benchmark and write its results; a bad argument is refused by argparse in one line
    before anything runs."""
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7, help="calls timed per measurement (default 7)")
    parser.add_argument("--out", help="the results file (default benchmarks/results/network-topology.md)")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats {args.repeats}: expected an integer >= 1")
    run(repeats=args.repeats, out=args.out)


if __name__ == "__main__":
    main()
