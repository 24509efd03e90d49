"""One sample simulated for the command line (``grainview run``, each sample of ``grainview
study``): its settings and output file checked before any work, then deposited, compacted and
tested by an engine of :mod:`solver.engine`, with what it does said line by line and the
warning on unconverged steps in one line."""

from __future__ import annotations

import sys
from pathlib import Path

from ..contract.errors import ConvergenceWarning, GrainviewError
from .settings import biaxial_test, solver_parameters


def simulate(prep, path, *, test, near_contacts, overwrite, progress, scene="biaxial", parameters=None,
              compress=True, engine=None, checkpoint=None, label=None, shear_rate=None):
    """Deposit, compact isotropically (as ``prep`` says) and, for ``scene="biaxial"``, shear
    one sample in the biaxial ``test`` (:class:`solver.parameters.BiaxialTest`) into ``path``,
    with the engine named ``engine`` (:mod:`solver.engine`; None: the default); returns the
    path. An isotropic run writes its compacted state. ``parameters``: solver settings
    (:class:`solver.Parameters` fields) other than the defaults. ``checkpoint``: the file where
    the compaction saves its state as it goes and resumes from (:func:`solver.engine.prepare`).
    ``label``: the sample's name in the messages (default: its shape's). ``scene="shear"``: the
    compacted sample in the biperiodic cell of its box, sheared at ``shear_rate`` (s-1) to
    gamma = ``test.strain`` under sigma_yy = sigma0 (:mod:`solver.periodic_shear`)."""
    import warnings

    from solver.engine import DEFAULT_ENGINE, check_scene, prepare
    from solver.engine import engine as engine_named

    runner = engine_named(engine or DEFAULT_ENGINE)
    if scene == "shear":
        check_scene(engine, scene)
    path = Path(path)
    if path.exists() and not overwrite:
        raise GrainviewError(f"{path} exists; pass --overwrite to replace it")
    from solver.engine import shape_label

    name = label or shape_label(prep.shape)
    resumed = checkpoint is not None and Path(checkpoint).exists()
    if resumed:
        print(f"{name}: resuming the compaction of {prep.particles} particles from {checkpoint} ...", flush=True)
    else:
        print(f"{name}: depositing {prep.particles} particles and compacting under {prep.sigma0:g} Pa ...", flush=True)
    from time import monotonic

    from grainview.app.paper_size import hours

    start = monotonic()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sample = prepare(runner, prep, parameters or {}, progress=progress, checkpoint=checkpoint)
        history = sample.history
        settled = "settled" if history.settled else "NOT settled (step limit reached)"
        print(f"{name}: compaction {settled} after {history.compaction_steps} steps ({hours(monotonic() - start)} "
              f"of wall time{' since the checkpoint' if resumed else ''}); wall stresses "
              f"{', '.join(f'{s:.0f}' for s in history.compaction_stress)} Pa", flush=True)
        start = monotonic()
        if scene == "isotropic":
            runner.write_state(sample, path, attrs={"scene": "isotropic"}, overwrite=overwrite,
                               near_contacts=near_contacts, compress=compress)
        elif scene == "shear":
            rate = runner.shear_rate(sample, test.velocity) if shear_rate is None else shear_rate
            print(f"{name}: periodic simple shear to gamma = {test.strain} at {rate:.3g} s-1 under "
                  f"sigma_yy = {prep.sigma0:g} Pa ...", flush=True)
            runner.simple_shear(sample, path, test, rate, overwrite=overwrite, attrs=history.attrs(),
                                progress=progress, near_contacts=near_contacts, compress=compress)
        else:
            print(f"{name}: biaxial compression to eps_1 = {test.strain} at {test.velocity:g} m/s{inertia_words(sample, test)}"
                  " ...", flush=True)
            runner.shear(sample, path, test, overwrite=overwrite, progress=progress, attrs=history.attrs(),
                         near_contacts=near_contacts, compress=compress)
    unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    if unconverged:
        print(f"{name}: warning: {unconverged_warning(sample, path, unconverged)}", file=sys.stderr)
    print(f"{name}: wrote {path}" + ("" if scene == "isotropic" else f" (the test: {hours(monotonic() - start)} of wall "
                                      "time)"), flush=True)
    return path


def inertia_words(sample, test) -> str:
    """The test's inertia numbers at its start, in words (:func:`grainview.app.paper_size.inertia_numbers`),
    or "" for a sample that is not this package's simulation."""
    from grainview.app.paper_size import inertia_numbers

    try:
        paper, grain = inertia_numbers(sample, test.velocity)
    except AttributeError:  # another engine's sample
        return ""
    return f" (inertia number I = {paper:.1e}, the paper's eps_dot sqrt(m/p); grain-scale {grain:.1e})"


