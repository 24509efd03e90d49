"""``grainview study``: the paper's two samples (pentagons and disks) simulated side by side or
one after the other, each skipped when finished and resumed when stopped, before the report.
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

from ..contract.errors import ConvergenceWarning, GrainviewError
from .estimates import compile_ahead, compile_line, print_estimate
from .progress import SampleProgress, workers_stop_with_me
from .settings import (SOLVER_OPTIONS, biaxial_test, given, preparation_of, progress_flag, shear_strain_default,
                       simulation_kwargs, solver_parameters)
from .simulation import check_shear, reissue, resumed_unconverged_warning, simulate


STUDY_SAMPLES = {"pentagons": "pentagon", "disks": "disk"}
"""The study's samples: file label -> shape."""


def study_particles(args) -> dict:
    """The study's sample sizes, label -> particles: ``--particles N`` for both samples,
    ``--particles N1,N2`` for the pentagons and the disks, ``--paper-size`` the paper's
    (:data:`grainview.app.paper_size.PAPER_PARTICLES`)."""
    from grainview.app.paper_size import PAPER_PARTICLES

    if args.paper_size:
        if "particles" in given(args):
            raise GrainviewError(f"--paper-size sets --particles ({PAPER_PARTICLES['pentagon']},"
                                 f"{PAPER_PARTICLES['disk']}); expected one of them")
        return {label: PAPER_PARTICLES[shape] for label, shape in STUDY_SAMPLES.items()}
    text = str(args.particles)
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) not in (1, len(STUDY_SAMPLES)):
        raise GrainviewError(f"--particles {text}: expected one whole number for both samples or "
                             f"{len(STUDY_SAMPLES)}, comma-separated ({','.join(STUDY_SAMPLES)}), e.g. 14400,10000")
    values = values * len(STUDY_SAMPLES) if len(values) == 1 else values
    return dict(zip(STUDY_SAMPLES, values))


def study_tests(args, particles) -> dict:
    """The study's biaxial test of each sample, label -> :class:`solver.parameters.BiaxialTest`:
    the command line's; with ``--paper-size`` and no ``--velocity``, each sample's top wall at
    the strain rate of 400 particles at 1 cm/s (:func:`grainview.app.paper_size.velocity_for`)."""
    from dataclasses import replace

    from grainview.app.paper_size import velocity_for

    test = biaxial_test(args)
    if not args.paper_size or "velocity" in given(args):
        return dict.fromkeys(particles, test)
    return {label: replace(test, velocity=velocity_for(n)) for label, n in particles.items()}


def study_state(runner, prep, parameters, path, checkpoint, expected, overwrite) -> str:
    """What is to be done for one sample of the study: "finished" (its file complete),
    "partial" (its test to be resumed) or "start" (from its compaction's checkpoint when there
    is one, else from its deposit). A file or checkpoint of other settings (``expected``: the
    file's attributes; ``prep`` and ``parameters``: what the checkpoint is of) is refused in one
    line before any work, unless ``overwrite`` (then the checkpoint is removed and the sample
    starts afresh)."""
    from solver.engine import check_settings

    if overwrite:
        checkpoint.unlink(missing_ok=True)
        return "start"
    if path.exists() and expected.get("scene") != "isotropic":  # a compacted sample, or another scene's test
        check_settings(path, {"scene": expected["scene"]}, "give another --out (a compacted sample is sheared by "
                       "reading it: solver.load_sample), or pass --overwrite to replace it")
    state = compacted_state(path) if expected.get("scene") == "isotropic" else runner.file_state(path)
    if state in ("finished", "partial"):
        check_settings(path, expected, "pass --overwrite to replace it, or give the settings it was made with")
        checkpoint.unlink(missing_ok=True)  # the compaction is in the test's file now
        return state
    if checkpoint.exists():
        from solver.engine import check_checkpoint

        check_checkpoint(runner, checkpoint, prep, parameters)
    return "start"


def compacted_state(path) -> str:
    """How far the file of a compacted sample (scene isotropic: one snapshot) got: "missing",
    "empty" (created, its snapshot not written: the run died between the two) or "finished"; a
    file that is not a run's (no snapshot and no ``scene`` attribute) is refused in one line,
    not taken as empty and replaced."""
    if not path.exists():
        return "missing"
    from ..contract.reader import ContractFile

    with ContractFile(path) as ds:  # FileFormatError, in one line, for a file that is not netCDF
        attrs, snapshots = ds.attrs, ds.n_snapshots
    if snapshots:
        return "finished"
    if "scene" not in attrs:  # not a run's file: another netCDF file, not the study's to replace
        raise GrainviewError(f"{path} is not a file of grainview's runs (no snapshot, no scene attribute); pass "
                             "--overwrite to replace it, or give another --out")
    return "empty"


