"""How long two file commands take on a study-sized file: ``grainview export --to csv`` and
``grainview info``.

    python -m benchmarks.cli_io [--file RUN.nc] [--snapshots 201 --contacts 1206] [--repeats 5]
                                [--sources DIR --commit C] [--out results/cli-io.md]

The file is ``--file`` (e.g. a study's ``pentagons.nc``) or, without it, a synthetic series
(:func:`grainview.datasets.harmonic_series`) of ``--snapshots`` snapshots of
``--contacts`` contacts, the size of a 400-particle study's run, written compressed to a
temporary folder. Every measurement is a fresh process, timed from outside, so each includes
Python's start and the imports, as a user sees them.

* ``export --to csv``: the command as it is (the snapshots read a block at a time, the table
  written block by block) against the way it was before, one snapshot's contacts table read
  from the lazily opened file after another (:data:`PER_SNAPSHOT`, kept here to measure it),
  in alternating turns; the two tables are checked to be the same bytes.
* ``info``: the first run after installing (a copy of grainview's and solver's sources
  without their compiled bytecode, which Python then compiles and caches, as after
  ``pip install -e .``; the file's pages dropped too), cold (the file's pages dropped from
  the page cache with ``posix_fadvise`` before each run: the first ``info`` of a file just
  copied or written long ago) and warm (the same command again), all three with Python
  writing its bytecode cache as it does by default (``PYTHONDONTWRITEBYTECODE`` unset: where it
  is set, every run compiles grainview's modules again and takes the first run's time), and
  where a warm run's time goes: the interpreter and the imports
  (``python -c "import grainview.app.cli"``), the command line's parser
  (:func:`grainview.app.cli.build_parser`) and the summary itself
  (:func:`grainview.app.file_summary.describe_file`).

The code measured is this repository's grainview and solver packages, or those of ``--sources``
(a folder holding both, e.g. ``git archive <commit> grainview solver | tar -x -C DIR``: a
commit measured apart from uncommitted changes; ``--commit`` names it in the table). Writes a
markdown table to ``--out`` (default: print it).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

PER_SNAPSHOT = r"""
import sys
import pandas as pd
from grainview.contract.io import open_dataset
from grainview.analysis.tables import contacts_table
from grainview.analysis.snapshots import snapshot_indices
from grainview.export.contacts_csv import KIND_NAMES, _CSV_NAMES
ds = open_dataset(sys.argv[1])
frames = []
for k in snapshot_indices(ds, 1):
    table = contacts_table(ds, time=int(k))
    table.insert(0, "time", table.attrs["time"])
    table.insert(0, "snapshot", int(k))
    table.insert(table.columns.get_loc("fn"), "loaded", table["fn"] > 0)
    table["kind"] = table["kind"].map(lambda code: KIND_NAMES.get(int(code), str(int(code))))
    frames.append(table.rename(columns=_CSV_NAMES))
pd.concat(frames, ignore_index=True).to_csv(sys.argv[2] + "/contacts.csv", index=False)
"""
"""The CSV export as it was: each snapshot's table from the lazily opened file, one after the
other, concatenated and written at the end."""

STAGES = r"""
import sys, time
start = time.perf_counter()
from grainview.app import cli
imported = time.perf_counter()
parser = cli.build_parser()
built = time.perf_counter()
from grainview.app.file_summary import describe_file
describe_file(sys.argv[1])
done = time.perf_counter()
print(imported - start, built - imported, done - built)
"""
"""A warm ``info``'s stages, timed inside one process."""


def timed(command: list, cwd=None, env=None) -> float:
    """Wall time of ``command`` run to its end in ``cwd``, s (its output dropped)."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=cwd or ROOT,
                   env=env)
    return time.perf_counter() - start


def fresh_sources(folder: Path, sources: Path = ROOT) -> Path:
    """A copy of the grainview and solver packages of ``sources`` in ``folder``, without their
    compiled bytecode: Python run there imports them as after a fresh install."""
    import shutil

    if folder.exists():
        shutil.rmtree(folder)
    for package in ("grainview", "solver"):
        shutil.copytree(sources / package, folder / package, ignore=shutil.ignore_patterns("__pycache__"))
    return folder


def drop_from_cache(path: Path) -> None:
    """Ask the kernel to drop ``path``'s pages from the page cache (this file's only)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
        os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
    finally:
        os.close(fd)


def synthetic_file(folder: Path, snapshots: int, contacts: int) -> Path:
    """A compressed synthetic series of the given size in ``folder``."""
    from grainview.datasets import harmonic_series
    from grainview.contract.dataset import netcdf_options

    ds = harmonic_series(n_snapshots=snapshots, n_contacts=contacts)
    path = folder / "synthetic.nc"
    ds.to_netcdf(path, **netcdf_options(ds, compress=True))
    return path