def unconverged_warning(sim, path, unconverged) -> str:
    """What the warning on a run's unconverged steps says: how many of the compaction's and of
    the test's steps stopped at their contact solver's iteration cap or stall test, in that
    solver's words, and how far each phase's impulses were from a solution
    (grainview.app.convergence), the test's read from the written file: each phase with its
    own numbers, those the run's report states."""
    import netCDF4

    from .convergence import norms_phrase, residual_comparison, stop_rule, tolerances, unconverged_in_file

    with netCDF4.Dataset(path) as nc:
        counts = unconverged_in_file(nc.variables, {k: nc.getncattr(k) for k in nc.ncattrs()})
    p = sim.parameters
    rule = {"tolerance": p.tolerance, "max_tolerance": p.max_tolerance, "max_iterations": p.max_iterations,
            "stall_sweeps": p.stall_sweeps, "solver": p.solver}
    parts = []
    compaction = sim.history.compaction_unconverged
    if compaction is not None and compaction.steps:
        phase = {**rule, "residual": compaction.residual, "local_law_residual": compaction.local_law_residual,
                 "typical_local_law_residual": None}
        parts.append(f"{compaction.steps} of the compaction's {sim.history.compaction_steps} "
                     f"({residual_comparison(phase)})")
    if counts is not None and counts["of"]:
        parts.append(f"{counts['steps']} of the test's {counts['of']} ({residual_comparison({**counts, **rule})})")
    where = f": {'; '.join(parts)}" if parts else ""
    return (f"the contact solver ({p.solver}) did not converge in {unconverged} step(s){where}. They stopped at "
            f"{stop_rule(rule)} before {norms_phrase(rule)} ({tolerances(rule)}). {path} records the test's per "
            "snapshot (nlgs_unconverged_steps) and the compaction's in its attributes (compaction_unconverged_*), "
            "and its report states both, apart")


def reissue(caught):
    """Show again the warnings of ``caught`` (a ``catch_warnings(record=True)`` list) other than
    the ConvergenceWarnings, which the caller summarises in one line."""
    import warnings

    for w in caught:
        if not issubclass(w.category, ConvergenceWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def resumed_unconverged_warning(path, unconverged, taken="the resumed test's steps") -> str:
    """What the warning on a resumed test's unconverged steps says: how many of the steps taken
    now stopped at their contact solver's iteration cap or stall test, and, from the written
    file, how many of the whole test's did and how far their impulses were from a solution
    (grainview.app.convergence), in the words of :func:`unconverged_warning`; ``taken`` names the
    steps taken now."""
    import netCDF4

    from .convergence import norms_phrase, residual_comparison, stop_rule, tolerances, unconverged_in_file

    with netCDF4.Dataset(path) as nc:
        counts = unconverged_in_file(nc.variables, {k: nc.getncattr(k) for k in nc.ncattrs()})
    if counts is None:  # another engine's file
        return f"the contact solver did not converge in {unconverged} of {taken}"
    whole = f"; in the whole test {counts['steps']} of its {counts['of']} ({residual_comparison(counts)})"
    return (f"the contact solver ({counts['solver']}) did not converge in {unconverged} of {taken}"
            f"{whole}. They stopped at {stop_rule(counts)} before {norms_phrase(counts)} ({tolerances(counts)}). "
            f"{path} records the test's per snapshot (nlgs_unconverged_steps), and its report states them")


def longest_output_name(folder) -> int:
    """The longest file name, in bytes, that ``--out`` may have in ``folder``: the folder's
    name limit (``PC_NAME_MAX``, 255 on common file systems) less what the writer's temporary
    names add (:data:`grainview.contract.writer.TEMPORARY_NAME_EXTRA`)."""
    import os

    from ..contract.writer import TEMPORARY_NAME_EXTRA

    try:
        limit = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):  # not known here (or not POSIX): the common limit
        limit = 255
    return limit - TEMPORARY_NAME_EXTRA


def check_output_file(path, overwrite):
    """Check ``--out`` of a run before anything is simulated: a file name in a writable
    folder, short enough for the writer's temporary names, not a folder, not a link to
    nowhere, not an existing file without --overwrite."""
    import os

    from ..contract.writer import TEMPORARY_NAME_EXTRA

    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    size = len(os.fsencode(path.name))
    if folder.is_dir() and size > longest_output_name(folder):
        raise GrainviewError(f"--out {path.name[:24]}...: a file name of {size} bytes: expected at most "
                             f"{longest_output_name(folder)} in {folder} (the writer's temporary names add "
                             f"{TEMPORARY_NAME_EXTRA} bytes to it)")
    if path.is_symlink() and not path.exists():
        raise GrainviewError(f"--out {path} is a symbolic link to {os.readlink(path)}, which does not exist; "
                             "expected a file name (or the link's target folder made first)")
    if path.is_dir():
        raise GrainviewError(f"--out {path} is a folder; expected a file name such as {path / 'run.nc'}")
    if path.exists() and not overwrite:
        raise GrainviewError(f"--out {path} exists; pass --overwrite to replace it")
    if not folder.is_dir():
        raise GrainviewError(f"--out {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise GrainviewError(f"--out {path}: the folder {folder} is not writable")


def check_run_settings(args, prep):
    """Every setting of a run against the others before any work: the solver parameters (a
    time step of the wrong sign or form is named as such first), then the time step against
    the walls' speeds and the test's length in steps, by the engine (:mod:`solver.engine`)."""
    from solver.engine import check_test, engine

    parameters = solver_parameters(args)
    scene = getattr(args, "scene", "biaxial")
    if scene == "shear":
        check_shear(args, parameters)
    check_test(args.engine, biaxial_test(args), scene)
    engine(args.engine).check(prep, parameters, biaxial_test(args) if scene == "biaxial" else None)


def check_shear(args, parameters):
    """Scene shear: an engine that declares it (:func:`solver.engine.check_scene`), and the
    settings its periodic cell takes (``check_simple_shear``), before any work."""
    from solver.engine import check_scene, engine

    check_scene(args.engine, "shear")
    engine(args.engine).check_simple_shear(parameters)
