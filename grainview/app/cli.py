"""The ``grainview`` command line: ``study``, ``run``, ``ensemble``, ``report``, ``info``, ``export``,
``demo`` and ``warmup``.

Errors a user can cause are printed as one line (``grainview: error: ...``) with exit code 2,
never as a traceback.

The simulation's options (``run``, ``study``, ``ensemble``) are the fields of the settings
records of :mod:`solver.parameters` (``Parameters``, ``Preparation``, ``BiaxialTest``): each
option's flag, type, choices, default and help come from its field (:func:`setting_option`),
and its value is checked by the record's validator (:mod:`grainview.app.settings`). The
command line holds no default of its own for them; options of other functions take those
functions' defaults, imported as values. The simulation itself goes through an engine of
:mod:`solver.engine` (``--engine``), so another engine needs no edit here; the study's workflow
is :mod:`grainview.app.study`, one run's :mod:`grainview.app.simulation`, the conversions'
:mod:`grainview.app.convert_command`.

Only the parser of the command that is run is built in full (:func:`build_parser`), so that each
command imports what its own options need and nothing more.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

from ..contract.errors import GrainviewError, SchemaError
from . import convert_command
from .estimates import compile_ahead, compile_line
from .settings import (ENSEMBLE_SOLVER_OPTIONS, S1S2_HELP, acceleration_option, biaxial_test, engine_option,
                       flag_of, no_compress_option, preparation_of, progress_flag, residual_option, setting_option,
                       shape_of, shear_strain_default, simulation_kwargs, simulation_options, solver_parameters,
                       split_list, test_options)
from .simulation import check_output_file, check_run_settings, simulate
from .study import STUDY_SAMPLES, run_study


COMMAND_HELP = {
    "study": "the paper's study: pentagons vs disks, simulated, analysed, plotted",
    "run": "simulate one sample into a netCDF file",
    "report": "analyse runs: headline table vs the paper and all figures",
    "ensemble": "many runs (settings x seeds) on a dask cluster, then their report",
    "info": "validate a grainview netCDF file and print its summary",
    "export": "write snapshots as VTK (ParaView, OVITO) or CSV",
    "demo": "write a synthetic harmonic-model series and analyse it lazily",
    "warmup": "compile every numba kernel into the cache, so that runs start at once",
    "convert": convert_command.HELP,
}
"""Each command's line in ``grainview --help``, in order."""


def _info(args) -> int:
    from .file_summary import describe_file

    if args.check:  # first, so that every problem is listed: the summary's own and every value's
        from ..contract.io import open_dataset
        from ..contract.validation import validate

        problems = []
        try:
            describe_file(args.file, check=True)  # every stored chunk read: checksums verified
        except SchemaError as exc:
            problems += exc.problems
        try:
            with open_dataset(args.file, chunks="auto") as ds:
                validate(ds, source=str(args.file))
        except SchemaError as exc:
            problems += [problem for problem in exc.problems if problem not in problems]
        if problems:
            raise SchemaError(problems, source=str(args.file))
    lines, attrs = describe_file(args.file)  # netCDF4 and numpy only: no xarray, dask or pandas to import
    for line in lines:
        print(line)
    if args.attrs:
        for key, value in attrs.items():
            print(f"  {key} = {value}")
    version = attrs.get("grainview_schema_version", "?")
    if args.check:
        print(f"valid: every value checked against grainview data contract {version}")
    else:
        print(f"valid: structure, units, times and forces follow grainview data contract {version} "
              "(--check also checks every value)")
    return 0


def _export(args) -> int:
    from ..export import write_csv, write_vtk
    from ..contract.io import open_dataset
    from ..contract.validation import validate

    ds = open_dataset(args.file)
    validate(ds, source=str(args.file))
    if args.to == "vtk":
        paths = write_vtk(ds, args.out, every=args.every, overwrite=args.overwrite, progress=args.progress != "off")
        outlines = any(path.endswith("polygons.pvd") for path in paths)
        print(f"wrote {len(paths)} VTK files to {args.out}: open snapshots.pvd in ParaView or OVITO"
              + (", and polygons.pvd (the polygons' outlines) in ParaView" if outlines else ""))
    else:
        path = write_csv(ds, args.out, every=args.every, overwrite=args.overwrite, progress=args.progress != "off")
        print(f"wrote {path}")
    return 0