def expected_attrs(prep, test, parameters, scene="biaxial") -> dict:
    """File attributes a study file of ``prep`` sheared in ``test`` (the biaxial test, or the
    periodic cell's shear for ``scene="shear"``: its rate comes from the compacted sample, so
    only its strain is known; ``scene="isotropic"``: the compacted sample alone, no test) with
    the solver settings ``parameters`` (the command line's :data:`SOLVER_OPTIONS`, given or
    default) holds."""
    velocity = {"wall_velocity_m_s": test.velocity, "right_wall_mass_ratio": test.wall_mass} if scene == "biaxial" \
        else {}
    tested = {} if scene == "isotropic" else {"strain_target": test.strain, **velocity, "snapshot_every": test.every}
    return {"scene": scene, **tested, "solver_friction": prep.friction, "sigma0_Pa": prep.sigma0, **prep.attrs(),
            **{f"solver_{k}": v for k, v in parameters.items()}}


def study_sample(label, prep, path, state, checkpoint, *, test, near_contacts, overwrite, progress,
                  parameters=None, compress=True, engine=None, scene="biaxial"):
    """One sample of the study: skipped when finished (a file whose compression was stopped is
    compressed), its test resumed when partial, else prepared (from the compaction's
    checkpoint ``checkpoint`` when it holds one) and sheared into ``path``; the checkpoint is
    removed once the test's file is complete."""
    from solver.engine import DEFAULT_ENGINE
    from solver.engine import engine as engine_named

    runner = engine_named(engine or DEFAULT_ENGINE)
    if state == "finished":
        if scene != "isotropic":  # a compacted sample has no test to compress
            runner.resume(path, progress=progress, compress=compress)
        print(f"{label}: {path} is complete (skipped)", flush=True)
        return path
    if state == "partial":
        import warnings
        from time import monotonic

        from grainview.app.paper_size import hours

        print(f"{label}: resuming the test in {path} ...", flush=True)
        start = monotonic()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            steps = runner.resume(path, progress=progress, compress=compress)
        reissue(caught)
        unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
        if unconverged:
            print(f"{label}: warning: {resumed_unconverged_warning(path, unconverged)}", file=sys.stderr)
        print(f"{label}: resumed for {steps} steps ({hours(monotonic() - start)} of wall time); wrote {path}",
              flush=True)
        return path
    simulate(prep, path, test=test, near_contacts=near_contacts, overwrite=True, progress=progress,
              parameters=parameters, compress=compress, engine=engine, checkpoint=checkpoint, label=label,
              scene=scene)
    Path(checkpoint).unlink(missing_ok=True)
    return path


def estimated_tests(tests, scene):
    """The biaxial tests whose estimate stands for the study's tests (None for scene isotropic,
    whose samples are compacted only): for scene shear, the one
    that reaches the same eps_q in as many steps (h (e^eps_1 - 1) = gamma h / 2 at the same top
    wall speed); a periodic step's cost is the walled one's in the estimate."""
    if scene == "isotropic":
        return dict.fromkeys(tests)
    if scene != "shear":
        return tests
    import math
    from dataclasses import replace

    return {label: replace(test, strain=math.log1p(test.strain / 2)) for label, test in tests.items()}


