"""Shared helpers of the benchmarks: machine description, medians of repeated timings, peak
memory of a measurement run in a fresh process, Markdown tables and results files, how a row
was solved in words."""

from __future__ import annotations

import datetime
import multiprocessing as mp
import os
import platform
import resource
import statistics
import subprocess
import time


def machine_description() -> str:
    """One Markdown paragraph: date, CPU, cores, memory, Python and library versions."""
    import dask
    import numba
    import numpy
    import xarray

    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=os.path.dirname(__file__)).stdout.strip()
    except OSError:
        commit = "?"
    return (f"Run on {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M UTC}, commit {commit}; "
            f"{cpu}, {os.cpu_count()} cores, {mem_gib:.0f} GiB; Python {platform.python_version()}, "
            f"numpy {numpy.__version__}, numba {numba.__version__}, xarray {xarray.__version__}, "
            f"dask {dask.__version__}.")


def median_time(func, repeats=5, warmup=1):
    """Median wall time of ``func()`` over ``repeats`` calls after ``warmup`` calls (s)."""
    for _ in range(warmup):
        func()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def _child(queue, func, args):
    try:
        result = func(*args)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # MiB on Linux
        queue.put((result, peak, None))
    except BaseException as exc:  # report, do not hang the parent
        queue.put((None, None, repr(exc)))


def in_fresh_process(func, *args):
    """Run ``func(*args)`` in a fresh process; return (result, peak resident memory in MiB)."""
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_child, args=(queue, func, args))
    proc.start()
    result, peak, error = queue.get()
    proc.join()
    if error:
        raise RuntimeError(f"benchmark child failed: {error}")
    return result, peak


def markdown_table(header, rows) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def capture_contact_problems(sim, steps: int = 1) -> list:
    """Step ``sim`` ``steps`` times and return each step's contact problem as its solver
    receives it (:meth:`solver.stepper.Simulation.contact_problem`): ``(problem, pn, pt, vx, vy,
    w, options)`` with copies of the warm-start impulses and the free velocities, and the
    stopping limits as keywords (tolerance, max_tolerance, max_iterations, stall). The steps
    run as usual, whatever the solver."""
    seen = []
    for _ in range(steps):
        posed = sim.contact_problem()
        seen.append((posed.problem, *(a.copy() for a in posed.state), posed.limits._asdict()))
        sim.step()
    return seen