def _demo(args) -> int:
    from .demo import run_demo

    path, frame = run_demo(args.out, snapshots=args.snapshots, contacts=args.contacts, seed=args.seed,
                           overwrite=args.overwrite, compress=not args.no_compress,
                           log=lambda line: print(f"demo: {line}", flush=True))
    print(f"wrote {path} and {path.parent / 'harmonic_prediction.csv'}; q/p against the harmonic prediction "
          "(a' + a_n + a_t)/2:")
    print(frame.round(4).to_string())
    return 0


def _warmup(args) -> int:
    import os

    from .warmup import cache_location, warm_up

    folder = os.environ.get("NUMBA_CACHE_DIR")
    if folder:
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as exc:
            raise GrainviewError(f"NUMBA_CACHE_DIR={folder}: cannot create the folder ({exc.strerror})") from None
        if not os.access(folder, os.W_OK):
            raise GrainviewError(f"NUMBA_CACHE_DIR={folder}: the folder is not writable; expected a writable folder")
    print(f"warmup: compiling, or loading from the cache, every numba kernel of the solver and the analysis; "
          f"cache: {cache_location()}", flush=True)
    result = warm_up(log=lambda line: print(f"warmup: {line}", flush=True))
    print(f"warmup: done: {result['kernels']} kernels ready in {result['cache']}; runs that use this cache "
          "start without compiling", flush=True)
    return 0


def _study(args) -> int:
    code = run_study(args)
    return _report(args) if code is None else code


def _run(args) -> int:
    shear_strain_default(args)
    biaxial_test(args)
    check_output_file(args.out, args.overwrite)
    prep = preparation_of(args, shape_of(args.shape))
    check_run_settings(args, prep)
    from solver.engine import DEFAULT_ENGINE

    if (args.engine or DEFAULT_ENGINE) == DEFAULT_ENGINE:
        from grainview.app.paper_size import machine_load

        from .warmup import cold_shares

        shares = cold_shares(["solver"])
        line = compile_line("run", shares, machine_load())
        if line:
            print(line, flush=True)
            compile_ahead("run", shares, progress_flag(args))
    simulate(prep, args.out, scene=args.scene, shear_rate=args.shear_rate, **simulation_kwargs(args))
    return 0


def _report(args) -> int:
    from ..contract.io import open_dataset
    from .report import write_report

    if getattr(args, "ensemble", False):
        if args.labels or args.movie:
            raise GrainviewError("--labels and --movie do not apply to --ensemble (the runs are named by their files)")
        return _ensemble_report(args)

    labels = args.labels.split(",") if args.labels else [Path(f).stem for f in args.files]
    if len(labels) != len(args.files):
        raise GrainviewError(f"--labels has {len(labels)} names for {len(args.files)} files")
    runs = {label: open_dataset(f, validate=True) for label, f in zip(labels, args.files)}
    figures = split_list(args.figures, str, "figures") if getattr(args, "figures", None) else None
    result = write_report(runs, args.out, residual_strain=args.residual_strain, overwrite=args.overwrite,
                          log=lambda line: print(f"report: {line}", flush=True), figures=figures)
    files = list(result["files"])
    if getattr(args, "movie", False):  # the study reports without movies
        from ..plot.movies import animate

        for label, ds in runs.items():
            path = Path(args.out) / f"force_chains_{label}.gif"
            print(f"report: movie of {label} ...", flush=True)
            files.append(animate(ds, path, kind="force_chains", every=args.movie_every, overwrite=args.overwrite,
                                 progress=False))
    print(_terminal_table(result["table"]))
    print(f"wrote {len(files)} files in {args.out}")
    return 0


def _terminal_table(table) -> str:
    """A report's table fitted to the terminal's width, rounded as the Markdown
    (grainview.app.table_text.terminal_table)."""
    from .table_text import terminal_table

    return terminal_table(table)


