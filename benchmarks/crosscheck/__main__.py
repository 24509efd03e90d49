"""Cross-check: the same compacted samples sheared by the same biaxial test in three engines.

    nice -n 10 python -m benchmarks.crosscheck --jobs 2   # the full run (~1 h on 2 shared cores)
    python -m benchmarks.crosscheck --shape disk --particles 100 --strain 0.02   # a quick look

The engines: this project's solver (``engine_project.py``, its public API), Box2D 2.3
(``engines_box2d.py``) and pymunk (``engines_pymunk.py``); the peers run as subprocesses in their
own virtual environment (``benchmarks/requirements-peers.txt``; created under
``benchmarks/_data/crosscheck/venv-peers`` when missing, or given by ``--peer-python``).

Protocol (Azema et al., PRE 76, 011301, 2007, Sec. II.B): a sample of ``--particles`` regular
pentagons or disks (the paper's size mix), compacted isotropically under sigma0 = 10 kPa by
``grainview run isotropic`` (cached under ``benchmarks/_data/crosscheck/samples``); from its
last snapshot, in every engine: 2D, zero gravity, density 2600 kg/m3 in a 1 m thick slab (the
sample's masses and moments of inertia), grain friction 0.4, frictionless walls, no
restitution, time step 5e-4 s; bottom and left walls fixed, top wall moving down at 0.01 m/s,
right wall sliding along x under the force sigma0 h (1 m) with h the current sample height,
until eps_1 = ln(1 + (h0 - h)/h0) = ``--strain``; a snapshot every ``--every`` steps.

Each run becomes a file of the grainview data contract (``export.py`` for the peers); the
project's accessors analyse all of them (``analyse.py``): means of q/p, a, a_n, a_t, z, k_d per
eps_q window, checks of the stress and of the right wall, and, with ``--check-iterations``
(default), the change of the residual q/p when the peers' iteration budgets are doubled. The
results go to ``RESULTS.md`` and ``crosscheck.png`` in ``--out`` (default: this folder for the
default settings, ``benchmarks/_data/crosscheck/report-<settings>`` otherwise, so that the
committed files always hold one full run).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import shlex
import shutil
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
BENCHMARKS = os.path.dirname(HERE)

from benchmarks.crosscheck import export
from benchmarks.crosscheck.report import write_report

DATA = os.path.join(BENCHMARKS, "_data", "crosscheck")
NETCDF_LOCK = threading.Lock()
ENGINES = ("project", "box2d", "pymunk")
SHAPES = ("pentagon", "disk")
DEFAULTS = {"shape": "pentagon,disk", "particles": 400, "seed": 0, "strain": 0.25, "every": 100,
            "engines": ",".join(ENGINES), "box2d_iterations": "100,40", "pymunk_iterations": 200,
            "check_iterations": True}


@dataclass
class Job:
    """One engine run: the command, its contract file and (peers) its raw snapshot folder."""

    shape: str
    engine: str
    name: str  # file stem, with the iteration settings
    command: list
    out: str
    raw: str | None = None
    doubled: bool = False  # a run of the iteration check
    settings: str = ""
    wall_s: float = float("nan")
    meta: dict = field(default_factory=dict)


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m benchmarks.crosscheck", description=__doc__.split("\n\n")[0])
    parser.add_argument("--shape", default=DEFAULTS["shape"], help="comma-separated: pentagon, disk (default both)")
    parser.add_argument("--particles", type=int, default=DEFAULTS["particles"],
                        help="particles per sample (default 400)")
    parser.add_argument("--seed", type=int, default=DEFAULTS["seed"], help="seed of the deposit (default 0)")
    parser.add_argument("--strain", type=float, default=DEFAULTS["strain"], help="target eps_1 (default 0.25)")
    parser.add_argument("--every", type=int, default=DEFAULTS["every"], help="steps between snapshots (default 100)")
    parser.add_argument("--engines", default=DEFAULTS["engines"],
                        help="comma-separated: project, box2d, pymunk (default all)")
    parser.add_argument("--box2d-iterations", default=DEFAULTS["box2d_iterations"],
                        help="Box2D velocity,position iterations per step (default 100,40)")
    parser.add_argument("--pymunk-iterations", type=int, default=DEFAULTS["pymunk_iterations"],
                        help="pymunk iterations per step (default 200)")
    parser.add_argument("--check-iterations", action=argparse.BooleanOptionalAction, default=True,
                        help="also run the peers with doubled iterations and report the change of q/p (default on)")
    parser.add_argument("--jobs", type=int, default=1, help="runs at the same time (default 1)")
    parser.add_argument("--peer-python", default=os.environ.get("PEER_PYTHON"),
                        help="python of the peers' venv (default $PEER_PYTHON, else benchmarks/_data/crosscheck/"
                        "venv-peers, created from benchmarks/requirements-peers.txt when missing)")
    parser.add_argument("--reuse", action="store_true", help="analyse existing runs of the same settings, rerun none")
    parser.add_argument("--out", default=None, help="folder of RESULTS.md and crosscheck.png (see above)")
    return parser


def parse_args(argv=None):
    """Parsed and checked arguments; a bad value exits with a one-line error."""
    parser = build_parser()
    args = parser.parse_args(argv)
    args.shapes = [s.strip() for s in args.shape.split(",") if s.strip()]
    args.engine_list = [e.strip() for e in args.engines.split(",") if e.strip()]
    bad = [s for s in args.shapes if s not in SHAPES] or not args.shapes
    if bad:
        parser.error(f"--shape {args.shape!r}: expected a comma-separated list of {', '.join(SHAPES)}")
    bad = [e for e in args.engine_list if e not in ENGINES] or not args.engine_list
    if bad:
        parser.error(f"--engines {args.engines!r}: expected a comma-separated list of {', '.join(ENGINES)}")
    if args.particles < 10:
        parser.error(f"--particles {args.particles}: expected at least 10")
    if not 0 < args.strain < 1:
        parser.error(f"--strain {args.strain}: expected a vertical strain eps_1 in (0, 1)")
    if args.every < 1:
        parser.error(f"--every {args.every}: expected a positive number of steps")
    if args.jobs < 1:
        parser.error(f"--jobs {args.jobs}: expected a positive number of runs")
    try:
        args.box2d = tuple(int(v) for v in args.box2d_iterations.split(","))
    except ValueError:
        args.box2d = ()
    if len(args.box2d) != 2 or min(args.box2d) < 1:
        parser.error(f"--box2d-iterations {args.box2d_iterations!r}: expected two positive integers, e.g. 100,40")
    if args.pymunk_iterations < 1:
        parser.error(f"--pymunk-iterations {args.pymunk_iterations}: expected a positive number")
    args.default_settings = all(getattr(args, k) == v for k, v in DEFAULTS.items())
    return args


def log(message):
    print(f"[{datetime.datetime.now():%H:%M:%S}] {message}", flush=True)


def fail(message):
    """Exit with a one-line error."""
    sys.exit(f"python -m benchmarks.crosscheck: error: {message}")


def call(command, what):
    """Run ``command``; exit with one line naming ``what`` if it fails."""
    result = subprocess.run(command)
    if result.returncode != 0:
        fail(f"{what} failed (exit {result.returncode}): {shlex.join(command)}")


# -- environment and samples ------------------------------------------------------------------------
def peer_python(args):
    """The peers' python: ``--peer-python``, else the cached venv (created when missing).
    Exits with one line if it cannot import Box2D and pymunk."""
    python = args.peer_python
    if python is None:
        venv = os.path.join(DATA, "venv-peers")
        python = os.path.join(venv, "bin", "python")
        if not os.path.exists(python):
            log(f"creating the peers' virtual environment {venv}")
            call([sys.executable, "-m", "venv", venv], "creating the peers' venv")
            call([python, "-m", "pip", "install", "-q", "-r", os.path.join(BENCHMARKS, "requirements-peers.txt")],
                 "installing benchmarks/requirements-peers.txt")
    try:
        probe = subprocess.run([python, "-c", "import Box2D, pymunk, numpy"], capture_output=True, text=True)
    except OSError:
        probe = None
    if probe is None or probe.returncode != 0:
        fail(f"{python} cannot import Box2D, pymunk and numpy; create a venv with "
             "`pip install -r benchmarks/requirements-peers.txt` and pass its python as --peer-python")
    return python


def sample_files(shape, args):
    """The compacted sample (netCDF) and its export for the peers (npz), built when missing."""
    folder = os.path.join(DATA, "samples")
    os.makedirs(folder, exist_ok=True)
    stem = os.path.join(folder, f"{shape}{args.particles}_seed{args.seed}")
    nc, npz = stem + ".nc", stem + ".npz"
    if not os.path.exists(nc):
        log(f"{shape}: compacting a {args.particles}-particle sample (grainview run isotropic) -> {nc}")
        call([sys.executable, "-m", "grainview", "run", "isotropic", "--shape", shape, "--particles",
              str(args.particles), "--seed", str(args.seed), "--out", nc, "--progress", "off"],
             f"compacting the {shape} sample")
    if not os.path.exists(npz) or os.path.getmtime(npz) < os.path.getmtime(nc):
        export.sample_to_npz(nc, npz)
    return nc, npz


# -- runs -------------------------------------------------------------------------------------------
def make_jobs(args, samples, python):
    """Every run to do: per shape, each engine (and, with the iteration check, each peer with
    doubled iterations)."""
    tag = f"strain{args.strain:g}_every{args.every}"
    protocol = ["--strain", str(args.strain), "--every", str(args.every)]
    jobs = []
    for shape in args.shapes:
        nc, npz = samples[shape]
        folder = os.path.join(DATA, "runs", f"{os.path.basename(nc)[:-3]}_{tag}")
        os.makedirs(folder, exist_ok=True)
        for engine in args.engine_list:
            if engine == "project":
                out = os.path.join(folder, "project.nc")
                jobs.append(Job(shape, engine, "project", [sys.executable, os.path.join(HERE, "engine_project.py"),
                                                            nc, out, *protocol], out, settings="NLGS tolerance"))
                continue
            budgets = [args.box2d if engine == "box2d" else (args.pymunk_iterations,)]
            if args.check_iterations:
                budgets.append(tuple(2 * b for b in budgets[0]))
            for k, budget in enumerate(budgets):
                if engine == "box2d":
                    name = f"box2d_v{budget[0]}_p{budget[1]}"
                    flags = ["--velocity-iterations", str(budget[0]), "--position-iterations", str(budget[1])]
                    settings = f"{budget[0]} velocity, {budget[1]} position iterations"
                else:
                    name = f"pymunk_i{budget[0]}"
                    flags = ["--iterations", str(budget[0])]
                    settings = f"{budget[0]} iterations"
                raw, out = os.path.join(folder, name), os.path.join(folder, name + ".nc")
                script = os.path.join(HERE, f"engines_{engine}.py")
                jobs.append(Job(shape, engine, name, [python, script, npz, raw, *protocol, *flags], out, raw=raw,
                                doubled=k == 1, settings=settings))
    return jobs


def execute(job, npz_of):
    """Run one job (subprocess, output to ``<out>.log``); convert a peer's raw snapshots to the
    contract and delete them. Returns the job with its wall time and engine metadata."""
    meta_path = job.out + ".json"
    if job.raw is not None and os.path.isdir(job.raw):
        shutil.rmtree(job.raw)
    log(f"{job.shape} {job.name}: running")
    start = time.perf_counter()
    with open(job.out + ".log", "w") as fh:
        result = subprocess.run(job.command, stdout=fh, stderr=subprocess.STDOUT)
    job.wall_s = time.perf_counter() - start
    if result.returncode != 0:
        raise RuntimeError(f"{job.shape} {job.name} failed (exit {result.returncode}); see {job.out}.log")
    if job.raw is not None:
        with open(os.path.join(job.raw, "meta.json")) as fh:
            meta = json.load(fh)
        with NETCDF_LOCK:  # the netCDF library is not thread-safe
            export.raw_to_contract(job.raw, npz_of[job.shape], job.out)
        shutil.rmtree(job.raw)
        with open(meta_path, "w") as fh:
            json.dump(meta, fh, indent=1)
    with open(meta_path) as fh:
        job.meta = json.load(fh)
    job.meta["run_wall_s"] = job.wall_s
    with open(meta_path, "w") as fh:
        json.dump(job.meta, fh, indent=1)
    log(f"{job.shape} {job.name}: done in {job.wall_s:.0f} s")
    return job


def load_existing(job):
    """--reuse: the job's metadata from an earlier run; exits with one line if it is missing."""
    if not (os.path.exists(job.out) and os.path.exists(job.out + ".json")):
        fail(f"--reuse: {job.out} (or its .json) is missing; run without --reuse")
    with open(job.out + ".json") as fh:
        job.meta = json.load(fh)
    job.wall_s = job.meta.get("run_wall_s", float("nan"))
    return job