def measure(path: Path, folder: Path, repeats: int, sources: Path = ROOT) -> dict:
    """Every number of the table, for the file ``path`` and the packages of ``sources``
    (scratch space in ``folder``)."""
    python = sys.executable
    environment = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX")}
    environment["PYTHONPATH"] = ""  # the copy's packages, from the folder the commands run in
    copy = fresh_sources(folder / "installed", sources)
    now, before = folder / "now", folder / "before"
    export = [python, "-m", "grainview.app.cli", "export", str(path), "--to", "csv", "--out", str(now),
              "--overwrite", "--progress", "off"]
    old = [python, "-c", PER_SNAPSHOT, str(path), str(before)]
    before.mkdir(exist_ok=True)
    times = {"now": [], "before": []}
    for _ in range(repeats):  # alternating turns, so that a change of load falls on both
        times["now"].append(timed(export, cwd=copy, env=environment))
        times["before"].append(timed(old, cwd=copy, env=environment))
    same = (now / "contacts.csv").read_bytes() == (before / "contacts.csv").read_bytes()
    info = [python, "-m", "grainview.app.cli", "info", str(path)]
    cold, warm, first = [], [], []
    for _ in range(repeats):
        copy = fresh_sources(folder / "installed", sources)
        drop_from_cache(path)
        first.append(timed(info, cwd=copy, env=environment))
        drop_from_cache(path)
        cold.append(timed(info, cwd=copy, env=environment))
        warm.append(timed(info, cwd=copy, env=environment))
    stages = []
    for _ in range(repeats):
        done = subprocess.run([python, "-c", STAGES, str(path)], check=True, capture_output=True, text=True,
                              cwd=copy, env=environment)
        stages.append([float(v) for v in done.stdout.split()])
    bare = [timed([python, "-c", "pass"], cwd=copy, env=environment) for _ in range(repeats)]
    return {"csv_bytes": (now / "contacts.csv").stat().st_size, "same": same, "export": times,
            "first": first, "cold": cold, "warm": warm, "stages": [statistics.median(s) for s in zip(*stages)],
            "python": statistics.median(bare)}


def table(path: Path, described: str, numbers: dict, repeats: int, commit: str) -> str:
    """The markdown of the measurements."""
    import platform

    med = statistics.median
    mb = numbers["csv_bytes"] / 1e6
    now, before = med(numbers["export"]["now"]), med(numbers["export"]["before"])
    imported, parser, summary = numbers["stages"]
    load = os.getloadavg()
    lines = [
        "# `grainview export --to csv` and `grainview info` on a study-sized file",
        "",
        f"Made by `python -m benchmarks.cli_io` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, commit "
        f"{commit} (machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores shared with other "
        f"jobs; load averages {load[0]:.1f}, {load[1]:.1f}, {load[2]:.1f} at the end). The file: {described} "
        f"({path.stat().st_size / 2**20:.1f} MiB). Medians of {repeats} fresh processes each, timed from outside "
        "(Python's start and the imports included).",
        "",
        "| command | time | CSV | rate |",
        "|---|---|---|---|",
        f"| `export --to csv`, one snapshot's table after another (before) | {before:.1f} s | {mb:.1f} MB | "
        f"{mb / before:.1f} MB/s |",
        f"| `export --to csv`, a block of snapshots at a time (now) | {now:.1f} s | {mb:.1f} MB | "
        f"{mb / now:.1f} MB/s |",
        f"| `info`, the first run after installing (grainview's modules compiled on the way) | "
        f"{med(numbers['first']):.2f} s (range {min(numbers['first']):.2f}-{max(numbers['first']):.2f}) | | |",
        f"| `info`, cold (the file's pages dropped from the page cache) | {med(numbers['cold']):.2f} s "
        f"(range {min(numbers['cold']):.2f}-{max(numbers['cold']):.2f}) | | |",
        f"| `info`, warm (the same command again) | {med(numbers['warm']):.2f} s "
        f"(range {min(numbers['warm']):.2f}-{max(numbers['warm']):.2f}) | | |",
        "",
        f"The two exports wrote the same bytes: {'yes' if numbers['same'] else 'NO'}; now {before / now:.1f}x faster. "
        f"A warm `info`: the interpreter alone {numbers['python']:.2f} s, importing grainview.app.cli "
        f"{imported:.2f} s (numpy and netCDF4 among it), building the command line's parser {parser:.2f} s, the "
        f"summary itself (reading the file, the checks, the lines) {summary:.2f} s.",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--file", type=Path, help="a run's file (default: a synthetic series of the sizes below)")
    parser.add_argument("--snapshots", type=int, default=201, help="snapshots of the synthetic file (default 201)")
    parser.add_argument("--contacts", type=int, default=1206, help="contacts per snapshot of the synthetic file "
                        "(default 1206)")
    parser.add_argument("--repeats", type=int, default=5, help="fresh processes per measurement (default 5)")
    parser.add_argument("--sources", type=Path, default=ROOT, help="folder holding the grainview and solver "
                        "packages to measure (default: this repository's)")
    parser.add_argument("--commit", help="the commit --sources holds, for the table (default: this repository's "
                        "HEAD, marked when its packages have uncommitted changes)")
    parser.add_argument("--out", type=Path, help="markdown file to write (default: print)")
    args = parser.parse_args(argv)
    commit = args.commit
    if commit is None:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=ROOT).stdout.strip()
        changed = subprocess.run(["git", "status", "--porcelain", "grainview", "solver"], capture_output=True,
                                 text=True, cwd=ROOT).stdout.strip()
        commit += " with uncommitted changes" if changed else ""
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        if args.file is not None:
            path = args.file.resolve()
            described = f"{args.file.name}, a run's file"
        else:
            path = synthetic_file(folder, args.snapshots, args.contacts)
            described = (f"a synthetic harmonic-model series of {args.snapshots} snapshots x {args.contacts} contacts, "
                         "compressed")
        text = table(path, described, measure(path, folder, args.repeats, args.sources.resolve()), args.repeats,
                     commit)
    if args.out:
        args.out.write_text(text)
    else:
        print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
