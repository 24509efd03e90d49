"""How long ``grainview study`` and ``grainview warmup`` take, with numba's cache of compiled
kernels empty (a fresh machine: every kernel compiled) and filled (every later run), and when
each of their lines appears.

    python -m benchmarks.study_time [--runs warmup-cold,warmup-warm,study-cold,study-warm,calibration]
                                    [--study-args "--jobs 1"] [--sources DIR --commit C]
                                    [--cache DIR] [--pause 120] [--out results/study-time.md]

Every run is a fresh process of the command line, timed from outside, with ``NUMBA_CACHE_DIR``
set to a folder of its own: ``-cold`` runs start from an empty folder, ``-warm`` runs reuse the
folder the cold run of the same command filled (a ``-warm`` run without its cold run first fills
one with ``grainview warmup``, or copies ``--cache``). Each of the command's lines (stdout and
stderr; the study's progress lines left out of the table) is timestamped as it arrives, with the
1-minute load average then and the processor time (user + system) used so far by the command
and its worker processes, so the table gives the time to the first line, to each stage and to
the end, and what each stage cost in processor time: the time it takes on a core with nothing
else on it, which grainview/app/paper_size.py's 400-particle costs, ``COMPILE_SECONDS`` and
``REPORT_SECONDS`` are taken from (the ``calibration`` run: a ``--jobs 1`` study runs its stages
one after the other in one process, so the processor time between two of its lines is that
stage's). The study's own
estimate (its ``estimate: the study ~...`` line) is quoted beside the measured time. The load
averages at the start (1, 5 and 15 minutes) and the mean of the 1-minute one over the run
(sampled every 5 s) are part of the result on a shared machine.

The code measured is this repository's grainview and solver packages, or those of ``--sources``
(a folder holding both, e.g. ``git archive <commit> grainview solver | tar -x -C DIR``: a commit
measured apart from uncommitted changes; ``--commit`` names it). Writes a markdown file to
``--out`` (default: print it).
"""

from __future__ import annotations

import argparse
import os
import shlex
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RUNS = ("warmup-cold", "warmup-warm", "study-cold", "study-warm", "calibration")
"""What can be measured: each command on an empty and on a filled cache, and the calibration: a
``--jobs 1`` study on a filled cache, whose stages' processor times are their costs."""
PAUSE = 120.0
"""Seconds between two runs: the 1-minute load average decays as exp(-t / 60 s)."""
LOAD_EVERY = 5.0
"""Seconds between two samples of the load average."""
ENTRY = "import sys; from grainview.app.cli import main; sys.exit(main())"


def load_average() -> float:
    """The 1-minute load average."""
    return os.getloadavg()[0]


def load_averages() -> str:
    """The 1-, 5- and 15-minute load averages, in words."""
    return "/".join(f"{x:.1f}" for x in os.getloadavg())


def tree_cpu(pid) -> float:
    """Processor seconds (user + system) used so far by process ``pid`` and its living
    descendants, from /proc (0 where it cannot be read)."""
    parents, times = {}, {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(entry)] = int(fields[1])
        times[int(entry)] = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    tree, grew = {pid}, True
    while grew:
        more = {child for child, parent in parents.items() if parent in tree} - tree
        tree |= more
        grew = bool(more)
    return sum(times.get(p, 0.0) for p in tree)


def timed(argv, env, cwd) -> dict:
    """Run the command line with ``argv`` (a fresh process) and return ``{"wall": seconds, "cpu":
    processor seconds, "lines": [(seconds, stream, text, 1-minute load average then, processor
    seconds of the command so far)], "load_start": the 1-, 5- and 15-minute load averages at the
    start, "load_mean": the mean of the 1-minute one over the run, "rc"}``."""
    lines, lock = [], threading.Lock()
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-c", ENTRY, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env, cwd=cwd, bufsize=1)

    def read(stream, name):
        for text in stream:
            with lock:
                lines.append((time.monotonic() - start, name, text.rstrip("\n"), load_average(), tree_cpu(proc.pid)))

    readers = [threading.Thread(target=read, args=(proc.stdout, "out")),
               threading.Thread(target=read, args=(proc.stderr, "err"))]
    for reader in readers:
        reader.start()
    loads, waited, averages = [load_average()], time.monotonic(), load_averages()
    while True:  # wait4, not Popen.wait: it gives the processor time of the command and its workers
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        time.sleep(0.05)
        if time.monotonic() - waited >= LOAD_EVERY:
            loads.append(load_average())
            waited = time.monotonic()
    wall = time.monotonic() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    for reader in readers:
        reader.join()
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "lines": sorted(lines), "load_start": averages,
            "load_mean": sum(loads) / len(loads), "rc": proc.returncode}


