"""Analysis throughput: contacts per second of stress, fabric, force tensors, the xi-network
(K = 100), persistence and contact lifetimes on a synthetic series opened lazily from
netCDF, with the peak memory of each measurement; eager (loaded) against dask (lazy).

The series is drawn from the harmonic model (grainview.datasets) and streamed to disk one
snapshot at a time with the solver's writer, so it never has to fit in memory.
"""

from __future__ import annotations

import os
import time

import numpy as np

from benchmarks.common import in_fresh_process, markdown_table, median_time

CASES = {
    "stress (sigma, p, q)": lambda ds: ds.grain.stress_invariants(),
    "fabric (F, a, a')": lambda ds: ds.grain.fabric_anisotropy(walls=False, reference=0.0),
    "force tensors (a_n, a_t)": lambda ds: ds.grain.force_anisotropies(reference=0.0),
    "xi-network (K = 100)": lambda ds: _xi(ds),
    "persistence gamma(t)": lambda ds: _persistence(ds),
    "contact lifetimes (every life)": lambda ds: _lifetimes(ds),
}


def _xi(ds):
    from grainview.analysis.xi_network import xi_network
    return xi_network(ds, xi=np.linspace(0, 5, 100))


def _persistence(ds):
    from grainview.analysis.persistence import persistence
    return persistence(ds)


def _lifetimes(ds):
    from grainview.analysis.lifetimes import contact_events
    return contact_events(ds, walls=False)


def write_series(path, n_snapshots, n_contacts, seed=0, attrs=None):
    """Stream a harmonic-model series of ``n_snapshots`` x ``n_contacts`` to ``path`` (global
    attributes ``attrs`` added)."""
    from grainview.contract.writer import SnapshotWriter
    from grainview.datasets import PAIR_LENGTH_M, harmonic_contacts

    rng = np.random.default_rng(seed)
    n_part = 2 * n_contacts
    i = np.arange(0, n_part, 2, dtype="i4")
    base = rng.uniform(-0.5, 0.5, (n_contacts, 2))
    with SnapshotWriter.create(path, radius=np.full(n_part, PAIR_LENGTH_M / 2), n_vertices=0,
                               mass=1.0, inertia=1e-4, n_contact_slots=n_contacts, overwrite=True,
                               attrs=attrs) as w:
        for k in range(n_snapshots):
            s = k / max(n_snapshots - 1, 1)
            normal, fn, ft, kind = harmonic_contacts(n_contacts, 0.3 * s, 0.4 * s, 0.25 * s, rng=rng, spread="exponential")
            pos = np.empty((n_part, 2))
            pos[i] = base
            pos[i + 1] = base + PAIR_LENGTH_M * normal
            # keep 90% of the pairs from one snapshot to the next so persistence has work to do
            order = np.arange(n_contacts) if k == 0 else np.where(rng.uniform(size=n_contacts) < 0.9, np.arange(n_contacts), -1)
            keep = order >= 0
            contacts = dict(i=i[keep], j=i[keep] + 1, kind=kind[keep], normal=normal[keep], fn=fn[keep], ft=ft[keep],
                            point=pos[i[keep]] + 0.5 * PAIR_LENGTH_M * normal[keep], branch=PAIR_LENGTH_M * normal[keep])
            w.append(time=float(k), position=pos, angle=np.zeros(n_part), contacts=contacts,
                     box_min=[0.0, 0.0], box_max=[1.0, 2.0 * (1 - 0.1 * s)])


def _measure(path, case, mode, chunk, n_load):
    """In a fresh process: median time of one analysis, lazily from file or eagerly."""
    import grainview

    ds = grainview.open_dataset(path, chunks=chunk)
    if mode == "eager":
        ds = ds.isel(time=slice(0, n_load)).load()
    func = CASES[case]
    n_contacts = int(ds["contact_count"].sum())

    def run():
        result = func(ds)
        if hasattr(result, "compute"):
            result.compute()

    repeats = 3 if mode == "dask" else 5
    median, _ = median_time(run, repeats=repeats, warmup=1)
    return median, n_contacts


def run(n_snapshots=1000, n_contacts=30_000, chunk=25, n_eager=100, workdir="benchmarks/_data"):
    os.makedirs(workdir, exist_ok=True)
    path = os.path.join(workdir, f"series_{n_snapshots}x{n_contacts}.nc")
    if not os.path.exists(path):
        start = time.perf_counter()
        write_series(path, n_snapshots, n_contacts)
        print(f"wrote {path} ({os.path.getsize(path) / 2**30:.2f} GiB) in {time.perf_counter() - start:.0f} s")
    rows = []
    for case in CASES:
        for mode in ("eager", "dask"):
            try:
                (median, n), peak = in_fresh_process(_measure, path, case, mode, chunk, n_eager)
            except RuntimeError as exc:
                rows.append([case, mode, "-", "-", "-", f"failed: {exc}"])
                continue
            rows.append([case, mode, f"{n:,}", f"{median:.3f}", f"{n / median / 1e6:.2f}", f"{peak:.0f}"])
            print(rows[-1], flush=True)
    header = ["analysis", "mode", "contacts", "median time (s)", "Mcontacts/s", "peak RSS (MiB)"]
    text = (f"Synthetic series: {n_snapshots} snapshots x {n_contacts:,} contacts, netCDF-3 file of "
            f"{os.path.getsize(path) / 2**30:.2f} GiB. dask: opened lazily with {chunk} snapshots per "
            f"chunk, whole series computed (3 repeats); eager: first {n_eager} snapshots loaded into "
            f"memory first (5 repeats). Peak RSS of the measuring process, loading included.\n\n")
    return text + markdown_table(header, rows)


if __name__ == "__main__":
    import sys
    quick = "--quick" in sys.argv
    print(run(n_snapshots=40 if quick else 1000, n_contacts=3000 if quick else 30_000,
              chunk=10 if quick else 25, n_eager=20 if quick else 100))
