"""One command for every current benchmark: each writes its section file under
benchmarks/results/, and benchmarks/RESULTS.md is assembled from those files.

    python -m benchmarks                    # every section (hours on 2 cores), then RESULTS.md
    python -m benchmarks --quick            # each section at tiny sizes (minutes): checks they run
    python -m benchmarks --only scaling,parallel   # some sections, then RESULTS.md again
    python -m benchmarks --assemble         # RESULTS.md from the section files as they are
    python -m benchmarks --list             # the sections and what each runs

A section is one benchmark run in a fresh process (``python -m benchmarks.<module> ...``, the
arguments in :data:`SECTIONS`); it writes ``benchmarks/results/<name>.md`` with the date,
commit and machine of its run. After the sections the command assembles RESULTS.md from every
section file, measured now or before (:func:`assemble`; ``--assemble`` does only that), so
RESULTS.md always holds the latest run of each section and says when each was taken. A
``--quick`` run writes its sections and its RESULTS.md under benchmarks/_data/quick/ (not
committed) and leaves the committed files alone. A section that fails keeps its previous file
and the command goes on with the next one; the exit status says whether any failed.

The dense samples the shear benchmarks start from (``benchmarks/_data/samples/``) are compacted
first when missing (benchmarks/compaction.py, the ``fast`` route; hours at 14,400 particles).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS_DIR = os.path.join(HERE, "results")
RESULTS = os.path.join(HERE, "RESULTS.md")
QUICK_DIR = os.path.join(HERE, "_data", "quick")


def sample(shape: str, particles: int) -> str:
    """The cached dense sample of ``particles`` particles of ``shape`` (solver_bench.scaling)."""
    return os.path.join(HERE, "_data", "samples", f"{shape}_{particles}_fast.pkl")


@dataclass(frozen=True)
class Section:
    """One section of RESULTS.md: the benchmark module that measures it and its arguments.

    ``full`` and ``quick`` are the module's arguments for a full and a quick run (``quick``
    None: the section has no quick form and a quick run leaves it out). ``out`` is the module's
    option that names the file it writes (None: a full run writes the section's file itself,
    and a quick run prints its Markdown, which is written to the quick folder). ``samples``
    are the (shape, particles) of the dense samples the full run needs, ``quick_samples`` those
    of the quick run."""
    name: str
    module: str
    summary: str
    full: tuple
    quick: tuple | None = None
    out: str | None = "--out"
    samples: tuple = ()
    quick_samples: tuple = ()

    def path(self, folder: str = RESULTS_DIR) -> str:
        return os.path.join(folder, f"{self.name}.md")

    def command(self, quick: bool, folder: str) -> list:
        """The command line that measures the section into ``folder``."""
        args = list(self.quick if quick else self.full)
        if self.out:
            args += [self.out, self.path(folder)]
        root = os.path.dirname(HERE)  # the commands run there: paths relative to it
        args = [os.path.relpath(a, root) if a.startswith(root + os.sep) else a for a in args]
        return [sys.executable, "-m", f"benchmarks.{self.module}"] + args


def _solver_section(name: str, summary: str) -> Section:
    return Section(name, "sections", summary, (name.replace("-", "_"),), (name.replace("-", "_"), "--quick"))


def _shear_section(name, module, summary, particles, full, quick=None):
    quick_args = None if quick is None else ("--sample", sample("pentagon", 200)) + quick
    return Section(name, module, summary, ("--sample", sample("pentagon", particles)) + full, quick_args,
                   samples=(("pentagon", particles),), quick_samples=(("pentagon", 200),) if quick else ())


SECTIONS = (
    _solver_section("scaling", "time per step, per particle and per point-sweep on dense samples of 1000-14,400 "
                               "particles, serial and on 2 domains; loose 57,600"),
    _solver_section("work-precision", "run time against the error of q/p, eps_p and the forces, over tolerances, "
                                      "time steps and fixed sweep counts"),
    _solver_section("acceleration", "sweeps at equal accuracy: Anderson and other candidates against the NLGS"),
    _solver_section("peers", "Box2D and pymunk on the same settled piles: time and floor-force error"),
    _solver_section("analysis", "contacts per second of the analyses, eager and lazy"),
    _solver_section("skipping", "what a scene does not need costs nothing"),
    _solver_section("stress", "numerical stress tests: fast compaction, large steps, collapsing piles"),
    _solver_section("ensemble", "ensembles on dask.distributed: runner efficiency, out-of-core analysis"),
    _shear_section("sweep-cost-4000", "sweep_cost", "ns per point and sweep on captured problems, serial and on "
                   "2 domains", 4000, ("--first", "100", "--count", "8", "--sweeps", "40", "--repeats", "5",
                                       "--strips", "1,2", "--threads", "2"),
                   ("--first", "5", "--count", "2", "--sweeps", "5", "--repeats", "1")),
    _shear_section("sweep-cost-14400", "sweep_cost", "the same at 14,400", 14400,
                   ("--first", "100", "--count", "8", "--sweeps", "40", "--repeats", "3", "--strips", "1,2",
                    "--threads", "2")),
    _shear_section("sweep-stages-4000", "sweep_cost", "an Anderson solve's passes, ns per point", 4000,
                   ("--first", "100", "--count", "6", "--sweeps", "40", "--stages"),
                   ("--first", "5", "--count", "2", "--sweeps", "5", "--stages")),
    _shear_section("sweep-stages-14400", "sweep_cost", "the same at 14,400", 14400,
                   ("--first", "100", "--count", "6", "--sweeps", "40", "--stages")),
    _shear_section("step-profile-4000", "step_profile", "where a step's time goes, stage by stage, on 1 and 2 "
                   "domains", 4000, ("--domains", "1,2", "--skip", "300", "--steps", "300", "--repeats", "4"),
                   ("--domains", "1,2", "--skip", "5", "--steps", "5", "--repeats", "1")),
    _shear_section("step-profile-14400", "step_profile", "the same at 14,400", 14400,
                   ("--domains", "1,2", "--skip", "200", "--steps", "200", "--repeats", "2")),
    Section("step-variants", "step_variants", "whole steps of every way of solving, each on its own trajectory",
            ("--build", "--particles", "1000", "--serial", "--steps", "3000")),
    _shear_section("portable-sums", "portable_sums", "what the fixed-order (processor-independent) sums of the "
                   "Anderson history cost against the reassociated ones of b3039cc: the kernels, whole steps and "
                   "solves of the same problems", 2000, (), ("--quick",)),
    Section("contact-solvers", "contact_solvers", "the problem-level methods (nlgs, newton, pcg) on Siconos' and "
            "the stepper's problems", ()),
    Section("two-level", "two_level", "a two-level method (NLGS sweeps + an AMG V-cycle on the truncated face, "
            "TNNMG-style; needs pyamg) against the NLGS on the same problems", ()),
    Section("proximal", "proximal", "a proximal-point loop around the semi-smooth Newton, and ADMM and interior-point "
            "probes, on the same problems", ()),
    Section("body-admm", "body_admm", "ADMM in body space (M + rho H^T H) against the NLGS on the stepper's problems "
            "at 1000, 4000, 14,400 pentagons", ()),
    Section("compliance", "compliance", "a compliant contact law (W + eps diag W): NLGS and pcg to 1e-4 on the stepper's "
            "problems, and what it changes against the rigid answer", ()),
    Section("stopping-rule", "stopping_rule", "what a step needs (body velocities, sign conditions) against what the "
            "NLGS's stopping test tracks, sweep by sweep, on the stepper's problems at 1000, 4000, 14,400 pentagons", ()),
    Section("parallel", "parallel", "one sweep and 300 steps of a fixed problem on 2 domains", (), ("--quick",)),
    Section("compaction", "compaction", "the compaction routes: steps, sweeps, time and the state reached",
            ("--particles", "1000", "--seeds", "0,1,2", "--routes", "paper,fast", "--acceleration", "anderson",
             "--out", os.path.join(HERE, "_data", "compaction-section.jsonl")),
            ("--particles", "60", "--seeds", "0", "--routes", "fast", "--acceleration", "anderson",
             "--out", os.path.join(QUICK_DIR, "compaction.jsonl")), out="--results"),
    Section("force-chains", "force_chains", "force chains: contacts per second", (), ("--quick",), out=None),
    Section("coarse-graining", "coarse_graining", "coarse-grained fields: 14,400 particles x 100 snapshots",
            (), ("--quick",), out=None),
    Section("network-topology", "network_topology", "persistent homology of the force network",
            ("--repeats", "7"), ("--repeats", "1")),
    Section("compression", "compression", "compressed files: size, speed of the analyses, memory",
            ("--repeats", "3")),
    Section("checksums", "checksums", "the Fletcher-32 checksums of finished files: size and read speed",
            ("--repeats", "15"), ("--quick",)),
    Section("lammps-convert", "lammps_convert", "`grainview convert lammps` on a large run: time and memory", ()),
    Section("cli-io", "cli_io", "`grainview export --to csv` and `grainview info` on a study-sized file: time",
            ("--repeats", "5"), ("--repeats", "1", "--snapshots", "20", "--contacts", "200")),
    Section("study-time", "study_time", "`grainview warmup` and `grainview study` with the kernels compiled and "
            "not: wall time, first line, stages' processor time, the study's own estimate",
            (), ("--runs", "warmup-warm,study-warm", "--study-args", "--particles 20 --strain 0.002", "--pause", "0")),
    Section("periodic-shear", "periodic_shear", "the periodic simple shear against the walled biaxial test at equal N: "
            "processor time per particle-step and per sweep over whole tests",
            ("--whole", "0.2", "--ways", "walled,periodic,periodic:1"), ("--quick",)),
    Section("periodic-control", "periodic_control", "a periodic cell's height under a normal stress: how steadily "
            "sigma_yy holds sigma0, and the sweeps and time it costs, per cell mass and solver", (), ("--quick",)),
    Section("wall-control", "wall_control", "the walled test's stress-controlled wall: how steadily sigma_xx holds "
            "sigma0 and p over the residual window, per mass of the wall", (), ("--quick",)),
    Section("wall-motion", "wall_motion", "the walled tests' right wall: its stress, motion and free-flight time, "
            "and p across the sample, over the residual window (reads the fidelity study's files)", (), ("--quick",)),
)
"""The current benchmarks, in the order of RESULTS.md. benchmarks/README.md says what each measures."""

BY_NAME = {s.name: s for s in SECTIONS}


def _demoted(text: str) -> str:
    """``text`` with every Markdown heading one level deeper (outside code blocks)."""
    out, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        out.append("#" + line if not fenced and re.match(r"#{1,5} ", line) else line)
    return "\n".join(out)


def _run_date(text: str) -> str:
    """When a section file says it was measured (its 'Run on ...' or 'Made by ... on ...' line)."""
    found = re.search(r"(\d{4}-\d{2}-\d{2}(?: \d{2}:\d{2} UTC)?)", text)
    return found.group(1) if found else "undated"


def _anchor(title: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")


def assembled(folder: str = RESULTS_DIR, sections=SECTIONS, note: str = "", base: str = HERE) -> str:
    """RESULTS.md's text from the section files in ``folder``, in the order of ``sections``: a
    header, a table of contents giving each section's date, then each file with its headings
    one level down and its links made relative to ``base`` (the folder RESULTS.md is written
    to). A missing file is listed as not measured. The text depends on the section files
    alone, so the committed RESULTS.md can be checked against them."""
    rel = os.path.relpath(folder, base)
    contents, bodies = [], []
    for section in sections:
        path = section.path(folder)
        if not os.path.exists(path):
            contents.append(f"| {section.name} | {section.summary} | not measured |")
            continue
        text = open(path).read().strip()
        title = text.splitlines()[0].lstrip("# ").strip() if text.startswith("# ") else section.name
        contents.append(f"| [{section.name}](#{_anchor(title)}) | {section.summary} | {_run_date(text)} |")
        text = re.sub(r"(!?\[[^\]]*\]\()(?!https?:|#|/)([^)]+\))", lambda m: m.group(1) + os.path.join(rel, m.group(2)),
                      text)
        bodies.append(_demoted(text if text.startswith("# ") else f"# {section.name}\n\n{text}"))
    header = ["# Benchmark results", "",
              f"Assembled by `python -m benchmarks` from the section files in `{rel}/`: "
              "each section is the latest run of its benchmark and says when, on which commit and machine it was "
              "measured (the table's last column). "
              "benchmarks/README.md says what each benchmark is and how to run it, docs/benchmarks.md how to "
              "read the tables; past studies are in benchmarks/archive/.", ""]
    if note:
        header += [note, ""]
    header += ["| section | what | measured |", "|---|---|---|"] + contents + [""]
    return "\n".join(header) + "\n" + "\n\n".join(bodies) + "\n"


def assemble(folder: str = RESULTS_DIR, output: str = RESULTS, sections=SECTIONS, note: str = "") -> str:
    """Write ``output`` (RESULTS.md) from the section files in ``folder`` (:func:`assembled`);
    returns its text."""
    text = assembled(folder, sections, note, os.path.dirname(os.path.abspath(output)))
    with open(output, "w") as fh:
        fh.write(text)
    return text


def _ensure_samples(samples, log=print) -> None:
    """Compact the dense samples that are not cached yet (solver_bench.scaling.build_sample)."""
    for shape, particles in samples:
        if not os.path.exists(sample(shape, particles)):
            from benchmarks.solver_bench.scaling import build_sample

            log(f"compacting the dense sample of {particles} {shape}s (benchmarks/compaction.py, 'fast' route)")
            build_sample(shape, particles)


def measure(section: Section, quick: bool, folder: str, log=print) -> bool:
    """Run ``section``'s benchmark into its file in ``folder``; True when it succeeded. A
    failed run leaves the section's previous file as it was."""
    try:
        _ensure_samples(section.quick_samples if quick else section.samples, log)
    except Exception as exc:  # a sample that cannot be made fails its section, not the run
        log(f"the dense samples of {section.name} could not be made: {exc!r}")
        return False
    command = section.command(quick, folder)
    log("$ python " + " ".join(command[1:]), flush=True)
    root = os.path.dirname(HERE)
    if section.out or not quick:
        return subprocess.run(command, cwd=root).returncode == 0
    done = subprocess.run(command, cwd=root, stdout=subprocess.PIPE, text=True)
    if done.returncode != 0:
        return False
    text = done.stdout
    title = re.search(r"^# ", text, flags=re.M)  # the Markdown starts at its title; progress lines before it
    with open(section.path(folder), "w") as fh:
        fh.write((text[title.start():] if title else text).strip() + "\n")
    return True


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, into benchmarks/_data/quick/: checks "
                        "that every section runs (the committed files are left alone)")
    parser.add_argument("--only", help="comma-separated sections (default: all; --list names them)")
    parser.add_argument("--assemble", action="store_true", help="only assemble RESULTS.md from the section files")
    parser.add_argument("--list", action="store_true", help="list the sections and their commands")
    args = parser.parse_args(argv)
    wanted = SECTIONS
    if args.only:
        names = [n.strip() for n in args.only.split(",") if n.strip()]
        unknown = [n for n in names if n not in BY_NAME]
        if unknown:
            parser.error(f"--only {args.only}: unknown section(s) {', '.join(unknown)}; expected some of "
                         f"{', '.join(BY_NAME)}")
        wanted = [BY_NAME[n] for n in names]
    folder, output = (QUICK_DIR, os.path.join(QUICK_DIR, "RESULTS.md")) if args.quick else (RESULTS_DIR, RESULTS)
    if args.list:
        for s in wanted:
            form = s.quick if args.quick else s.full
            line = "(no quick form)" if form is None else " ".join(["python"] + s.command(args.quick, folder)[1:])
            print(f"{s.name}: {s.summary}\n    {line}")
        return 0
    failed = []
    if not args.assemble:
        os.makedirs(folder, exist_ok=True)
        for s in wanted:
            if args.quick and s.quick is None:
                print(f"== {s.name}: no quick form, left out", flush=True)
                continue
            print(f"== {s.name}", flush=True)
            start = time.perf_counter()
            if not measure(s, args.quick, folder):
                failed.append(s.name)
                print(f"== {s.name} FAILED; its previous file is kept", flush=True)
            else:
                print(f"== {s.name}: {time.perf_counter() - start:.0f} s", flush=True)
    note = "QUICK run: tiny sizes, the numbers only check that the benchmarks run." if args.quick else ""
    assemble(folder, output, SECTIONS, note)
    print(f"wrote {os.path.relpath(output)}" + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
