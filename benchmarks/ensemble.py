"""Ensembles on dask.distributed: the parallel efficiency of the ensemble runner on this
machine's cores, and an analysis of a synthetic ensemble larger than memory computed on a
LocalCluster with bounded memory per worker.

    python -m benchmarks.ensemble            # writes benchmarks/_data/RESULTS-ensemble.md
    python -m benchmarks.ensemble --quick    # tiny sizes, checks the script (_data/)

``python -m benchmarks`` runs the same as its section ``ensemble``, into benchmarks/results/ensemble.md: the
committed numbers are that file's.

Runner: the same set of small biaxial tests (pentagons and disks, one seed each per worker)
run by ``grainview.app.ensemble.run_ensemble`` on a LocalCluster of 1 worker, then of 2 workers (cold
output folders, warm numba cache); efficiency = T(1 worker) / (workers x T(workers)).

Out of core: ``runs`` synthetic harmonic-model series (grainview.datasets, streamed to disk)
of ``snapshots`` x ``contacts`` each, two settings of half the runs each, opened with
``grainview.open_ensemble``; the stress invariants and the fabric anisotropy of every run and
snapshot, reduced to mean +- spread over seeds on eps_q bins (``seed_statistics``), computed on
a LocalCluster of single-threaded workers with a memory limit. The peak resident memory of each
worker process is sampled every 0.2 s.
"""

from __future__ import annotations

import os
import threading
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.analysis import write_series
from benchmarks.common import machine_description, markdown_table


RUNNER_SIZES = {False: dict(particles=400, seeds=2, strain=0.02), True: dict(particles=30, seeds=1, strain=0.005)}
"""Sizes of the runner measurement: full run and --quick."""
OUT_OF_CORE_SIZES = {False: dict(runs=16, snapshots=500, contacts=30_000, memory_limit="3GiB"),
                     True: dict(runs=4, snapshots=20, contacts=3000, memory_limit="1GiB")}
"""Sizes of the out-of-core measurement: full run and --quick."""


def runner_efficiency(folder, particles=100, seeds=2, strain=0.02, workers=(1, 2)):
    """Wall time of one ensemble (pentagons + disks x ``seeds``) on each worker count."""
    import shutil

    from grainview.app.ensemble import grid, run_ensemble

    specs = grid(shapes=("pentagon", "disk"), particles=(particles,), seeds=seeds, strain=strain, every=100)
    times, steps, inside = {}, {}, {}
    for n in workers:
        out = os.path.join(folder, f"runner_{n}")
        shutil.rmtree(out, ignore_errors=True)
        start = time.perf_counter()
        results = run_ensemble(specs, out, workers=n, progress=False)
        times[n] = time.perf_counter() - start
        steps[n] = sum(r["steps"] for r in results)
        inside[n] = sum(r["seconds"] for r in results)
        print(f"runner: {n} worker(s): {times[n]:.1f} s wall, {inside[n]:.1f} s in the runs", flush=True)
    rows = [[n, len(specs), f"{times[n]:.1f}", f"{inside[n]:.1f}", f"{times[workers[0]] * workers[0] / (n * times[n]):.2f}"]
            for n in workers]
    text = (f"{len(specs)} biaxial tests ({particles} pentagons and {particles} disks x {seeds} seeds, to "
            f"eps_1 = {strain}, {steps[workers[0]]:,} steps in all), deposit and compaction included, on a "
            "LocalCluster of single-threaded worker processes (cluster start-up included).\n\n")
    text += ("'time in the runs': the runs' own wall times added up (simulation and output); the rest of "
             "the wall time is the cluster's start-up, the workers' imports and scheduling.\n\n")
    return text + markdown_table(["workers", "runs", "wall time (s)", "time in the runs (s)", "parallel efficiency"],
                                 rows)