def _ensemble_report(args) -> int:
    from ..analysis.ensemble import open_ensemble
    from .ensemble_report import write_ensemble_report

    ens = open_ensemble(args.files, validate=True)
    result = write_ensemble_report(ens, args.out, residual_strain=args.residual_strain, overwrite=args.overwrite,
                                   log=lambda line: print(f"report: {line}", flush=True))
    print(_terminal_table(result["table"]))
    print(f"wrote {len(result['files'])} files in {args.out}")
    return 0


def _ensemble(args) -> int:
    from grainview.app.ensemble import check_cluster, grid, run_ensemble

    check_cluster(args.scheduler, args.workers)  # before any line is printed; the library's one check
    test = biaxial_test(args)
    frictions = split_list(args.friction_list, float, "friction") if args.friction_list else [None]
    sigma0 = split_list(args.sigma0_list, float, "sigma0") if args.sigma0_list else [None]
    particles = {"particles": split_list(args.particles_list, int, "particles")} if args.particles_list else {}
    shapes = [shape_of(s, f"--shapes {args.shapes}") for s in split_list(args.shapes, str, "shapes")]
    specs = grid(shapes=shapes, **particles, frictions=frictions, sigma0=sigma0,
                 seeds=args.seeds, first_seed=args.seed, preparation=args.preparation,
                 strain=test.strain, velocity=test.velocity, every=test.every,
                 solver=tuple(sorted(solver_parameters(args).items())), engine=args.engine)
    out = Path(args.out)
    report = out / "report"
    if not args.no_report and (report / "headline.csv").exists() and not (args.overwrite or args.overwrite_report):
        raise GrainviewError(f"{report} already holds a report; pass --overwrite-report to replace it (finished runs "
                             "are kept), or --no-report to run only")
    where = args.scheduler or f"a local cluster of {args.workers or 'one worker per core'}"
    print(f"ensemble: {len(specs)} runs on {where}; files in {out} (finished runs are skipped, unfinished "
          "ones resumed)", flush=True)
    results = run_ensemble(specs, out, scheduler=args.scheduler, workers=args.workers, overwrite=args.overwrite,
                           compress=not args.no_compress,
                           progress=progress_flag(args), log=lambda line: print(f"ensemble: {line}", flush=True))
    failed = [r for r in results if "error" in r]
    if failed:
        print(f"grainview: error: {len(failed)} of {len(results)} runs failed (above); fix the cause and run the "
              "same command again: finished runs are skipped, unfinished ones resumed", file=sys.stderr)
        return 1
    if args.no_report:
        return 0
    args.files = [r["path"] for r in results]
    args.out = str(report)
    args.overwrite = True  # checked above, before the runs: an existing report is replaced only when asked
    return _ensemble_report(args)


