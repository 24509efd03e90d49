"""What compressing a finished run costs and saves: size, time and memory to compress, and the
analyses' throughput on the compressed file against the same data uncompressed.

    python -m benchmarks.compression [FILE] [--repeats 3] [--out benchmarks/results/compression.md]

Without FILE, a synthetic series of 40 snapshots x 200,000 contacts (8 million contacts, every
slot a contact; benchmarks/analysis.py's writer) is written once into benchmarks/_data. The
file is copied into a temporary folder in three forms: netCDF-3 (a run while it goes on), the
default compressed file (grainview.contract.writer.compress_file: one snapshot per chunk,
zlib 1 only where it saves at least 40%) and, to show what the filter choice buys, every
variable deflated (zlib 4, the same chunks). Each compression runs in a fresh process, whose
time and peak resident memory are reported. The analyses (stress invariants, fabric
anisotropy, force anisotropies, the xi-network with 100 thresholds, every contact's lifetime;
lazily with dask from open_dataset's default chunks) run on the three files in turn,
``--repeats`` rounds; the tables give medians, contacts/s and the ratio to netCDF-3 from this
one run.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

CASES = {
    "stress invariants": lambda ds: ds.grain.stress_invariants()["q_over_p"],
    "fabric anisotropy": lambda ds: ds.grain.fabric_anisotropy(),
    "force anisotropies": lambda ds: ds.grain.force_anisotropies(),
    "xi-network (K = 100)": lambda ds: _xi(ds),
    "contact lifetimes": lambda ds: _lifetimes(ds),
}

COMPRESS = r"""
import json, resource, sys, time
import grainview.contract.writer as writer
path, level, min_saving = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
writer.MIN_SAVING = min_saving
start = time.perf_counter()
writer.compress_file(path, complevel=level)
print(json.dumps({"seconds": time.perf_counter() - start,
                  "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def _xi(ds):
    from grainview.analysis.xi_network import xi_network

    return xi_network(ds, xi=np.linspace(0, 5, 100))


def _lifetimes(ds):
    from grainview.analysis.lifetimes import contact_events

    return contact_events(ds, walls=False)


def compress(path, level, min_saving) -> dict:
    """compress_file on ``path`` in a fresh process: its seconds and peak resident memory (MiB)."""
    import json

    done = subprocess.run([sys.executable, "-c", COMPRESS, path, str(level), str(min_saving)],
                          capture_output=True, text=True, check=True, cwd=os.path.dirname(HERE))
    return json.loads(done.stdout.strip().splitlines()[-1])


def timed(path, case) -> float:
    """Seconds of one analysis of ``path``, opened lazily."""
    import grainview

    with grainview.open_dataset(path) as ds:
        start = time.perf_counter()
        result = CASES[case](ds)
        if hasattr(result, "compute"):
            result.compute()
        return time.perf_counter() - start


def layout(path) -> str:
    """Which per-snapshot variables are deflated, and the chunk of ``fn``."""
    import netCDF4

    with netCDF4.Dataset(path) as nc:
        deflated = [n for n, v in nc.variables.items() if v.dimensions[:1] == ("time",) and v.filters()["zlib"]]
        return f"deflated: {', '.join(deflated) or 'none'}; fn chunk {nc.variables['fn'].chunking()}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", nargs="?", help="a file of the contract (default: the synthetic 8M-contact series)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", help="markdown file to write (default: print)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    import grainview
    from benchmarks.common import machine_description
    from grainview.contract.writer import decompress_file

    source = args.file
    if source is None:
        from benchmarks.analysis import write_series

        source = os.path.join(HERE, "_data", "series_40x200000.nc")
        if not os.path.exists(source):
            os.makedirs(os.path.dirname(source), exist_ok=True)
            write_series(source, 40, 200_000)
    with tempfile.TemporaryDirectory(dir=os.path.join(HERE, "_data") if os.path.isdir(os.path.join(HERE, "_data"))
                                     else None) as tmp:
        files = {"netCDF-3": os.path.join(tmp, "plain.nc"), "default": os.path.join(tmp, "default.nc"),
                 "zlib 4, everything": os.path.join(tmp, "all.nc")}
        shutil.copy(source, files["netCDF-3"])
        decompress_file(files["netCDF-3"])
        written = {}
        for name, level, min_saving in (("default", None, None), ("zlib 4, everything", 4, 0.0)):
            shutil.copy(files["netCDF-3"], files[name])
            from grainview.contract.writer import DEFAULT_COMPLEVEL, MIN_SAVING

            written[name] = compress(files[name], level or DEFAULT_COMPLEVEL,
                                     MIN_SAVING if min_saving is None else min_saving)
        with grainview.open_dataset(files["netCDF-3"], chunks=None) as ds:
            contacts = int(ds["contact_count"].sum())
            shape = (f"{ds.sizes['particle']:,} particles, {ds.sizes['time']} snapshots, {ds.sizes['contact']:,} "
                     f"contact slots, {contacts:,} contacts")
        for case in CASES:  # warm-up: numba's kernels, the page cache
            timed(files["netCDF-3"], case)
        times = {(name, case): [] for name in files for case in CASES}
        for _ in range(args.repeats):
            for case in CASES:
                for name, path in files.items():
                    times[name, case].append(timed(path, case))
        median = {key: statistics.median(v) for key, v in times.items()}
        sizes = {name: os.path.getsize(path) for name, path in files.items()}
        layouts = {name: layout(files[name]) for name in written}
    lines = [machine_description(), "",
             f"{os.path.basename(source)}: {shape}. Analyses lazily with open_dataset's default chunks; medians "
             f"of {args.repeats} rounds, the three files in turn within each round.", "",
             "| file | size (MB) | size / netCDF-3 | compress_file (s) | its peak memory (MiB) |",
             "|---|---|---|---|---|"]
    for name in files:
        w = written.get(name)
        lines.append(f"| {name} | {sizes[name] / 1e6:.0f} | {sizes[name] / sizes['netCDF-3']:.2f} | "
                     + (f"{w['seconds']:.1f} | {w['peak_mib']:.0f} |" if w else "- | - |"))
    lines += ["", "; ".join(f"{name}: {text}" for name, text in layouts.items()), "",
              "| analysis | " + " | ".join(f"{name}: s, M contacts/s" for name in files)
              + " | default / netCDF-3 | zlib 4 everything / netCDF-3 |",
              "|---|" + "---|" * (len(files) + 2)]
    for case in CASES:
        cells = [f"{median[name, case]:.2f}, {contacts / median[name, case] / 1e6:.1f}" for name in files]
        lines.append(f"| {case} | " + " | ".join(cells)
                     + f" | {median['netCDF-3', case] / median['default', case]:.2f}"
                     f" | {median['netCDF-3', case] / median['zlib 4, everything', case]:.2f} |")
    lines += ["", "Ratios are throughputs: the compressed file's contacts/s over netCDF-3's (1 = as fast)."]
    report = "\n".join(lines) + "\n"
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(report)
        print(f"wrote {args.out}")
    print(report)


if __name__ == "__main__":
    main()