def sheared_sample(shape: str, particles: int, strain: float, folder: str):
    """A sample of ``shape`` at ``particles`` compacted with the 'fast' preparation (plain
    serial NLGS, no stall test) and sheared to eps_1 = ``strain`` (top wall 1 cm/s, sigma0 =
    10 kPa, dt = 5e-4 s), warnings silenced: the start of the benchmarks that compare ways of
    solving. The shear's file is written in ``folder`` and removed."""
    import warnings

    import solver
    from solver.preparation import prepare_sample, preparation

    os.makedirs(folder, exist_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(preparation("fast", shape=shape, particles=particles), progress=False,
                             solver="nlgs", stall_sweeps=0)
        path = os.path.join(folder, f"{shape}_{particles}_shear.nc")
        solver.biaxial_test(sim, path, strain=strain, velocity=0.01, every=10**9, overwrite=True, progress=False)
    os.remove(path)
    return sim


def save_sample(path: str, sim, seconds: float) -> None:
    """Pickle a compacted simulation and its compaction's seconds to ``path``, whole or not at
    all (written beside it, then renamed): the sample files of compaction.py ``--save`` and
    time_to_strain.py's cache."""
    import pickle

    with open(path + ".part", "wb") as fh:
        pickle.dump((sim, seconds), fh)
    os.replace(path + ".part", path)


def load_sample(path: str):
    """The compacted simulation and its compaction's seconds from a file of :func:`save_sample`."""
    import pickle

    with open(path, "rb") as fh:
        return pickle.load(fh)


def way_of_solving(row: dict) -> str:
    """How a benchmark row's contact problems were solved, in words: its ``solver`` (rows from
    before it: the method their ``acceleration`` names, :data:`solver.contact_solvers.ACCELERATIONS`,
    plain sweeps without one) with the options the method reads that the row holds
    (:attr:`solver.contact_solvers.Method.parameters`), ``stall_sweeps`` and ``domains`` (rows
    from before an option existed: no stall test, one domain)."""
    from solver import contact_solvers

    name = row["solver"] if "solver" in row else contact_solvers.from_acceleration(row.get("acceleration", "off"))
    how = name + "".join(f", {keyword} {row[field]}" for field, keyword in contact_solvers.method(name).parameters
                         if field in row)
    stall = row.get("stall_sweeps", 0)
    domains = row.get("domains", 1)
    return how + (f", stall {stall}" if stall else "") + (f", {domains} domains" if domains > 1 else "")


NOTES_MARKER = "<!-- notes: written by hand, kept when the benchmark rewrites this file -->"
"""The line of a results file below which its text is a person's (what the numbers say, a
second run by hand, the targets): :func:`write_text_keeping_notes` keeps it."""


def write_text_keeping_notes(path: str, text: str) -> str:
    """Write a results file's generated ``text`` to ``path``, keeping what the file it replaces
    holds from :data:`NOTES_MARKER` on (a person's notes; they may now speak of older numbers,
    so a line on stdout says so). Returns what was written."""
    notes = ""
    if os.path.exists(path):
        with open(path) as fh:
            old = fh.read()
        if NOTES_MARKER in old:
            notes = old[old.index(NOTES_MARKER):]
            print(f"{path}: the notes below its marker were kept; check that they still match the new numbers")
    whole = text.rstrip("\n") + "\n\n" + notes if notes else text
    with open(path, "w") as fh:
        fh.write(whole)
    return whole


def results_text(title: str, intro: str, sections: list) -> str:
    """A results file's generated text: the ``title``, the ``intro`` paragraph, the machine
    description and the ``sections``, each followed by a blank line."""
    return "\n".join([f"# {title}", "", intro, "", machine_description(), ""] + [line for section in sections
                                                                              for line in (section, "")])


def measured(run, how: str = ""):
    """Call ``run()`` and say how it ran: returns (its result, one sentence with the load
    averages at the start and the end, the wall time, ``how`` (e.g. "one thread (nice)") and the
    git HEAD after the run), for a results file's header."""
    load = os.getloadavg()
    start = time.perf_counter()
    result = run()
    elapsed = time.perf_counter() - start
    load_end = os.getloadavg()
    head = subprocess.run(["git", "log", "-1", "--format=%h %s"], capture_output=True, text=True).stdout[:80]
    return result, (f"Load average (1, 5, 15 min) at the start {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f}; at the "
                    f"end {load_end[0]:.2f}, {load_end[1]:.2f}, {load_end[2]:.2f}; {elapsed:.0f} s of wall time"
                    + (f"; {how}" if how else "") + f". HEAD: {head.strip()}")


def write_results(path: str, title: str, intro: str, sections: list) -> str:
    """Write a RESULTS-*.md file (:func:`results_text`), then the notes of the file it replaces
    (:func:`write_text_keeping_notes`); print the generated text and return it."""
    text = results_text(title, intro, sections)
    write_text_keeping_notes(path, text)
    print(text)
    return text


def print_or_write(path, title: str, intro: str, sections: list, quick: bool = False) -> str:
    """A benchmark's results: a ``quick`` run with no file given (``path`` None) is printed only;
    any other run is written to ``path`` (:func:`write_results`); a quick run's title says so.
    Returns the text."""
    title = title + (" (quick)" if quick else "")
    if path is None:
        text = results_text(title, intro, sections)
        print(text)
        return text
    return write_results(path, title, intro, sections)


def run_and_record(description: str, run, results_name: str, argv=None) -> None:
    """The command line of a benchmark whose ``run(quick=...)`` returns its results as text:
    ``--quick`` runs a short version and prints it only; without it the text is printed and
    written to ``benchmarks/<results_name>``. Any other argument (``--help`` included) is
    answered by argparse before anything is measured."""
    import argparse

    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--quick", action="store_true", help=f"a short run, printed only (benchmarks/{results_name} "
                        "is kept)")
    quick = parser.parse_args(argv).quick
    text = run(quick=quick)
    print(text)
    if not quick:
        write_text_keeping_notes(os.path.join(os.path.dirname(os.path.abspath(__file__)), results_name), text)