def _study_parser(sub):
    from grainview.app.paper_size import PAPER_PARTICLES, REFERENCE_PARTICLES, REFERENCE_VELOCITY, velocity_for
    from solver.engine import Preparation

    from solver.engine import CHECKPOINT_SECONDS, SHEAR_STRAIN

    minutes = CHECKPOINT_SECONDS / 60
    study = sub.add_parser("study", help=COMMAND_HELP["study"],
                           description=f"Deposit, compact ({Preparation.sigma0 / 1e3:g} kPa) and shear an S1-like "
                           "pentagon sample and an "
                           "S2-like disk sample into the residual state, side by side, then write the report "
                           "(table vs the paper, figures). The files hold the near contacts too, so the table "
                           "also counts them (docs/fidelity.md). The same command again, after a stop (Ctrl-C, "
                           "SIGTERM) or a kill, skips the finished samples and resumes the others where they were: "
                           "a test from its file, a compaction from its checkpoint OUT/<sample>.compaction.nc "
                           f"(written every {minutes:g} minutes and when stopped); files of other settings are refused "
                           "unless --overwrite.")
    study.add_argument("--out", default="study", help="output folder (default: study)")
    study.add_argument("--jobs", type=int, default=len(STUDY_SAMPLES),
                       help=f"processes: the {len(STUDY_SAMPLES)} samples side by side (default {len(STUDY_SAMPLES)})")
    speeds = " and ".join(f"{velocity_for(PAPER_PARTICLES[shape]):g}" for shape in ("pentagon", "disk"))
    study.add_argument("--paper-size", action="store_true",
                       help=f"the paper's sizes: {PAPER_PARTICLES['pentagon']} pentagons and {PAPER_PARTICLES['disk']} "
                       f"disks, each top wall at the strain rate of {REFERENCE_PARTICLES} particles at "
                       f"{REFERENCE_VELOCITY:g} m/s (speed x sqrt(N/{REFERENCE_PARTICLES}): {speeds} m/s; "
                       "--velocity V shears both at V); hours on two cores, resumable: the same command again "
                       "goes on where a stopped or killed run was (docs/fidelity.md, section 4)")
    study.add_argument("--no-report", action="store_true",
                       help="simulate only (grainview report OUT/pentagons.nc OUT/disks.nc --out DIR reports later)")
    study.add_argument("--scene", choices=["biaxial", "isotropic", "shear"], default="biaxial",
                       help="biaxial (default: the top wall compresses each sample), isotropic (each sample compacted "
                       "and written, OUT/<sample>.nc, for a test to start from later; no report) or shear (each "
                       "compacted sample in the biperiodic cell of its box, sheared to gamma = --strain, default "
                       f"{SHEAR_STRAIN:g}, at 2 v/h under sigma_yy = "
                       "sigma0; as grainview run shear)")
    residual_option(study)
    simulation_options(study, samples=tuple(STUDY_SAMPLES))
    study.set_defaults(func=_study)


def _run_parser(sub):
    from solver.engine import MAX_VERTICES, SHEAR_STRAIN, BiaxialTest, Preparation

    run = sub.add_parser("run", help=COMMAND_HELP["run"],
                         description=f"Geometric deposit, isotropic compaction under sigma0 ({Preparation.sigma0 / 1e3:g} "
                         f"kPa), then (scene biaxial) compression by the top wall ({BiaxialTest.velocity * 100:g} cm/s) "
                         "with sigma0 held on the right wall.")
    run.add_argument("scene", nargs="?", choices=["biaxial", "isotropic", "shear"], default="biaxial",
                     help="biaxial (default), isotropic (writes the compacted state) or shear (the compacted sample "
                     "in a biperiodic cell, sheared to gamma = --strain, default "
                     f"{SHEAR_STRAIN:g}, under sigma_yy = sigma0)")
    run.add_argument("--shear-rate", type=float, default=None,
                     help="scene shear: the imposed shear rate gamma_dot, s-1 (default 2 v/h, v the --velocity "
                     "and h the compacted sample's height: the pace of the biaxial test at v in eps_q = "
                     "eps_1 - eps_2; docs/solver.md)")
    setting_option(run, Preparation, "shape", help=f"pentagon, disk, a number of vertices from 3 to "
                   f"{MAX_VERTICES} (6: hexagons), irregular (random convex polygons) or a .json file of vertex lists "
                   "{\"polygons\": [[[x, y], ...], ...]} (docs/solver.md, \"Shapes\"; default "
                   f"{Preparation.shape})")
    run.add_argument("--out", default="run.nc", help="output netCDF file (default: run.nc)")
    run.add_argument("--near-contacts", action="store_true",
                     help="also write the pairs within the alert distance that carry no force (with their "
                     "gap), for the analyses' near= counting (the study always does)")
    simulation_options(run)
    run.set_defaults(func=_run)


