"""What the Fletcher-32 checksums of finished files cost: size, and the speed of reading.

    python -m benchmarks.checksums [FILE] [--snapshots 40 --contacts 100000] [--repeats 5] [--out PATH] [--quick]

Without FILE, a synthetic series of ``--snapshots`` x ``--contacts`` (every slot a contact;
benchmarks/analysis.py's writer) is written into a temporary folder. The file is compressed
twice, as a finished run is (grainview.contract.writer.compress_file): with checksums, as
grainview writes it now, and without (``writer.CHECKSUMS = False``, as files were compressed
before). Then, in turns within each of ``--repeats`` rounds (the two files read alternately,
after one warm-up read of each so both are in the page cache): every stored chunk of every
variable read with netCDF4 (what ``grainview info --check`` does first,
grainview.contract.file_checks.damaged_chunks), and two analyses lazily from
grainview.open_dataset's default chunks (stress invariants, force anisotropies). The table gives
medians and the ratio of the two files' times (with / without; 1 = as fast), and the median and
range of the rounds' own ratios, from this one run.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))

CASES = {
    "every chunk read (info --check's first pass)": None,
    "stress invariants": lambda ds: ds.grain.stress_invariants()["q_over_p"],
    "force anisotropies": lambda ds: ds.grain.force_anisotropies(),
}


def compressed(source: str, path: str, checksums: bool) -> float:
    """``source`` copied to ``path`` and compressed with or without checksums; seconds."""
    import grainview.contract.writer as writer

    shutil.copy(source, path)
    writer.decompress_file(path)
    original = writer.CHECKSUMS
    writer.CHECKSUMS = checksums
    try:
        start = time.perf_counter()
        writer.compress_file(path)
        return time.perf_counter() - start
    finally:
        writer.CHECKSUMS = original


def timed(path: str, case: str) -> float:
    """Seconds of one read of ``path``: every chunk with netCDF4, or one analysis, lazily."""
    import netCDF4

    import grainview
    from grainview.contract.file_checks import damaged_chunks

    if CASES[case] is None:
        start = time.perf_counter()
        with netCDF4.Dataset(path) as nc:
            problems = damaged_chunks(nc.variables)
        assert problems == [], problems
        return time.perf_counter() - start
    with grainview.open_dataset(path) as ds:
        start = time.perf_counter()
        result = CASES[case](ds)
        if hasattr(result, "compute"):
            result.compute()
        return time.perf_counter() - start


def filters(path: str) -> str:
    """Which variables carry a checksum and which are deflated."""
    import netCDF4

    with netCDF4.Dataset(path) as nc:
        f32 = [n for n, v in nc.variables.items() if v.ndim and v.filters()["fletcher32"]]
        deflated = [n for n, v in nc.variables.items() if v.ndim and v.filters()["zlib"]]
        return (f"{len(f32)} of {sum(1 for v in nc.variables.values() if v.ndim)} variables with a checksum; "
                f"deflated: {', '.join(deflated) or 'none'}")


def measure(source: str, repeats: int, folder: str) -> dict:
    """Sizes, compression times and read times of the two files made from ``source``."""
    files = {"with checksums": os.path.join(folder, "with.nc"), "without": os.path.join(folder, "without.nc")}
    seconds = {name: compressed(source, path, name == "with checksums") for name, path in files.items()}
    import grainview

    with grainview.open_dataset(files["without"], chunks=None) as ds:
        contacts = int(ds["contact_count"].sum())
        shape = (f"{ds.sizes['particle']:,} particles, {ds.sizes['time']} snapshots, {ds.sizes['contact']:,} "
                 f"contact slots, {contacts:,} contacts")
    for case in CASES:  # warm-up: numba's kernels, the page cache
        for path in files.values():
            timed(path, case)
    times = {(name, case): [] for name in files for case in CASES}
    for round_ in range(repeats):
        order = list(files) if round_ % 2 == 0 else list(files)[::-1]
        for case in CASES:
            for name in order:
                times[name, case].append(timed(files[name], case))
    ratios = {case: [a / b for a, b in zip(times["with checksums", case], times["without", case])] for case in CASES}
    return {"shape": shape, "sizes": {name: os.path.getsize(path) for name, path in files.items()},
            "compress_s": seconds, "median": {key: statistics.median(v) for key, v in times.items()},
            "ratios": ratios,
            "filters": {name: filters(path) for name, path in files.items()}}


def table(label: str, result: dict, repeats: int) -> str:
    """The Markdown of one file's measurement."""
    sizes, median = result["sizes"], result["median"]
    lines = [f"## {label}", "", f"{result['shape']}. Medians of {repeats} rounds, the two files read in turn "
             "within each round (their order reversed every other round).", "",
             "| file | size (bytes) | size / without | compress_file (s) |", "|---|---|---|---|"]
    for name in sizes:
        lines.append(f"| {name} | {sizes[name]:,} | {sizes[name] / sizes['without']:.4f} | "
                     f"{result['compress_s'][name]:.2f} |")
    lines += ["", "; ".join(f"{name}: {text}" for name, text in result["filters"].items()), "",
              "| read | with checksums (s) | without (s) | time with / without | the rounds' ratios: median "
              "(range) |", "|---|---|---|---|---|"]
    for case in CASES:
        a, b = median["with checksums", case], median["without", case]
        ratios = result["ratios"][case]
        lines.append(f"| {case} | {a:.3f} | {b:.3f} | {a / b:.2f} | {statistics.median(ratios):.2f} "
                     f"({min(ratios):.2f}-{max(ratios):.2f}) |")
    lines += ["", "Times are medians; a round's ratio divides its two reads of the same case, taken one after the "
              "other, so the machine's load drifts less between them."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", nargs="?", help="a file of the contract (default: a synthetic series)")
    parser.add_argument("--snapshots", type=int, default=40)
    parser.add_argument("--contacts", type=int, default=100_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="a tiny series and 1 round: checks that it runs")
    parser.add_argument("--out", help="markdown file to write (default: print only)")
    args = parser.parse_args(argv)
    if args.quick:
        args.snapshots, args.contacts, args.repeats = 3, 2000, 1
    warnings.simplefilter("ignore")
    from benchmarks.common import measured, results_text, write_text_keeping_notes

    with tempfile.TemporaryDirectory() as folder:
        source = args.file
        if source is None:
            from benchmarks.analysis import write_series

            source = os.path.join(folder, "series.nc")
            write_series(source, args.snapshots, args.contacts)
        label = os.path.basename(source) if args.file else f"Synthetic series, {args.snapshots} x {args.contacts:,}"
        result, how = measured(lambda: measure(source, args.repeats, folder))
    intro = ("Made by `python -m benchmarks.checksums` (the module's docstring says what it does). A finished run "
             "is compressed with HDF5's Fletcher-32 checksum on every chunk (docs/schema.md, \"Checksums\"); here the "
             "same file compressed with and without them. The ratios come from one run on a shared machine. " + how)
    text = results_text("Checksums of finished files: size and read speed", intro, [table(label, result, args.repeats)])
    if args.out:
        write_text_keeping_notes(args.out, text)
        print(f"wrote {args.out}")
    print(text)


if __name__ == "__main__":
    main()
