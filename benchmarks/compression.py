"""What compressing a finished run costs and saves: size, time to compress, time of the
analyses on the compressed file against the same file uncompressed.

    python benchmarks/compression.py [FILE]        # default: study/disks.nc (grainview study)

FILE is copied twice into a temporary folder: one copy is made netCDF-3, the other
compressed (grainview.contract.writer.compress_file, the solver's default at the end of a run). The
analyses (stress invariants, fabric anisotropy, force anisotropies, computed lazily with dask
from open_dataset's default chunks) run on both copies alternately, ``--repeats`` times; the
table gives medians and their ratio from this one run.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))


def analyses(path) -> float:
    """Seconds to compute the stress invariants, fabric and force anisotropies of ``path``."""
    import grainview

    with grainview.open_dataset(path) as ds:
        start = time.perf_counter()
        ds.grain.stress_invariants()["q_over_p"].compute()
        ds.grain.fabric_anisotropy().compute()
        ds.grain.force_anisotropies().compute()
        return time.perf_counter() - start


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", nargs="?", default="study/disks.nc")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    import grainview
    from common import machine_description
    from grainview.contract.writer import compress_file, decompress_file

    with tempfile.TemporaryDirectory() as tmp:
        plain, packed = os.path.join(tmp, "plain.nc"), os.path.join(tmp, "packed.nc")
        shutil.copy(args.file, plain)
        decompress_file(plain)
        shutil.copy(plain, packed)
        start = time.perf_counter()
        compress_file(packed)
        seconds = time.perf_counter() - start
        with grainview.open_dataset(plain, chunks=None) as ds:
            shape = f"{ds.sizes['particle']} particles, {ds.sizes['time']} snapshots, {ds.sizes['contact']} contact slots"
        times = {plain: [], packed: []}
        for _ in range(args.repeats):
            for path in times:
                times[path].append(analyses(path))
        size_plain, size_packed = os.path.getsize(plain), os.path.getsize(packed)
        median = {path: statistics.median(v) for path, v in times.items()}
    print(machine_description() + "\n")
    print(f"{os.path.basename(args.file)}: {shape}; analyses = stress invariants + fabric anisotropy + force "
          f"anisotropies with open_dataset's default chunks; medians of {args.repeats} alternating runs.\n")
    print("| file | size (MB) | time to write (s) | analyses, median (s) |")
    print("|---|---|---|---|")
    print(f"| netCDF-3 (while a run goes on) | {size_plain / 1e6:.1f} | - | {median[plain]:.2f} |")
    print(f"| compressed (NETCDF4_CLASSIC, zlib 4, shuffle) | {size_packed / 1e6:.1f} | {seconds:.2f} "
          f"(compress_file) | {median[packed]:.2f} |")
    print(f"| ratio compressed / netCDF-3 | {size_packed / size_plain:.2f} | | {median[packed] / median[plain]:.2f} |")


if __name__ == "__main__":
    main()