def _report_parser(sub):
    report = sub.add_parser("report", help=COMMAND_HELP["report"],
                            description="Analyse one or more files of the data contract: the headline table "
                            "(residual state next to the paper's values), the paper's figures, a CSV of the "
                            "table. Runs labelled with 'pent' or 'disk', or else whose particles are all pentagons or all "
                            "disks, are compared with the paper's S1 or S2.")
    report.add_argument("files", nargs="+", help="netCDF files of the grainview contract")
    report.add_argument("--labels", default=None, help="comma-separated labels (default: file names); "
                        "labels containing 'pent' or 'disk' are compared with the paper's S1/S2 values; other runs by their "
                        "particles' shape")
    report.add_argument("--out", default="report", help="output folder (default: report)")
    report.add_argument("--overwrite", action="store_true", help="replace an existing report in --out")
    report.add_argument("--movie", action="store_true", help="also a force-chain movie of each run "
                        "(force_chains_<label>.gif)")
    report.add_argument("--ensemble", action="store_true", help="the files are seeds and settings of one "
                        "ensemble: report mean +- spread over the seeds of each setting (docs/ensembles.md)")
    report.add_argument("--figures", default=None, help="comma-separated paper figure numbers to draw, e.g. "
                        "03,08,13,14 (default: every figure the runs support; a large run takes minutes a figure)")
    import inspect

    from ..plot.movies import animate

    every = inspect.signature(animate).parameters["every"].default
    report.add_argument("--movie-every", type=int, default=every,
                        help=f"one movie frame every k snapshots (default {every})")
    residual_option(report)
    report.set_defaults(func=_report)


def _ensemble_parser(sub):
    from solver.engine import DEFAULT_PRESET, MAX_VERTICES, Parameters, Preparation

    ens = sub.add_parser("ensemble", help=COMMAND_HELP["ensemble"],
                         description="One biaxial test per (shape, particles, friction, sigma0, seed) on a "
                         "dask.distributed cluster (a local one, one worker per core, or --scheduler), each into "
                         "OUT/<run>.nc; a run whose worker dies is resumed by another; running the command again "
                         "skips finished runs and resumes the others. Then the ensemble report: mean +- spread over "
                         "seeds (docs/ensembles.md).")
    ens.add_argument("--out", default="ensemble", help="output folder (default: ensemble)")
    ens.add_argument("--shapes", default=Preparation.shape, help="comma-separated shapes: pentagon, disk or numbers "
                     f"of vertices from 3 to {MAX_VERTICES} (default {Preparation.shape}; e.g. pentagon,disk,6)")
    for name, unit in (("particles", ""), ("friction", ""), ("sigma0", " in Pa")):
        default = getattr(Preparation, name)
        ens.add_argument(flag_of(name), dest=f"{name}_list", default=None,
                         help=f"comma-separated values of {name}{unit} (default {default:g}, the preparation's)")
    from .ensemble import SEEDS_PER_SETTING as seeds
    ens.add_argument("--seeds", type=int, default=seeds, help=f"seeds per setting (default {seeds})")
    setting_option(ens, Preparation, "seed", flag="--first-seed", help=f"first seed (default {Preparation.seed})")
    test_options(ens)
    ens.add_argument("--preparation", default=DEFAULT_PRESET, help=f"named preparation (default {DEFAULT_PRESET}; "
                     f"{S1S2_HELP})")
    for name in ENSEMBLE_SOLVER_OPTIONS:
        setting_option(ens, Parameters, name)
    acceleration_option(ens)
    engine_option(ens)
    ens.add_argument("--workers", type=int, default=None, help="worker processes of the local cluster "
                     "(default: one per core; each single-threaded)")
    ens.add_argument("--scheduler", default=None, help="address of an existing dask scheduler (tcp://host:8786); "
                     "its workers must import grainview and see --out (default: none, a local cluster)")
    ens.add_argument("--no-report", action="store_true", help="run only; no report")
    ens.add_argument("--overwrite", action="store_true", help="redo every run, replacing its file (and the report)")
    ens.add_argument("--overwrite-report", action="store_true", help="replace an existing report in OUT/report; "
                     "finished runs are kept")
    no_compress_option(ens)
    ens.add_argument("--progress", choices=["auto", "on", "off"], default="auto", help="a progress bar per run "
                     "(default auto: on in a terminal)")
    residual_option(ens)
    ens.set_defaults(func=_ensemble)