def run_study(args) -> int | None:
    """Simulate the study the parsed command line ``args`` asks for; returns the exit code, or
    None when the report is to be written: ``args.files``, ``args.labels``, ``args.out`` and
    ``args.overwrite`` then name the samples' files and the report's folder."""
    from concurrent.futures import ProcessPoolExecutor

    from solver.engine import engine

    shear_strain_default(args)
    biaxial_test(args)
    if args.jobs < 1:
        raise GrainviewError(f"--jobs {args.jobs}: expected at least 1 process")
    import os

    threads = min(args.jobs, len(STUDY_SAMPLES)) * args.domains
    if threads > (os.cpu_count() or 1):
        raise GrainviewError(f"--domains {args.domains} with --jobs {args.jobs} needs {threads} cores, this machine has "
                             f"{os.cpu_count()}: a busy core stalls every parallel sweep; pass --jobs 1")
    out = Path(args.out)
    samples = STUDY_SAMPLES
    particles = study_particles(args)
    tests = study_tests(args, particles)
    preps = {label: preparation_of(args, shape, particles[label]) for label, shape in samples.items()}
    parameters = solver_parameters(args)
    runner = engine(args.engine)
    shear = args.scene == "shear"
    if shear:
        check_shear(args, parameters)
    from solver.engine import check_test

    for label, prep in preps.items():
        check_test(args.engine, tests[label], args.scene)
        runner.check(prep, parameters, tests[label] if args.scene == "biaxial" else None)
    paths = {label: out / f"{label}.nc" for label in samples}
    checkpoints = {label: out / f"{label}.compaction.nc" for label in samples}
    if out.is_file():
        raise GrainviewError(f"--out {out} is a file; expected a folder")
    from solver.engine import Parameters, default_of

    recorded = {name: parameters.get(name, default_of(Parameters, name)) for name in SOLVER_OPTIONS}
    states = {label: study_state(runner, preps[label], parameters, paths[label], checkpoints[label],
                                  expected_attrs(preps[label], tests[label], recorded, args.scene), args.overwrite)
              for label in samples}
    out.mkdir(parents=True, exist_ok=True)
    to_run = [label for label, state in states.items() if state != "finished"]
    if to_run:
        from solver.engine import DEFAULT_ENGINE
        from grainview.app.paper_size import machine_load

        from .warmup import GROUPS, cold_shares

        load = machine_load()
        groups = [group for group in GROUPS if group != "solver" or (args.engine or DEFAULT_ENGINE) == DEFAULT_ENGINE]
        reported = not args.no_report and args.scene != "isotropic"  # compacted samples are not reported
        shares = cold_shares(groups if reported else [g for g in groups if g == "solver"])
        line = compile_line("study", shares, load)
        if line:
            print(line, flush=True)
        print_estimate({label: preps[label] for label in to_run}, estimated_tests(tests, args.scene), parameters,
                        args.jobs, shares, report=reported, load=load)
        compile_ahead("study", shares, progress_flag(args))
    args.near_contacts = True  # the report counts near pairs as well (docs/fidelity.md)
    kwargs = simulation_kwargs(args)
    kwargs.pop("test")
    kwargs["overwrite"] = args.overwrite
    kwargs["scene"] = args.scene
    if args.jobs == 1:
        for label in samples:
            study_sample(label, preps[label], paths[label], states[label], checkpoints[label], test=tests[label],
                          **kwargs)
    else:  # one process per sample: the two samples run side by side on two cores
        kwargs["progress"] = SampleProgress.for_jobs(kwargs["progress"])
        with ProcessPoolExecutor(max_workers=min(args.jobs, len(samples))) as pool, workers_stop_with_me() as stop:
            futures = [pool.submit(study_sample, label, preps[label], paths[label], states[label],
                                   checkpoints[label], test=tests[label],
                                   **{**kwargs, "progress": kwargs["progress"] and kwargs["progress"].at(i, label)})
                       for i, label in enumerate(samples)]
            stopped = []
            for future in futures:
                try:
                    future.result()
                except (KeyboardInterrupt, SystemExit) as exc:  # a worker stopped by Ctrl-C or SIGTERM
                    stopped.append(exc)
            if stop["signal"] is not None or stopped:
                from solver.engine import Terminated

                raise (Terminated() if stop["signal"] == signal.SIGTERM or any(
                    isinstance(exc, SystemExit) for exc in stopped) else KeyboardInterrupt())
    report = out / "report"
    if args.no_report:
        return 0
    if args.scene == "isotropic":
        print(f"study: the compacted samples are {', '.join(str(p) for p in paths.values())}; a report needs "
              "tests (scene biaxial or shear)", flush=True)
        return 0
    if all(state == "finished" for state in states.values()) and (report / "headline.csv").exists():
        print(f"study: every sample was complete already and {report} holds their report; nothing to do "
              "(--overwrite runs the study again)", flush=True)
        return 0
    args.files = [str(p) for p in paths.values()]
    args.labels = ",".join(paths)
    args.out = str(report)
    args.overwrite = True  # the report of the files just completed replaces an older one of the same folder
    return None