def write_ensemble(folder, runs, snapshots, contacts):
    paths = []
    for k in range(runs):
        friction = 0.2 if k < runs // 2 else 0.4
        path = os.path.join(folder, f"synthetic_mu{friction}_s{k % (runs // 2)}.nc")
        if not os.path.exists(path):
            write_series(path, snapshots, contacts, seed=k,
                         attrs={"solver_friction": friction, "preparation_seed": k % (runs // 2)})
        paths.append(path)
    return paths


class PeakSampler:
    """Largest resident set size of each process of ``pids``, sampled every ``interval`` s."""

    def __init__(self, pids, interval=0.2):
        import psutil

        self.procs = {pid: psutil.Process(pid) for pid in pids}
        self.peak = {pid: 0 for pid in pids}
        self.interval, self.stop = interval, threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self.stop.is_set():
            for pid, proc in self.procs.items():
                try:
                    self.peak[pid] = max(self.peak[pid], proc.memory_info().rss)
                except Exception:  # a worker restarted
                    pass
            time.sleep(self.interval)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join()


def out_of_core(folder, runs=16, snapshots=500, contacts=30_000, workers=2, memory_limit="3GiB", chunk=10):
    import psutil
    from distributed import Client, LocalCluster

    import grainview
    from grainview.analysis.ensemble import seed_statistics

    start = time.perf_counter()
    paths = write_ensemble(folder, runs, snapshots, contacts)
    written = time.perf_counter() - start
    size = sum(os.path.getsize(p) for p in paths)
    print(f"out of core: {len(paths)} files, {size / 2**30:.1f} GiB ({written:.0f} s to write the missing ones)",
          flush=True)
    ens = grainview.open_ensemble(paths, chunks=chunk)
    bins = np.linspace(0.0, 0.1, 11)
    with LocalCluster(n_workers=workers, threads_per_worker=1, memory_limit=memory_limit, dashboard_address=None,
                      env={"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}) as cluster, Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        client.run(lambda: __import__("grainview.analysis.stress") and __import__("grainview.analysis.fabric"))  # imports, not timed
        with PeakSampler(pids) as sampler:
            start = time.perf_counter()
            q = ens.grain.stress_invariants()["q_over_p"]
            a = ens.grain.fabric_anisotropy(walls=False)["a"]
            q, a = client.compute([q, a], sync=True)  # every run and snapshot
            elapsed = time.perf_counter() - start
        stats_q = seed_statistics(q, eps_q_bins=bins)
        stats_a = seed_statistics(a, eps_q_bins=bins)
    n_contacts = runs * snapshots * contacts
    peak = max(sampler.peak.values()) / 2**20
    memory = psutil.virtual_memory().total / 2**30
    example = stats_q["mean"].isel(eps_q_bin=-1).values, stats_q["std"].isel(eps_q_bin=-1).values
    print(f"out of core: {elapsed:.1f} s, peak worker RSS {peak:.0f} MiB", flush=True)
    rows = [[f"{runs} x {snapshots} x {contacts:,}", f"{size / 2**30:.1f}", f"{memory:.0f}", workers, memory_limit,
             f"{elapsed:.1f}", f"{n_contacts / elapsed / 1e6:.1f}", f"{peak:.0f}"]]
    text = (f"Synthetic ensemble: {runs} runs (2 settings x {runs // 2} seeds) x {snapshots} snapshots x "
            f"{contacts:,} contacts, netCDF-3 files, opened with `grainview.open_ensemble` ({chunk} snapshots per "
            "chunk, one run per chunk); q/p (stress invariants) and the fabric anisotropy a of every run and "
            "snapshot computed on a LocalCluster, then reduced over seeds on eps_q bins "
            f"(`seed_statistics`; e.g. last bin, q/p = {example[0].round(3).tolist()} +- "
            f"{example[1].round(4).tolist()} per setting). Peak RSS: the largest of the workers, sampled every "
            "0.2 s.\n\n")
    header = ["runs x snapshots x contacts", "data (GiB)", "machine memory (GiB)", "workers", "memory limit/worker",
              "time (s)", "Mcontacts/s", "peak worker RSS (MiB)"]
    return text + markdown_table(header, rows)


def main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, to check the script")
    parser.add_argument("--only", default="runner,out_of_core", help="comma-separated: runner,out_of_core")
    args = parser.parse_args(argv)
    wanted = args.only.split(",")
    folder = os.path.join(HERE, "_data", "ensemble_quick" if args.quick else "ensemble")
    os.makedirs(folder, exist_ok=True)
    output = os.path.join(HERE, "_data", "RESULTS-ensemble-quick.md" if args.quick else "RESULTS-ensemble.md")
    body = ["# Ensemble benchmarks", "",
            f"Generated by `python -m benchmarks.ensemble{' --quick' if args.quick else ''}`; see docs/ensembles.md.",
            "", machine_description(), ""]
    if "runner" in wanted:
        text = runner_efficiency(folder, **RUNNER_SIZES[args.quick])
        body += ["## Ensemble runner: parallel efficiency", "", text, ""]
    if "out_of_core" in wanted:
        body += ["## Out-of-core analysis of an ensemble", "", out_of_core(folder, **OUT_OF_CORE_SIZES[args.quick]), ""]
    with open(output, "w") as fh:
        fh.write("\n".join(body) + "\n")
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