def _info_parser(sub):
    info = sub.add_parser("info", help=COMMAND_HELP["info"],
                          description="Print a file's size, snapshots, strain and q/p reached and settings, "
                          "in under a second (about half a second for a 400-particle study's run on two cores "
                          "shared with other jobs; benchmarks/results/cli-io.md), checking its structure and "
                          "units against the data contract "
                          "(--check: every value too); exits with 2 and one line naming the fault when it is "
                          "not valid.")
    info.add_argument("file", help="path of a netCDF file of the grainview data contract")
    info.add_argument("--attrs", action="store_true", help="also list every global attribute")
    info.add_argument("--check", action="store_true",
                      help="also check every value against the contract (ids, kinds, finite forces, unit "
                      "normals...: reads the whole file; without it only the structure and units are checked)")
    info.set_defaults(func=_info)


def _export_parser(sub):
    export = sub.add_parser("export", help=COMMAND_HELP["export"],
                            description="Export a file of the data contract: --to vtk writes, per snapshot, "
                            "the particles (points with a radius) and the contacts (lines with fn, ft, kind, "
                            "force class) as VTK PolyData in one multi-block file, and the polygons' outlines; "
                            "snapshots.pvd puts them on the time axis (ParaView, OVITO), polygons.pvd the "
                            "outlines (ParaView); --to csv one tidy contact table (docs/analysis.md).")
    export.add_argument("file", help="netCDF file of the grainview contract")
    export.add_argument("--to", choices=("vtk", "csv"), required=True, help="output format")
    export.add_argument("--out", required=True, help="output folder (created if needed)")
    import inspect

    from ..export.vtk import write_vtk

    every = inspect.signature(write_vtk).parameters["every"].default
    export.add_argument("--every", type=int, default=every,
                        help=f"export every k-th snapshot (and the last; default {every})")
    export.add_argument("--overwrite", action="store_true", help="replace existing files in --out")
    export.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default on)")
    export.set_defaults(func=_export)


def _demo_parser(sub):
    demo = sub.add_parser("demo", help=COMMAND_HELP["demo"],
                          description="Write a synthetic series drawn from the harmonic model (no simulation, "
                          "seconds) and compare q/p with the prediction (a' + a_n + a_t)/2 computed lazily "
                          "from the file.")
    demo.add_argument("--out", default="demo-out", help="output folder, made if needed (default: demo-out in the "
                      "current folder); the command says where it writes and refuses to replace its files without "
                      "--overwrite")
    import inspect

    from ..datasets import harmonic_series
    from .demo import CONTACTS as contacts
    from .demo import SNAPSHOTS as snapshots

    demo.add_argument("--snapshots", type=int, default=snapshots, help=f"number of snapshots (default {snapshots})")
    demo.add_argument("--contacts", type=int, default=contacts, help=f"contacts per snapshot (default {contacts})")
    seed = inspect.signature(harmonic_series).parameters["seed"].default
    demo.add_argument("--seed", type=int, default=seed, help=f"random seed (default {seed})")
    demo.add_argument("--overwrite", action="store_true", help="replace existing output files")
    no_compress_option(demo)
    demo.set_defaults(func=_demo)


def _warmup_parser(sub):
    from grainview.app.paper_size import COMPILE_SECONDS, STUDY_TIME, hours

    cold = hours(sum(COMPILE_SECONDS.values()))
    warmup = sub.add_parser("warmup", help=COMMAND_HELP["warmup"],
                            description="Compile (or load) every numba kernel of the solver and the analysis into "
                            "numba's cache (NUMBA_CACHE_DIR when set, else __pycache__ beside the modules) with a "
                            f"tiny workload (seconds once warm; cold, about {cold} of processor time, the wall time "
                            f"on an idle core, longer on a busy one: {STUDY_TIME}). grainview run and study do it "
                            "first when the cache lacks their kernels; a batch job that runs the solver otherwise "
                            "spends its first step compiling and acts on SIGTERM only after that step: warm the cache "
                            "once per installation, e.g. before submitting batch jobs (docs/solver.md).")
    warmup.set_defaults(func=_warmup)