def measure(runs, study_args, sources: Path, folder: Path, cache: Path | None = None, pause: float = 0.0) -> dict:
    """Each run of ``runs`` (names of :data:`RUNS`), in that order: {name: :func:`timed`'s dict};
    ``cache``: a filled cache folder of the same sources, copied for the warm runs that have no
    cold run before them (instead of a ``grainview warmup`` into an empty one); ``pause``:
    seconds to wait before each run after the first, so that the load average at a run's start
    (which the study's estimate reads) holds little of the previous run's own processes."""
    import shutil

    env = {**os.environ, "PYTHONPATH": str(sources)}
    env.pop("NUMBA_CACHE_DIR", None)
    results = {}
    for name in runs:
        command, state = name.split("-") if name != "calibration" else ("study", "warm")
        cache_dir = folder / f"cache-{command}"
        if state == "warm" and not cache_dir.exists():
            if cache is not None:
                shutil.copytree(cache, cache_dir)
            else:
                timed(["warmup"], {**env, "NUMBA_CACHE_DIR": str(cache_dir)}, folder)
        if state == "cold":
            cache_dir.mkdir()
        argv = ["warmup"] if command == "warmup" else ["study", "--out", str(folder / f"out-{name}"),
                                                         *shlex.split(study_args)]
        if name == "calibration":
            argv += ["--jobs", "1"]
        if results and pause:
            time.sleep(pause)
        print(f"study_time: {name} ...", file=sys.stderr, flush=True)
        results[name] = timed(argv, {**env, "NUMBA_CACHE_DIR": str(cache_dir)}, folder)
        print(f"study_time: {name}: {results[name]['wall']:.0f} s (rc {results[name]['rc']})", file=sys.stderr,
              flush=True)
    return results


def _minutes(seconds) -> str:
    return f"{seconds:.0f} s" if seconds < 90 else f"{seconds / 60:.1f} min"


def table(results, study_args, commit) -> str:
    """The markdown file: a summary row per run, then each run's lines with their times."""
    from benchmarks.common import machine_description

    out = ["# `grainview study` and `grainview warmup`: wall time, cold and warm cache", "",
           f"{machine_description()} Code measured: {commit}; the study's options: "
           f"{f'`{study_args}`' if study_args else 'the defaults'}.", "",
           "| run | wall time | processor time | first line after | load at start (1/5/15 min) / mean (cores) "
           "| the study's estimate | exit |",
           "|---|---|---|---|---|---|---|"]
    cores = os.cpu_count()
    for name, r in results.items():
        first = r["lines"][0][0] if r["lines"] else float("nan")
        said = ["~" + text.split("~", 1)[1].split(" of wall time", 1)[0] for _, _, text, _, _ in r["lines"]
                if text.startswith("estimate: the study ~")]
        out.append(f"| {name} | {_minutes(r['wall'])} | {_minutes(r['cpu'])} | {first:.1f} s | "
                   f"{r['load_start']} / "
                   f"{r['load_mean']:.1f} ({cores}) | {', '.join(said) or '-'} | {r['rc']} |")
    for name, r in results.items():
        out += ["", f"## {name}: the lines as they came", "", "```"]
        for seconds, stream, text, load, cpu in r["lines"]:
            if " of at most " in text and ": step " in text:
                continue  # a progress line
            out.append(f"{seconds:7.1f} s  cpu {cpu:7.1f} s  load {load:4.1f} {'!' if stream == 'err' else ' '} {text}")
        out.append("```")
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=",".join(RUNS), help=f"comma-separated, in order (default {','.join(RUNS)}; "
                        "calibration: a --jobs 1 study on a filled cache)")
    parser.add_argument("--study-args", default="", help="more options of grainview study, e.g. '--particles 100'")
    parser.add_argument("--sources", type=Path, default=ROOT, help="folder holding the grainview and solver "
                        "packages to measure (default: this repository's)")
    parser.add_argument("--commit", help="the commit --sources holds (default: this repository's HEAD, marked when "
                        "its packages have uncommitted changes)")
    parser.add_argument("--cache", type=Path, help="a numba cache folder filled for --sources (e.g. by grainview "
                        "warmup), copied for the warm runs instead of warming an empty one first")
    parser.add_argument("--pause", type=float, default=PAUSE, help=f"seconds to wait between runs (default {PAUSE:g}: "
                        "the 1-minute load average then holds about a seventh of the previous run's processes)")
    parser.add_argument("--out", type=Path, help="markdown file to write (default: print)")
    args = parser.parse_args(argv)
    runs = [r.strip() for r in args.runs.split(",") if r.strip()]
    unknown = [r for r in runs if r not in RUNS]
    if unknown:
        parser.error(f"--runs: unknown {', '.join(unknown)}; expected some of {', '.join(RUNS)}")
    commit = args.commit
    if commit is None:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=ROOT).stdout.strip()
        changed = subprocess.run(["git", "status", "--porcelain", "grainview", "solver"], capture_output=True,
                                 text=True, cwd=ROOT).stdout.strip()
        commit += " with uncommitted changes" if changed else ""
    with tempfile.TemporaryDirectory(prefix="study-time-") as scratch:
        results = measure(runs, args.study_args, args.sources.resolve(), Path(scratch), args.cache, args.pause)
        text = table(results, args.study_args, commit)
    if args.out:
        args.out.write_text(text)
    else:
        print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
