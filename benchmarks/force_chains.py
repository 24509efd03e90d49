"""Force-chain throughput (ds.grain.force_chains, Peters et al. 2005): contacts per second,
against the target of 1 M contacts/s.

Samples: the study's own runs (``grainview study``: 400 pentagons and 400 disks, 201 snapshots;
GRAINVIEW_STUDY=folder, default /work/runs/study, else study/), and a paper-size packing of
14,400 pentagons made from the pentagon run by tiling its snapshots 6 x 6 (each tile a copy of
the 400 particles and their contacts, wall contacts kept in their tile), written one snapshot
at a time with the contract's writer to benchmarks/_data/ (made when absent). Each sample is
measured in a fresh process: eager (loaded into memory first) and lazy (opened with dask,
:data:`CHUNK` snapshots per chunk, computed with the threaded scheduler), the chains alone,
with ``follow=True`` (tracks and lifetimes), and the stress invariants as a reference (what
reading and dask cost any analysis); contacts = occupied slots (walls included), medians
of ``repeats`` runs after one warm-up (which also compiles the numba kernel).

Usage: ``python -m benchmarks.force_chains [--quick]``; writes benchmarks/results/force-chains.md.
"""

from __future__ import annotations

import os
import time

import numpy as np

from benchmarks.common import in_fresh_process, machine_description, markdown_table, median_time, run_and_record

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET = 1e6  # contacts per second
CHUNK = 20  # snapshots per dask chunk


def study_folder() -> str:
    for folder in (os.environ.get("GRAINVIEW_STUDY"), "/work/runs/study", os.path.join(HERE, "..", "study")):
        if folder and os.path.exists(os.path.join(folder, "pentagons.nc")):
            return folder
    raise SystemExit("no study files: run `grainview study` (or set GRAINVIEW_STUDY=folder)")


def write_tiled(source: str, path: str, tiles: int = 6, n_snapshots: int | None = None) -> None:
    """Write ``source``'s snapshots tiled ``tiles`` x ``tiles`` to ``path``."""
    import grainview
    from grainview.contract.writer import SnapshotWriter

    ds = grainview.open_dataset(source).load()
    if n_snapshots is not None:
        ds = ds.isel(time=slice(-n_snapshots, None))
    n = ds.sizes["particle"]
    n_walls = ds.sizes.get("wall", 0)
    size = (ds["box_max"] - ds["box_min"]).values.max(0) * 1.05
    shifts = np.array([[a, b] for a in range(tiles) for b in range(tiles)], float) * size
    m = len(shifts)
    total = n * m
    static = {name: np.tile(ds[name].values, m) for name in ("radius", "n_vertices", "mass", "inertia")}
    tmp = path + ".part"
    with SnapshotWriter.create(tmp, **static, n_walls=n_walls, overwrite=True,
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
                     contacts=contacts, box_min=snap["box_min"].values,
                     box_max=snap["box_min"].values + shifts.max(0) + size)
    os.replace(tmp, path)


CASES = {
    "force_chains()": lambda ds: ds.grain.force_chains(),
    "force_chains(follow=True)": lambda ds: ds.grain.force_chains(follow=True),
    "stress_invariants() (reference)": lambda ds: ds.grain.stress_invariants(),
}


def _measure(path, mode, case, chunk, repeats):
    """In a fresh process: median time of ``CASES[case]`` on ``path``, and the contacts counted."""
    import grainview

    ds = grainview.open_dataset(path, chunks={"time": chunk})
    if mode == "eager":
        ds = ds.load()
    n_contacts = int(ds["contact_count"].sum())

    def run():
        CASES[case](ds).compute()

    median, times = median_time(run, repeats=repeats, warmup=1)
    return median, n_contacts, ds.sizes["particle"], ds.sizes["time"]


def run(quick=False):
    folder = study_folder()
    load_before = os.getloadavg()[0]
    os.makedirs(os.path.join(HERE, "_data"), exist_ok=True)
    tiled = os.path.join(HERE, "_data", f"chains_tiled_14400{'_quick' if quick else ''}.nc")
    if not os.path.exists(tiled):
        start = time.perf_counter()
        write_tiled(os.path.join(folder, "pentagons.nc"), tiled, n_snapshots=10 if quick else 60)
        print(f"wrote {tiled} in {time.perf_counter() - start:.0f} s", flush=True)
    samples = {"study pentagons (400)": os.path.join(folder, "pentagons.nc"),
               "study disks (400)": os.path.join(folder, "disks.nc"),
               "tiled pentagons (14,400)": tiled}
    rows = []
    repeats = 2 if quick else 5
    for name, path in samples.items():
        for mode in ("eager", "dask"):
            for case in CASES:
                (median, n_c, n_p, n_t), peak = in_fresh_process(_measure, path, mode, case, CHUNK, repeats)
                rate = n_c / median
                verdict = "" if "reference" in case else ("met" if rate >= TARGET else "missed")
                rows.append([name, f"{n_t} x {n_p}", mode, case, f"{n_c:,}", f"{median:.3f}",
                             f"{rate / 1e6:.2f}", verdict, f"{peak:.0f}"])
                print(rows[-1], flush=True)
    header = ["sample", "snapshots x particles", "mode", "analysis", "contacts", "median time (s)", "M contacts/s",
              "target 1 M/s", "peak RSS (MiB)"]
    load = (f"Load average (1 min) {load_before:.1f} at the start and {os.getloadavg()[0]:.1f} at the end, on "
            f"{os.cpu_count()} cores: above the core count, other work shared the machine and the times are longer "
            f"than on free cores.")
    return (f"# Force-chain throughput\n\n`python -m benchmarks.force_chains{' --quick' if quick else ''}`: "
            f"ds.grain.force_chains() computed on whole runs, medians of {repeats} runs after one warm-up, "
            f"each sample and mode in a fresh process; eager: the file loaded into memory first; dask: opened "
            f"lazily, {CHUNK} snapshots per chunk, threaded scheduler. Contacts: occupied slots, wall contacts "
            f"included. The stress (p, q) on the same data is the reference: what reading the file and "
            f"dask cost any analysis. The tiled sample is the study's last {10 if quick else 60} pentagon snapshots "
            f"repeated 6 x 6 (module docstring).\n\n{machine_description()} {load}\n\n"
            + markdown_table(header, rows) + "\n")


def main(argv=None):
    """Run the benchmark (all of it, or ``--quick``) and write its results
    (:func:`common.run_and_record`)."""
    run_and_record(__doc__.split("\n\n")[0], run, "results/force-chains.md", argv)


if __name__ == "__main__":
    main()