def command_line(argv):
    niceness = os.nice(0)
    prefix = f"nice -n {niceness} " if niceness else ""
    return prefix + "python -m benchmarks.crosscheck" + "".join(" " + shlex.quote(a) for a in argv)


def run_record(args, argv, reuse):
    """What the report says about the command that made the runs: ``command``, ``machine``
    (date, commit, CPU, versions at its start) and, once finished, ``wall_s``. A run writes it
    to ``runs/record-<settings>.json``; ``--reuse`` reads it back (the command that made the
    runs, not the one that only re-analyses them). Exits with one line if ``--reuse`` finds
    none for these settings."""
    from benchmarks.common import machine_description

    settings = {k: getattr(args, k) for k in ("shapes", "particles", "seed", "strain", "every", "engine_list",
                                               "box2d", "pymunk_iterations", "check_iterations")}
    settings["box2d"] = list(settings["box2d"])
    name = f"record-{'-'.join(args.shapes)}_n{args.particles}_seed{args.seed}_strain{args.strain:g}_every{args.every}"
    path = os.path.join(DATA, "runs", name + ".json")
    if not reuse:
        return path, {"command": command_line(argv), "machine": machine_description(), "settings": settings}
    try:
        with open(path) as fh:
            record = json.load(fh)
    except (OSError, ValueError):
        record = None
    if record is None or record.get("settings") != settings or "wall_s" not in record:
        fail(f"--reuse: no finished run with these settings ({path}); run without --reuse")
    return path, record


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    args = parse_args(argv)
    start = time.perf_counter()
    record_path, record = run_record(args, argv, args.reuse)
    python = peer_python(args) if set(args.engine_list) - {"project"} and not args.reuse else None
    files = {shape: sample_files(shape, args) for shape in args.shapes}
    jobs = make_jobs(args, files, python)
    npz_of = {shape: files[shape][1] for shape in args.shapes}
    if args.reuse:
        jobs = [load_existing(job) for job in jobs]
    else:
        try:
            with ThreadPoolExecutor(max_workers=args.jobs) as pool:
                jobs = list(pool.map(lambda job: execute(job, npz_of), jobs))
        except RuntimeError as exc:
            fail(str(exc))
        record["wall_s"] = time.perf_counter() - start
        with open(record_path, "w") as fh:
            json.dump(record, fh, indent=1)
    sigma0 = {}
    for shape, npz in npz_of.items():
        with np.load(npz) as data:
            sigma0[shape] = float(data["sigma0"])
    if args.out is None:
        tag = "_".join(f"{k}{getattr(args, k)}" for k in ("particles", "seed", "strain", "every"))
        args.out = HERE if args.default_settings else os.path.join(DATA, f"report-{'-'.join(args.shapes)}_{tag}")
    write_report(args, jobs, sigma0, record, args.out, command_line(argv) if args.reuse else None)
    log(f"wrote {os.path.join(args.out, 'RESULTS.md')} and crosscheck.png")


if __name__ == "__main__":
    main()