def build_parser(command=None) -> argparse.ArgumentParser:
    """The command line: one subcommand per ``_<name>_parser``; the simulation's options are
    derived from the settings records (:func:`setting_option`). ``command``: the one subcommand
    whose options are built (the others named with their line of :data:`COMMAND_HELP` only);
    None: every one."""
    parser = argparse.ArgumentParser(prog="grainview", description=(
        "Contact dynamics of disks and polygons, and the force-transmission analyses of "
        "Azema et al., Phys. Rev. E 76, 011301 (2007)."))
    from importlib.metadata import PackageNotFoundError, version

    try:
        __version__ = version("grainview")
    except PackageNotFoundError:  # run from a source tree that was not installed
        __version__ = "(not installed)"

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    parsers = {"study": _study_parser, "run": _run_parser, "report": _report_parser, "ensemble": _ensemble_parser,
               "info": _info_parser, "export": _export_parser, "demo": _demo_parser, "warmup": _warmup_parser,
               "convert": convert_command.convert_parser}
    for name in COMMAND_HELP:
        if command in (None, name):
            parsers[name](sub)
        else:
            sub.add_parser(name, help=COMMAND_HELP[name])
    return parser


def _command_of(argv):
    """The subcommand ``argv`` names (its first word that is no option), or None."""
    return next((token for token in argv if not token.startswith("-")), None)


def _negative_values_attached(argv):
    """``argv`` with each negative number that follows a long option attached to it
    (``--time-step -1e-4`` -> ``--time-step=-1e-4``): argparse takes ``-1e-4`` for an option
    and answers "expected one argument", where the value should parse and then be refused
    for what it is."""
    out = []
    for token in argv:
        previous = out[-1] if out else ""
        if (token.startswith("-") and previous.startswith("--") and "=" not in previous
                and previous != "--" and _is_number(token)):
            out[-1] = f"{previous}={token}"
        else:
            out.append(token)
    return out


def _is_number(text) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


@contextlib.contextmanager
def _warnings_as_notes():
    """Within the block, a warning of the program's (a UserWarning) that reaches the user is one
    ``note: <message>`` line on stdout, as the conversions' notes are, not Python's report with
    the source file and line; other warnings are shown as before."""
    import warnings

    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, UserWarning):
            print(f"note: {message}")
        else:
            previous(message, category, filename, lineno, file, line)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def main(argv=None) -> int:
    argv = _negative_values_attached(sys.argv[1:] if argv is None else list(argv))
    command = _command_of(argv)
    args = build_parser(command if command in COMMAND_HELP else None).parse_args(argv)
    try:
        with _warnings_as_notes():
            return args.func(args)
    except SchemaError as exc:  # one line; `info --check` lists every problem
        listed = args.command == "info" and getattr(args, "check", False) and len(exc.problems) > 1
        message = str(exc).replace("\n", "\n  ") if listed else exc.summary()
        print(f"grainview: error: {message}", file=sys.stderr)
        return 2
    except (GrainviewError, FileExistsError, FileNotFoundError) as exc:
        # the library's advice names its keyword; on the command line it is the flag
        message = str(exc).replace("\n", "\n  ").replace("overwrite=True", "--overwrite")
        print(f"grainview: error: {message}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `grainview info FILE | head`: the reader has gone, say nothing
        import os

        try:  # so that Python's own flush at exit does not complain either
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):  # stdout without a file descriptor (captured)
            pass
        return 141
    except OSError as exc:  # a full disk, a read-only folder, a permission: one line
        where = f": {exc.filename}" if getattr(exc, "filename", None) else ""
        print(f"grainview: error: {exc.strerror or exc}{where}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("grainview: interrupted", file=sys.stderr)
        return 130
    except SystemExit as exc:
        from solver.engine import Terminated  # loaded with the progress lines' signal handling

        if not isinstance(exc, Terminated):
            raise
        print("grainview: terminated (SIGTERM)", file=sys.stderr)  # a batch scheduler's limit, after a whole step
        return 143


if __name__ == "__main__":
    sys.exit(main())
