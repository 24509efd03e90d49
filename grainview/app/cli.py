"""The ``grainview`` command line: ``study``, ``run``, ``ensemble``, ``report``, ``info``, ``export``,
``demo`` and ``warmup``.

Errors a user can cause are printed as one line (``grainview: error: ...``) with exit code 2,
never as a traceback.

The simulation's options (``run``, ``study``, ``ensemble``) are the fields of the settings
records of :mod:`solver.parameters` (``Parameters``, ``Preparation``, ``BiaxialTest``): each
option's flag, type, choices, default and help come from its field (:func:`setting_option`),
and its value is checked by the record's validator. The command line holds no default of its
own for them; options of other functions take those functions' defaults
(:func:`library_default`). The simulation itself goes through an engine of
:mod:`solver.engine` (``--engine``), so another engine needs no edit here.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import signal
import sys
from pathlib import Path

from ..contract.errors import ConvergenceWarning, GrainviewError, SchemaError

S1S2_HELP = ("s1s2: the paper's two initial states, each shape compacted its own way: pentagons with "
             "friction 0.4 as 'paper' (the paper's S1, solid fraction 0.80), disks compacted frictionless (S2, the "
             "denser 0.82); both tested with friction 0.4; docs/fidelity.md")
"""What ``--preparation s1s2`` means, in the help of every command that takes it."""
SOLVER_OPTIONS = ("wall_friction", "time_step", "tolerance", "solver", "stall_sweeps", "domains")
"""The :class:`solver.parameters.Parameters` fields that ``run`` and ``study`` take as options;
each option's type, choices, default and help are its field's (:func:`setting_option`)."""
ENSEMBLE_SOLVER_OPTIONS = ("wall_friction", "time_step", "tolerance", "solver")
"""The :class:`solver.parameters.Parameters` fields that ``ensemble`` takes as options."""
PREPARATION_OPTIONS = ("friction", "sigma0", "compaction_friction", "max_inertia_number", "aspect", "pressure_ramp")
"""The :class:`solver.preparation.Preparation` fields that change a named preparation on the
command line (besides the sample: particles, shape, seed)."""
TEST_OPTIONS = ("strain", "velocity", "every")
"""The :class:`solver.parameters.BiaxialTest` fields: the options of the biaxial test."""
STUDY_SAMPLES = {"pentagons": "pentagon", "disks": "disk"}
"""The study's samples: file label -> shape."""


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


def _convert_peer(args) -> int:
    from ..formats.peers import convert_peer

    count = convert_peer(args.out, args.raw, args.sample, engine=args.format, overwrite=args.overwrite,
                         compress=not args.no_compress)
    print(f"wrote {args.out}: {count} snapshots from {args.format} (check it: grainview info {args.out} --check)")
    return 0


def _convert(args) -> int:
    from ..formats.lammps import convert_lammps

    columns = None
    if args.columns:
        try:
            columns = dict(item.split("=", 1) for item in args.columns.split(","))
        except ValueError:
            raise GrainviewError(f"--columns {args.columns}: expected QUANTITY=COLUMN,... (e.g. "
                                 "patom1=c_pairs[1],patom2=c_pairs[2])") from None
    count = convert_lammps(args.out, args.particles, args.contacts, args.walls, log=args.log,
                           time_step=args.time_step, columns=columns, inertia=args.inertia,
                           overwrite=args.overwrite, compress=not args.no_compress,
                           progress=args.progress != "off")
    print(f"wrote {args.out}: {count} snapshots from LAMMPS (check it: grainview info {args.out} --check)")
    return 0


def _convert_lmgc90(args) -> int:
    from ..formats.lmgc90 import convert_lmgc90

    count = convert_lmgc90(args.out, args.run, x_period=args.x_period, overwrite=args.overwrite,
                           compress=not args.no_compress, progress=args.progress != "off")
    print(f"wrote {args.out}: {count} snapshots from LMGC90 (check it: grainview info {args.out} --check)")
    return 0


def _mercurydpm_units(text):
    """``--units si`` or ``--units length=L,mass=M,time=T`` as the reader's ``units``."""
    if text.strip().lower() == "si":
        return "si"
    try:
        return {key.strip(): float(value) for key, value in (item.split("=", 1) for item in text.split(","))}
    except ValueError:
        raise GrainviewError(f"--units {text}: expected si or length=L,mass=M,time=T (the SI value of one unit of "
                             "the run: m, kg, s)") from None


def _convert_mercurydpm(args) -> int:
    import warnings

    from ..formats.mercurydpm import convert_mercurydpm

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        count = convert_mercurydpm(args.out, args.data, args.fstat, args.restart,
                                   units=_mercurydpm_units(args.units), overwrite=args.overwrite,
                                   compress=not args.no_compress, progress=args.progress != "off")
    for note in caught:
        print(f"note: {note.message}")
    print(f"wrote {args.out}: {count} snapshots from MercuryDPM (check it: grainview info {args.out} --check)")
    return 0


def _convert_pegs(args) -> int:
    import warnings

    from ..formats.pegs import convert_pegs

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        count = convert_pegs(args.out, args.adjacency, args.positions, metres_per_pixel=args.metres_per_pixel,
                             force_unit_n=args.force_unit_n, frame_interval_s=args.frame_interval,
                             thickness_m=args.thickness, density_kg_m3=args.density, overwrite=args.overwrite,
                             compress=not args.no_compress, progress=args.progress != "off")
    for note in caught:
        print(f"note: {note.message}")
    print(f"wrote {args.out}: {count} frames from PeGS2 (check it: grainview info {args.out} --check)")
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


def _preparation(args, shape, particles=None):
    """The :class:`solver.preparation.Preparation` the command line asks for: the named preset
    with the preparation's settings given on the command line (:data:`PREPARATION_OPTIONS`);
    ``particles``: the sample's size (default ``--particles``)."""
    from solver.preparation import preparation

    changes = {name: getattr(args, name) for name in PREPARATION_OPTIONS if name in _given(args)}
    particles = args.particles if particles is None else particles
    return preparation(args.preparation, particles=particles, shape=shape, seed=args.seed, **changes)


def _solver_parameters(args) -> dict:
    """The :class:`solver.Parameters` fields given on the command line (:data:`SOLVER_OPTIONS`;
    the others keep their defaults), validated."""
    from solver.parameters import Parameters

    parameters = {name: getattr(args, name) for name in SOLVER_OPTIONS if name in _given(args)}
    if getattr(args, "acceleration", None) is not None:  # the former name of --solver
        from solver.contact_solvers import from_acceleration

        if "solver" in parameters:
            raise GrainviewError("--acceleration and --solver name the same setting: expected one of them")
        parameters["solver"] = from_acceleration(args.acceleration)
    Parameters(**parameters).validate()  # one clear line before anything is simulated
    return parameters


def _test(args):
    """The :class:`solver.parameters.BiaxialTest` of the command line, checked by its own
    validator before anything is simulated; a bad value is named by its flag."""
    from solver.parameters import BiaxialTest, problems

    test = BiaxialTest(**{name: getattr(args, name) for name in TEST_OPTIONS})
    for name, value, expected in problems(test)[:1]:
        shown = f"{value:g}" if isinstance(value, float) else value
        raise GrainviewError(f"{_flag(name)} {shown}: expected {expected}")
    return test


def _given(args) -> set:
    """The settings given on the command line (:class:`_Given`)."""
    return getattr(args, "given", None) or set()


def _flag(name) -> str:
    """The command-line flag of a setting: ``--`` and its name with dashes."""
    return "--" + name.replace("_", "-")


class _Given(argparse.Action):
    """Stores an option's value and notes, in ``args.given``, that it was given: a named
    preparation's own values hold for the settings that were not."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        namespace.given = _given(namespace) | {self.dest}


def _setting_type(f):
    """The command-line type of a settings field: its annotation's first type (``float | None``:
    float; ``str | int``: str, parsed further by the command)."""
    return {"float": float, "int": int}.get(str(f.type).split("|")[0].strip(), str)


def setting_option(parser, record, name, *, more="", flag=None, **overrides):
    """Add the option of field ``name`` of the settings dataclass ``record``
    (:func:`solver.parameters.setting`): flag ``--name-with-dashes``, its type, choices, default
    and help (the field's help, unit and default), all from the field. ``more``: words added to
    the help; ``flag``: another flag; ``overrides``: other
    :meth:`argparse.ArgumentParser.add_argument` keywords."""
    from dataclasses import fields

    f = next(f for f in fields(record) if f.name == name)
    meta, default = f.metadata, f.default
    choices = meta["choices"]() if meta.get("choices") else None
    shown = "none" if default is None else f"{default:g}" if isinstance(default, float) else default
    unit = f" {meta['unit']}" if meta.get("unit") and default is not None else ""
    text = f"{meta['help']}{more} (default {shown}{unit})".replace("%", "%%")
    options = dict(dest=name, default=default, action=_Given, help=text)
    options.update(dict(choices=choices) if choices is not None else dict(type=_setting_type(f)))
    options.update(overrides)
    parser.add_argument(flag or _flag(name), **options)


@functools.cache
def _module_tree(module):
    """The parsed source of ``module`` of grainview or solver (nothing imported), parsed once
    per process however many options read it."""
    import ast

    path = Path(__file__).parents[2].joinpath(*module.split(".")).with_suffix(".py")  # beside the grainview package
    return ast.parse(path.read_text(encoding="utf-8"))


def library_constant(module, name):
    """The value of the constant ``name`` of ``module`` (grainview's or solver's), read from its
    source, so that ``--help`` loads no xarray or scipy."""
    import ast

    node = next(n for n in _module_tree(module).body if isinstance(n, ast.Assign)
                and any(isinstance(t, ast.Name) and t.id == name for t in n.targets))
    return ast.literal_eval(node.value)


def library_default(module, function, parameter):
    """The default of ``parameter`` of grainview's ``module.function``, read from the module's
    source (its signature, parsed; nothing imported), so that an option's default is the
    function's and ``--help`` loads no xarray."""
    import ast

    node = next(n for n in ast.walk(_module_tree(module)) if isinstance(n, ast.FunctionDef) and n.name == function)
    args = node.args
    positional = args.posonlyargs + args.args
    pairs = list(zip(positional[len(positional) - len(args.defaults):], args.defaults))
    pairs += [(a, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None]
    return next(ast.literal_eval(d) for a, d in pairs if a.arg == parameter)


def _shape_of(text, option=None):
    """A shape of the command line: a name of :data:`solver.shapes.SHAPES` (disk, pentagon...),
    a number of vertices from 3 to :data:`MAX_VERTICES` (as an integer), a family of random
    convex polygons (:data:`solver.shape_families.FAMILIES`: irregular) or a .json file of vertex
    lists (read and checked here, given on as an absolute path)."""
    import os

    from solver.shape_families import SHAPE_FILE_SUFFIX, check_shape

    text = str(text).strip()
    shape = int(text) if text.isdigit() else text
    try:
        check_shape(shape)  # the library's one check
    except GrainviewError as exc:  # "shape=...: what was expected", or a file's name and what is wrong with it
        words = str(exc)
        if words.startswith("shape="):
            words = words.split(": ", 1)[1]
            raise GrainviewError(f"{option or f'--shape {text}'}: {words}") from None
        raise GrainviewError(f"{option or '--shape'} {words}") from None
    return os.path.abspath(text) if text.lower().endswith(SHAPE_FILE_SUFFIX) else shape


def _simulate(prep, path, *, test, near_contacts, overwrite, progress, scene="biaxial", parameters=None,
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

    from solver.engine import DEFAULT_ENGINE
    from solver.engine import engine as engine_named
    from solver.engine import prepare

    runner = engine_named(engine or DEFAULT_ENGINE)
    if scene == "shear":
        _refuse_other_engines(engine)
    path = Path(path)
    if path.exists() and not overwrite:
        raise GrainviewError(f"{path} exists; pass --overwrite to replace it")
    from solver.shape_families import shape_label

    name = label or shape_label(prep.shape)
    resumed = checkpoint is not None and Path(checkpoint).exists()
    if resumed:
        print(f"{name}: resuming the compaction of {prep.particles} particles from {checkpoint} ...", flush=True)
    else:
        print(f"{name}: depositing {prep.particles} particles and compacting under {prep.sigma0:g} Pa ...", flush=True)
    from time import monotonic

    from solver.paper_size import hours

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
            from solver.periodic_shear import matching_shear_rate, periodic_sample, shear_test

            rate = matching_shear_rate(sample, test.velocity) if shear_rate is None else shear_rate
            print(f"{name}: periodic simple shear to gamma = {test.strain} at {rate:.3g} s-1 under "
                  f"sigma_yy = {prep.sigma0:g} Pa ...", flush=True)
            shear_test(periodic_sample(sample), path, strain=test.strain, shear_rate=rate, every=int(test.every),
                       overwrite=overwrite, attrs=history.attrs(), progress=progress, near_contacts=near_contacts,
                       compress=compress)
        else:
            print(f"{name}: biaxial compression to eps_1 = {test.strain} at {test.velocity:g} m/s{_inertia(sample, test)}"
                  " ...", flush=True)
            runner.shear(sample, path, test, overwrite=overwrite, progress=progress, attrs=history.attrs(),
                         near_contacts=near_contacts, compress=compress)
    unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    if unconverged:
        print(f"{name}: warning: {_unconverged_warning(sample, path, unconverged)}", file=sys.stderr)
    print(f"{name}: wrote {path}" + ("" if scene == "isotropic" else f" (the test: {hours(monotonic() - start)} of wall "
                                      "time)"), flush=True)
    return path


def _inertia(sample, test) -> str:
    """The test's inertia numbers at its start, in words (:func:`solver.paper_size.inertia_numbers`),
    or "" for a sample that is not this package's simulation."""
    from solver.paper_size import inertia_numbers

    try:
        paper, grain = inertia_numbers(sample, test.velocity)
    except AttributeError:  # another engine's sample
        return ""
    return f" (inertia number I = {paper:.1e}, the paper's eps_dot sqrt(m/p); grain-scale {grain:.1e})"


def _unconverged_warning(sim, path, unconverged) -> str:
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


def _reissue(caught):
    """Show again the warnings of ``caught`` (a ``catch_warnings(record=True)`` list) other than
    the ConvergenceWarnings, which the caller summarises in one line."""
    import warnings

    for w in caught:
        if not issubclass(w.category, ConvergenceWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _resumed_unconverged_warning(path, unconverged) -> str:
    """What the warning on a resumed test's unconverged steps says: how many of the steps taken
    now stopped at their contact solver's iteration cap or stall test, and, from the written
    file, how many of the whole test's did and how far their impulses were from a solution
    (grainview.app.convergence), in the words of :func:`_unconverged_warning`."""
    import netCDF4

    from .convergence import norms_phrase, residual_comparison, stop_rule, tolerances, unconverged_in_file

    with netCDF4.Dataset(path) as nc:
        counts = unconverged_in_file(nc.variables, {k: nc.getncattr(k) for k in nc.ncattrs()})
    if counts is None:  # another engine's file
        return f"the contact solver did not converge in {unconverged} step(s) of the resumed test"
    whole = f"; in the whole test {counts['steps']} of its {counts['of']} ({residual_comparison(counts)})"
    return (f"the contact solver ({counts['solver']}) did not converge in {unconverged} of the resumed test's steps"
            f"{whole}. They stopped at {stop_rule(counts)} before {norms_phrase(counts)} ({tolerances(counts)}). "
            f"{path} records the test's per snapshot (nlgs_unconverged_steps), and its report states them")


def _progress_flag(args):
    return None if args.progress == "auto" else args.progress == "on"


def _simulation_kwargs(args):
    return dict(test=_test(args), near_contacts=args.near_contacts, overwrite=args.overwrite,
                progress=_progress_flag(args), parameters=_solver_parameters(args), compress=not args.no_compress,
                engine=args.engine)


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


def _check_output_file(path, overwrite):
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


def _check_settings(args, prep):
    """Every setting of a run against the others before any work: the solver parameters (a
    time step of the wrong sign or form is named as such first), then the time step against
    the walls' speeds and the test's length in steps, by the engine (:mod:`solver.engine`)."""
    from solver.engine import engine

    parameters = _solver_parameters(args)
    scene = getattr(args, "scene", "biaxial")
    if scene == "shear":
        _check_shear(args, parameters)
    engine(args.engine).check(prep, parameters, _test(args) if scene == "biaxial" else None)


def _run(args) -> int:
    _shear_strain_default(args)
    _test(args)
    _check_output_file(args.out, args.overwrite)
    prep = _preparation(args, _shape_of(args.shape))
    _check_settings(args, prep)
    from solver.engine import DEFAULT_ENGINE

    if (args.engine or DEFAULT_ENGINE) == DEFAULT_ENGINE:
        from solver.paper_size import machine_load

        from .warmup import cold_shares

        shares = cold_shares(["solver"])
        line = _compile_line("run", shares, machine_load())
        if line:
            print(line, flush=True)
            _compile_ahead("run", shares, _progress_flag(args))
    _simulate(prep, args.out, scene=args.scene, shear_rate=args.shear_rate, **_simulation_kwargs(args))
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
    figures = _split(args.figures, str, "figures") if getattr(args, "figures", None) else None
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
    (grainview.app.report.terminal_table)."""
    from .report import terminal_table

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


def _split(text, kind, name):
    """A comma-separated command-line list as values of ``kind``."""
    try:
        values = [kind(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise GrainviewError(f"--{name} {text}: expected a comma-separated list of {kind.__name__} values") from None
    if not values:
        raise GrainviewError(f"--{name} {text}: expected at least one value")
    return values


def _ensemble(args) -> int:
    from solver.ensemble import check_cluster, grid, run_ensemble

    check_cluster(args.scheduler, args.workers)  # before any line is printed; the library's one check
    test = _test(args)
    frictions = _split(args.friction_list, float, "friction") if args.friction_list else [None]
    sigma0 = _split(args.sigma0_list, float, "sigma0") if args.sigma0_list else [None]
    particles = {"particles": _split(args.particles_list, int, "particles")} if args.particles_list else {}
    shapes = [_shape_of(s, f"--shapes {args.shapes}") for s in _split(args.shapes, str, "shapes")]
    specs = grid(shapes=shapes, **particles, frictions=frictions, sigma0=sigma0,
                 seeds=args.seeds, first_seed=args.seed, preparation=args.preparation,
                 strain=test.strain, velocity=test.velocity, every=test.every,
                 solver=tuple(sorted(_solver_parameters(args).items())), engine=args.engine)
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
                           progress=_progress_flag(args), log=lambda line: print(f"ensemble: {line}", flush=True))
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


def _study_particles(args) -> dict:
    """The study's sample sizes, label -> particles: ``--particles N`` for both samples,
    ``--particles N1,N2`` for the pentagons and the disks, ``--paper-size`` the paper's
    (:data:`solver.paper_size.PAPER_PARTICLES`)."""
    from solver.paper_size import PAPER_PARTICLES

    if args.paper_size:
        if "particles" in _given(args):
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


def _study_tests(args, particles) -> dict:
    """The study's biaxial test of each sample, label -> :class:`solver.parameters.BiaxialTest`:
    the command line's; with ``--paper-size`` and no ``--velocity``, each sample's top wall at
    the strain rate of 400 particles at 1 cm/s (:func:`solver.paper_size.velocity_for`)."""
    from dataclasses import replace

    from solver.paper_size import velocity_for

    test = _test(args)
    if not args.paper_size or "velocity" in _given(args):
        return dict.fromkeys(particles, test)
    return {label: replace(test, velocity=velocity_for(n)) for label, n in particles.items()}


def _study_state(runner, prep, parameters, path, checkpoint, expected, overwrite) -> str:
    """What is to be done for one sample of the study: "finished" (its file complete),
    "partial" (its test to be resumed) or "start" (from its compaction's checkpoint when there
    is one, else from its deposit). A file or checkpoint of other settings (``expected``: the
    file's attributes; ``prep`` and ``parameters``: what the checkpoint is of) is refused in one
    line before any work, unless ``overwrite`` (then the checkpoint is removed and the sample
    starts afresh)."""
    from solver.restart import check_settings

    if overwrite:
        checkpoint.unlink(missing_ok=True)
        return "start"
    state = runner.file_state(path)
    if state in ("finished", "partial"):
        check_settings(path, expected, "pass --overwrite to replace it, or give the settings it was made with")
        checkpoint.unlink(missing_ok=True)  # the compaction is in the test's file now
        return state
    if checkpoint.exists():
        from solver.engine import check_checkpoint

        check_checkpoint(runner, checkpoint, prep, parameters)
    return "start"


def _expected_attrs(prep, test, parameters, scene="biaxial") -> dict:
    """File attributes a study file of ``prep`` sheared in ``test`` (the biaxial test, or the
    periodic cell's shear for ``scene="shear"``: its rate comes from the compacted sample, so
    only its strain is known) with the solver settings ``parameters`` (the command line's
    :data:`SOLVER_OPTIONS`, given or default) holds."""
    velocity = {"wall_velocity_m_s": test.velocity} if scene == "biaxial" else {}
    return {"scene": scene, "strain_target": test.strain, **velocity, "snapshot_every": test.every,
            "solver_friction": prep.friction, "sigma0_Pa": prep.sigma0, **prep.attrs(),
            **{f"solver_{k}": v for k, v in parameters.items()}}


def _study_sample(label, prep, path, state, checkpoint, *, test, near_contacts, overwrite, progress,
                  parameters=None, compress=True, engine=None, scene="biaxial"):
    """One sample of the study: skipped when finished (a file whose compression was stopped is
    compressed), its test resumed when partial, else prepared (from the compaction's
    checkpoint ``checkpoint`` when it holds one) and sheared into ``path``; the checkpoint is
    removed once the test's file is complete."""
    from solver.engine import DEFAULT_ENGINE
    from solver.engine import engine as engine_named

    runner = engine_named(engine or DEFAULT_ENGINE)
    if state == "finished":
        runner.resume(path, progress=progress, compress=compress)
        print(f"{label}: {path} is complete (skipped)", flush=True)
        return path
    if state == "partial":
        import warnings
        from time import monotonic

        from solver.paper_size import hours

        print(f"{label}: resuming the test in {path} ...", flush=True)
        start = monotonic()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            steps = runner.resume(path, progress=progress, compress=compress)
        _reissue(caught)
        unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
        if unconverged:
            print(f"{label}: warning: {_resumed_unconverged_warning(path, unconverged)}", file=sys.stderr)
        print(f"{label}: resumed for {steps} steps ({hours(monotonic() - start)} of wall time); wrote {path}",
              flush=True)
        return path
    _simulate(prep, path, test=test, near_contacts=near_contacts, overwrite=True, progress=progress,
              parameters=parameters, compress=compress, engine=engine, checkpoint=checkpoint, label=label,
              scene=scene)
    Path(checkpoint).unlink(missing_ok=True)
    return path


def _print_estimate(preps, tests, parameters, jobs, shares=None, report=True, load=None):
    """Print the expected wall time of the study: each stage of each sample on idle cores, with
    where its cost comes from, the compiling (``shares``: :func:`grainview.app.warmup.cold_shares`
    of a cold cache) and the report (``report``), the machine's load (``load``: (load average,
    cores), default this machine's) and what it makes of them, and the whole
    (:func:`solver.paper_size.study_estimate`)."""
    from solver.paper_size import STUDY_TIME, hours, machine_load, study_estimate
    from solver.parameters import Parameters

    p = Parameters(**parameters)
    load, cores = machine_load() if load is None else load
    shares = {group: share for group, (share, _) in (shares or {}).items() if share}
    whole = study_estimate({label: (prep, tests[label]) for label, prep in preps.items()}, p.time_step,
                           domains=p.domains, jobs=jobs, compile_share=shares, report=report, load=load, cores=cores)
    for label, stages in whole["samples"].items():
        for stage, (steps, cost, seconds, source) in stages.items():
            print(f"estimate: {label} ({preps[label].particles}), {stage}: ~{steps} steps x {cost:.3g} us per particle "
                  f"and step = ~{hours(seconds)} ({source})", flush=True)
    idle, factor, seconds = whole["idle"], whole["factor"], whole["seconds"]
    extra = []
    if idle["compile"]:
        which = " and ".join(f"{100 * share:.0f}% of the {group}'s" for group, share in shares.items())
        extra.append(f"compiling {which} kernels (not in numba's cache for this processor) ~{hours(idle['compile'])}")
    if report:
        extra.append(f"the report ~{hours(idle['report'])}")
    if extra:
        print(f"estimate: {', '.join(extra)}, on an idle core ({STUDY_TIME})", flush=True)
    if factor["simulation"] > 1 or factor["compile"] > 1:
        busy = "busy" if max(factor.values()) >= 1.5 else "lightly loaded"
        print(f"estimate: this machine is {busy} (load {load:.1f} on {cores} cores): each stage takes longer than on "
              f"idle cores, ~{factor['simulation']:.1f}x for the {whole['processes']} simulating process(es), "
              f"~{factor['compile']:.1f}x for one process (compiling, the report)", flush=True)
    else:
        print(f"estimate: the cores are free (load {load:.1f} on {cores} cores): the times above hold as they are",
              flush=True)
    parts = [f"{name} ~{hours(seconds[key])}" for key, name in
             (("compile", "compiling"), ("simulation", "the samples"), ("report", "the report")) if seconds[key]]
    print(f"estimate: the study ~{hours(whole['total'])} of wall time ({', '.join(parts)}; "
          f"{'side by side' if jobs > 1 else 'one after the other'}, "
          f"{'serial sweeps' if p.domains <= 1 else f'{p.domains} domains'}), within a factor of about 2; a "
          "stopped or killed run resumes with the same command", flush=True)


def _compile_line(command, shares, load) -> str:
    """The line that says, before anything else, that the kernels are compiled first and for
    about how long (``shares``: :func:`grainview.app.warmup.cold_shares`; ``load``: (load
    average, cores)); "" on a warm cache."""
    from solver.paper_size import COMPILE_SECONDS, hours, load_factor

    seconds = sum(COMPILE_SECONDS[group] * share for group, (share, _) in shares.items())
    if not seconds:
        return ""
    seconds *= load_factor(1, *load)
    return (f"{command}: compiling the kernels, first run only, about {hours(seconds)} (grainview warmup does it ahead "
            "of time)")


def _compile_ahead(command, shares, progress):
    """Compile, in this process and before any work, the kernels that ``shares``
    (:func:`grainview.app.warmup.cold_shares`) names, with progress: a line per stage of the
    warm-up's workload (:func:`grainview.app.warmup.warm_up`) with the kernels compiled so far,
    and in a terminal a bar over the kernels (``progress``: the command line's flag, None:
    auto), else a line a minute too. Ends with a line saying how long it took."""
    from time import monotonic

    from solver.paper_size import hours

    from .warmup import GROUPS, warm_up

    names = {name for _, found in shares.values() for name in found}
    if not names:
        return
    packages = tuple(package for group in GROUPS for package in GROUPS[group]
                     if group in shares and (group != "analysis" or shares[group][0]))
    done, start = set(), monotonic()
    bar = None
    if (sys.stderr.isatty() if progress is None else progress is True):
        from tqdm.std import tqdm

        bar = tqdm(total=len(names), desc=f"{command}: compiling", unit="kernel", leave=False)

    last = [start]

    def compiled(name):
        if name in names and name not in done:
            done.add(name)
            if bar is not None:
                bar.update(1)
            elif monotonic() - last[0] >= _SampleProgress.every:  # a log's line now and then
                last[0] = monotonic()
                print(f"{command}: compiling: {len(done)} of {len(names)} kernels, {hours(last[0] - start)}",
                      flush=True)

    def log(line):
        last[0] = monotonic()
        text = (f"{command}: compiling, stage {line}; {len(done)} of {len(names)} kernels so far, "
                f"{hours(last[0] - start)}")
        if bar is not None:
            bar.write(text)
        else:
            print(text, flush=True)

    from solver.interrupt import sigterm_raises

    try:
        with sigterm_raises():  # nothing is written yet: SIGTERM stops the command at once, as Ctrl-C does
            result = warm_up(log=log, packages=packages, compiled=compiled)
    finally:
        if bar is not None:
            bar.close()
    print(f"{command}: kernels compiled in {hours(monotonic() - start)} ({len(done)} compiled, the others loaded; "
          f"cache: {result['cache']})", flush=True)


def _shear_strain_default(args):
    """Scene shear: the test's strain is a shear gamma, SHEAR_STRAIN unless --strain is given
    (the biaxial test's default is an eps_1)."""
    if getattr(args, "scene", "biaxial") == "shear" and "strain" not in _given(args):
        from solver.periodic_shear import SHEAR_STRAIN

        args.strain = SHEAR_STRAIN


def _check_shear(args, parameters):
    """Scene shear: the settings only this package's solver and its NLGS or Anderson sweeps take
    (:func:`solver.cell_coupling.check_solver`), before any work."""
    from solver.cell_coupling import check_solver
    from solver.parameters import Parameters

    _refuse_other_engines(args.engine)
    check_solver(Parameters(**parameters))


def _refuse_other_engines(engine):
    """Scene shear: the periodic cell is this package's solver's; another ``engine`` is refused."""
    from solver.engine import DEFAULT_ENGINE

    if (engine or DEFAULT_ENGINE) != DEFAULT_ENGINE:
        raise GrainviewError(f"scene shear: the periodic cell is this package's solver's ({DEFAULT_ENGINE}), "
                             f"not engine {engine}'s")


def _estimated_tests(tests, scene):
    """The biaxial tests whose estimate stands for the study's tests: for scene shear, the one
    that reaches the same eps_q in as many steps (h (e^eps_1 - 1) = gamma h / 2 at the same top
    wall speed); a periodic step's cost is the walled one's in the estimate."""
    if scene != "shear":
        return tests
    import math
    from dataclasses import replace

    return {label: replace(test, strain=math.log1p(test.strain / 2)) for label, test in tests.items()}


def _study(args) -> int:
    from concurrent.futures import ProcessPoolExecutor

    from solver.engine import engine

    _shear_strain_default(args)
    _test(args)
    if args.jobs < 1:
        raise GrainviewError(f"--jobs {args.jobs}: expected at least 1 process")
    import os

    threads = min(args.jobs, len(STUDY_SAMPLES)) * args.domains
    if threads > (os.cpu_count() or 1):
        raise GrainviewError(f"--domains {args.domains} with --jobs {args.jobs} needs {threads} cores, this machine has "
                             f"{os.cpu_count()}: a busy core stalls every parallel sweep; pass --jobs 1")
    out = Path(args.out)
    samples = STUDY_SAMPLES
    particles = _study_particles(args)
    tests = _study_tests(args, particles)
    preps = {label: _preparation(args, shape, particles[label]) for label, shape in samples.items()}
    parameters = _solver_parameters(args)
    runner = engine(args.engine)
    shear = args.scene == "shear"
    if shear:
        _check_shear(args, parameters)
    for label, prep in preps.items():
        runner.check(prep, parameters, None if shear else tests[label])
    paths = {label: out / f"{label}.nc" for label in samples}
    checkpoints = {label: out / f"{label}.compaction.nc" for label in samples}
    if out.is_file():
        raise GrainviewError(f"--out {out} is a file; expected a folder")
    from solver.parameters import Parameters, default_of

    recorded = {name: parameters.get(name, default_of(Parameters, name)) for name in SOLVER_OPTIONS}
    states = {label: _study_state(runner, preps[label], parameters, paths[label], checkpoints[label],
                                  _expected_attrs(preps[label], tests[label], recorded, args.scene), args.overwrite)
              for label in samples}
    out.mkdir(parents=True, exist_ok=True)
    to_run = [label for label, state in states.items() if state != "finished"]
    if to_run:
        from solver.engine import DEFAULT_ENGINE
        from solver.paper_size import machine_load

        from .warmup import GROUPS, cold_shares

        load = machine_load()
        groups = [group for group in GROUPS if group != "solver" or (args.engine or DEFAULT_ENGINE) == DEFAULT_ENGINE]
        shares = cold_shares(groups if not args.no_report else [g for g in groups if g == "solver"])
        line = _compile_line("study", shares, load)
        if line:
            print(line, flush=True)
        _print_estimate({label: preps[label] for label in to_run}, _estimated_tests(tests, args.scene), parameters,
                        args.jobs, shares, report=not args.no_report, load=load)
        _compile_ahead("study", shares, _progress_flag(args))
    args.near_contacts = True  # the report counts near pairs as well (docs/fidelity.md)
    kwargs = _simulation_kwargs(args)
    kwargs.pop("test")
    kwargs["overwrite"] = args.overwrite
    kwargs["scene"] = args.scene
    if args.jobs == 1:
        for label in samples:
            _study_sample(label, preps[label], paths[label], states[label], checkpoints[label], test=tests[label],
                          **kwargs)
    else:  # one process per sample: the two samples run side by side on two cores
        kwargs["progress"] = _SampleProgress.for_jobs(kwargs["progress"])
        with ProcessPoolExecutor(max_workers=min(args.jobs, len(samples))) as pool, _workers_stop_with_me() as stop:
            futures = [pool.submit(_study_sample, label, preps[label], paths[label], states[label],
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
                from solver.interrupt import Terminated

                raise (Terminated() if stop["signal"] == signal.SIGTERM or any(
                    isinstance(exc, SystemExit) for exc in stopped) else KeyboardInterrupt())
    report = out / "report"
    if args.no_report:
        return 0
    if all(state == "finished" for state in states.values()) and (report / "headline.csv").exists():
        print(f"study: every sample was complete already and {report} holds their report; nothing to do "
              "(--overwrite runs the study again)", flush=True)
        return 0
    args.files = [str(p) for p in paths.values()]
    args.labels = ",".join(paths)
    args.out = str(report)
    args.overwrite = True  # the report of the files just completed replaces an older one of the same folder
    return _report(args)


@contextlib.contextmanager
def _workers_stop_with_me():
    """While the study's samples run in worker processes: Ctrl-C or SIGTERM sent to this
    process alone (not to its process group, as a terminal or a batch scheduler sends them)
    stops the workers too, after their current step, as Ctrl-C does (a compaction writes its
    checkpoint, a test keeps its snapshots); this process then waits for them and stops.
    Yields ``{"signal": the signal received, or None}``. Only in the main thread."""
    import multiprocessing
    import os

    state = {"signal": None}

    def handler(signum, _frame):
        state["signal"] = signum
        for child in multiprocessing.active_children():
            os.kill(child.pid, signal.SIGINT)

    try:
        previous = {signum: signal.signal(signum, handler) for signum in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        yield state
        return
    try:
        yield state
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old)


class _SampleProgress:
    """The progress of one sample of a study run side by side with the others: a tqdm bar at
    its own line in a terminal, else a line every :attr:`every` seconds (steps done, elapsed,
    expected to go). Called as ``progress(total, desc)`` (:func:`solver.interrupt.progress_bar`);
    picklable, for the worker processes."""

    every = library_constant("solver.interrupt", "PROGRESS_LINE_SECONDS")

    def __init__(self, terminal, position=0, label=""):
        self.terminal, self.position, self.label = terminal, position, label

    @classmethod
    def for_jobs(cls, flag):
        """The progress of side-by-side samples for the command line's ``--progress`` (None:
        auto, True: on, False: off): None when off."""
        if flag is False:
            return False
        return cls(terminal=sys.stderr.isatty() or flag is True)

    def at(self, position, label):
        """The progress of the sample ``label``, shown at line ``position``."""
        sample = _SampleProgress(self.terminal, position, label)
        sample.every = self.every
        return sample

    def __call__(self, total, desc):
        if self.terminal:
            from tqdm.std import tqdm

            return tqdm(total=total, desc=f"{self.label}: {desc}", unit="step", position=self.position, leave=False)
        return _ProgressLines(total, f"{self.label}: {desc}", self.every)


class _ProgressLines:
    """A progress bar as lines on stdout, one every ``every`` seconds (a log file's progress)."""

    def __init__(self, total, desc, every):
        import time

        self.total, self.desc, self.every, self.done = total, desc, every, 0
        self.start = self.last = time.monotonic()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def update(self, n):
        import time

        self.done += n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            elapsed = now - self.start
            print(f"{self.desc}: step {self.done} of at most {self.total}, {elapsed / 60:.0f} min", flush=True)


def _no_compress_option(p):
    p.add_argument("--no-compress", action="store_true",
                   help="leave the finished netCDF files uncompressed (default: zlib, about half the size; "
                   "read the same either way)")


def _residual_option(p):
    residual = library_constant("grainview.analysis.strain", "RESIDUAL_STRAIN")
    p.add_argument("--residual-strain", type=float, default=residual,
                   help=f"the residual state starts at this shear strain eps_q (default {residual}); "
                   "a run short of it reports 'not reached'")


def _acceleration_option(p):
    """``--acceleration``, the former name of ``--solver`` (command lines written before it)."""
    from solver.contact_solvers import ACCELERATIONS

    p.add_argument("--acceleration", choices=tuple(ACCELERATIONS), default=None,
                   help="the former name of --solver: " + ", ".join(f"{old} is {new}" for old, new in
                                                                 ACCELERATIONS.items()) + " (default: --solver's)")


def _engine_option(p):
    from solver.engine import DEFAULT_ENGINE, engine_names

    p.add_argument("--engine", choices=engine_names(), default=DEFAULT_ENGINE,
                   help=f"the simulation engine (solver.engine; default {DEFAULT_ENGINE}: this package's contact "
                   "dynamics)")


def _test_options(p):
    """The biaxial test's options, from :class:`solver.parameters.BiaxialTest`."""
    from solver.parameters import BiaxialTest
    from solver.preparation import MIN_TEST_STEPS

    setting_option(p, BiaxialTest, "strain")
    setting_option(p, BiaxialTest, "velocity", more=f": finite, > 0, and such that the test takes at least "
                   f"{MIN_TEST_STEPS} time steps and no more than a file's 32-bit step counter holds")
    setting_option(p, BiaxialTest, "every")


def _simulation_options(p, samples=1):
    """The options of ``run`` and ``study``: the sample, the test, the solver's settings and
    the preparation, each from its record's field (:func:`setting_option`). ``samples``: the
    samples a command makes (the study's ``--particles`` takes one size or one per sample)."""
    from solver.parameters import Parameters
    from solver.preparation import DEFAULT_PRESET, Preparation, preset_names

    if samples > 1:
        setting_option(p, Preparation, "particles", type=str, more=f"; or {samples}, comma-separated, one per "
                       f"sample ({','.join(STUDY_SAMPLES)}), e.g. 14400,10000")
    else:
        setting_option(p, Preparation, "particles")
    _test_options(p)
    setting_option(p, Preparation, "seed")
    physics = p.add_argument_group("physics and numerics (defaults: the paper's)")
    for name in ("friction", "sigma0"):
        setting_option(physics, Preparation, name)
    for name in SOLVER_OPTIONS:
        setting_option(physics, Parameters, name)
    _acceleration_option(physics)
    _engine_option(physics)
    prep = p.add_argument_group("sample preparation (docs/fidelity.md)")
    prep.add_argument("--preparation", choices=preset_names(), default=DEFAULT_PRESET,
                      help=f"named preparation (default {DEFAULT_PRESET}: compaction with the test's friction, "
                      f"walls closing at up to {Preparation.max_wall_speed:g} m/s; {S1S2_HELP}); the options "
                      "below change it")
    for name in PREPARATION_OPTIONS:
        if name not in ("friction", "sigma0"):
            setting_option(prep, Preparation, name)
    p.add_argument("--overwrite", action="store_true", help="replace existing output files")
    p.add_argument("--progress", choices=["auto", "on", "off"], default="auto",
                   help="progress bars (default: on in a terminal)")
    _no_compress_option(p)


def _study_parser(sub):
    from solver.paper_size import PAPER_PARTICLES, REFERENCE_PARTICLES, REFERENCE_VELOCITY, velocity_for
    from solver.preparation import Preparation

    minutes = library_constant("solver.compaction_checkpoint", "CHECKPOINT_SECONDS") / 60
    study = sub.add_parser("study", help="the paper's study: pentagons vs disks, simulated, analysed, plotted",
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
    study.add_argument("--scene", choices=["biaxial", "shear"], default="biaxial",
                       help="biaxial (default: the top wall compresses each sample) or shear (each compacted sample in "
                       "the biperiodic cell of its box, sheared to gamma = --strain, default "
                       f"{library_constant('solver.periodic_shear', 'SHEAR_STRAIN'):g}, at 2 v/h under sigma_yy = "
                       "sigma0; as grainview run shear)")
    _residual_option(study)
    _simulation_options(study, samples=len(STUDY_SAMPLES))
    study.set_defaults(func=_study)


def _run_parser(sub):
    from solver.parameters import BiaxialTest
    from solver.preparation import Preparation
    from solver.shape_families import MAX_VERTICES

    run = sub.add_parser("run", help="simulate one sample into a netCDF file",
                         description=f"Geometric deposit, isotropic compaction under sigma0 ({Preparation.sigma0 / 1e3:g} "
                         f"kPa), then (scene biaxial) compression by the top wall ({BiaxialTest.velocity * 100:g} cm/s) "
                         "with sigma0 held on the right wall.")
    run.add_argument("scene", nargs="?", choices=["biaxial", "isotropic", "shear"], default="biaxial",
                     help="biaxial (default), isotropic (writes the compacted state) or shear (the compacted sample "
                     "in a biperiodic cell, sheared to gamma = --strain, default "
                     f"{library_constant('solver.periodic_shear', 'SHEAR_STRAIN'):g}, under sigma_yy = sigma0)")
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
    _simulation_options(run)
    run.set_defaults(func=_run)


def _report_parser(sub):
    report = sub.add_parser("report", help="analyse runs: headline table vs the paper and all figures",
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
    every = library_default("grainview.plot.movies", "animate", "every")
    report.add_argument("--movie-every", type=int, default=every,
                        help=f"one movie frame every k snapshots (default {every})")
    _residual_option(report)
    report.set_defaults(func=_report)


def _ensemble_parser(sub):
    from solver.parameters import Parameters
    from solver.shape_families import MAX_VERTICES
    from solver.preparation import DEFAULT_PRESET, Preparation

    ens = sub.add_parser("ensemble", help="many runs (settings x seeds) on a dask cluster, then their report",
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
        ens.add_argument(_flag(name), dest=f"{name}_list", default=None,
                         help=f"comma-separated values of {name}{unit} (default {default:g}, the preparation's)")
    seeds = library_constant("solver.ensemble", "SEEDS_PER_SETTING")
    ens.add_argument("--seeds", type=int, default=seeds, help=f"seeds per setting (default {seeds})")
    setting_option(ens, Preparation, "seed", flag="--first-seed", help=f"first seed (default {Preparation.seed})")
    _test_options(ens)
    ens.add_argument("--preparation", default=DEFAULT_PRESET, help=f"named preparation (default {DEFAULT_PRESET}; "
                     f"{S1S2_HELP})")
    for name in ENSEMBLE_SOLVER_OPTIONS:
        setting_option(ens, Parameters, name)
    _acceleration_option(ens)
    _engine_option(ens)
    ens.add_argument("--workers", type=int, default=None, help="worker processes of the local cluster "
                     "(default: one per core; each single-threaded)")
    ens.add_argument("--scheduler", default=None, help="address of an existing dask scheduler (tcp://host:8786); "
                     "its workers must import grainview and see --out (default: none, a local cluster)")
    ens.add_argument("--no-report", action="store_true", help="run only; no report")
    ens.add_argument("--overwrite", action="store_true", help="redo every run, replacing its file (and the report)")
    ens.add_argument("--overwrite-report", action="store_true", help="replace an existing report in OUT/report; "
                     "finished runs are kept")
    _no_compress_option(ens)
    ens.add_argument("--progress", choices=["auto", "on", "off"], default="auto", help="a progress bar per run "
                     "(default auto: on in a terminal)")
    _residual_option(ens)
    ens.set_defaults(func=_ensemble)


def _info_parser(sub):
    info = sub.add_parser("info", help="validate a grainview netCDF file and print its summary",
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
    export = sub.add_parser("export", help="write snapshots as VTK (ParaView, OVITO) or CSV",
                            description="Export a file of the data contract: --to vtk writes, per snapshot, "
                            "the particles (points with a radius) and the contacts (lines with fn, ft, kind, "
                            "force class) as VTK PolyData in one multi-block file, and the polygons' outlines; "
                            "snapshots.pvd puts them on the time axis (ParaView, OVITO), polygons.pvd the "
                            "outlines (ParaView); --to csv one tidy contact table (docs/analysis.md).")
    export.add_argument("file", help="netCDF file of the grainview contract")
    export.add_argument("--to", choices=("vtk", "csv"), required=True, help="output format")
    export.add_argument("--out", required=True, help="output folder (created if needed)")
    every = library_default("grainview.export.vtk", "write_vtk", "every")
    export.add_argument("--every", type=int, default=every,
                        help=f"export every k-th snapshot (and the last; default {every})")
    export.add_argument("--overwrite", action="store_true", help="replace existing files in --out")
    export.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default on)")
    export.set_defaults(func=_export)


def _demo_parser(sub):
    demo = sub.add_parser("demo", help="write a synthetic harmonic-model series and analyse it lazily",
                          description="Write a synthetic series drawn from the harmonic model (no simulation, "
                          "seconds) and compare q/p with the prediction (a' + a_n + a_t)/2 computed lazily "
                          "from the file.")
    demo.add_argument("--out", default="demo-out", help="output folder, made if needed (default: demo-out in the "
                      "current folder); the command says where it writes and refuses to replace its files without "
                      "--overwrite")
    snapshots, contacts = (library_default("grainview.app.demo", "run_demo", k) for k in ("snapshots", "contacts"))
    demo.add_argument("--snapshots", type=int, default=snapshots, help=f"number of snapshots (default {snapshots})")
    demo.add_argument("--contacts", type=int, default=contacts, help=f"contacts per snapshot (default {contacts})")
    seed = library_default("grainview.datasets", "harmonic_series", "seed")
    demo.add_argument("--seed", type=int, default=seed, help=f"random seed (default {seed})")
    demo.add_argument("--overwrite", action="store_true", help="replace existing output files")
    _no_compress_option(demo)
    demo.set_defaults(func=_demo)


def _warmup_parser(sub):
    from solver.paper_size import COMPILE_SECONDS, STUDY_TIME, hours

    cold = hours(sum(COMPILE_SECONDS.values()))
    warmup = sub.add_parser("warmup", help="compile every numba kernel into the cache, so that runs start at once",
                            description="Compile (or load) every numba kernel of the solver and the analysis into "
                            "numba's cache (NUMBA_CACHE_DIR when set, else __pycache__ beside the modules) with a "
                            f"tiny workload (seconds once warm; cold, about {cold} of processor time, the wall time "
                            f"on an idle core, longer on a busy one: {STUDY_TIME}). grainview run and study do it "
                            "first when the cache lacks their kernels; a batch job that runs the solver otherwise "
                            "spends its first step compiling and acts on SIGTERM only after that step: warm the cache "
                            "once per installation, e.g. before submitting batch jobs (docs/solver.md).")
    warmup.set_defaults(func=_warmup)


def _convert_parser(sub):
    convert = sub.add_parser("convert", help="turn another code's output into a file of the contract",
                             description="Read another code's output and write a validated, compressed file of "
                             "the grainview contract (docs/formats.md); an existing file is kept unless "
                             "--overwrite.")
    formats = convert.add_subparsers(dest="format", metavar="FORMAT", required=True)
    lammps = formats.add_parser("lammps", help="a LAMMPS 2D granular run (dump custom + dump local)",
                                description="A LAMMPS 2D granular run: the particles' dump custom (id radius mass "
                                "x y, optionally vx vy omegaz), the pairs' dump local (compute property/local "
                                "patom1 patom2; compute pair/local fx fy fz p1 p2 p3), optionally the walls' dump "
                                "custom of fix wall/gran ... contacts arrays, and the log (time step and the "
                                "computes' definitions). Contacts: touching pairs with a compressive normal force "
                                "(docs/formats.md).")
    lammps.add_argument("--particles", required=True, help="the particles' dump custom")
    lammps.add_argument("--contacts", required=True, help="the pairs' dump local")
    lammps.add_argument("--walls", help="the walls' dump custom (id and f_ID[1..8] of fix wall/gran ... contacts; "
                        "default: none, no wall contacts)")
    lammps.add_argument("--log", help="the run's log.lammps or input script: time step and compute definitions "
                        "(default: none; then --time-step is needed)")
    lammps.add_argument("--time-step", type=float, help="the time step in s (default: the log's)")
    lammps.add_argument("--columns", help="which dump local column holds each quantity, e.g. "
                        "patom1=c_pairs[1],patom2=c_pairs[2],fx=c_forces[2],fy=c_forces[3],p1=c_forces[5],"
                        "p2=c_forces[6] (default: from the log or the columns' own names)")
    lammps.add_argument("--inertia", choices=("auto", "disc", "sphere"), default="auto",
                        help="moments of inertia m r^2/2 (disc) or 2 m r^2/5 (sphere); auto: as the log's "
                        "fix nve/sphere says, disc without a log (default: auto)")
    lammps.add_argument("--out", required=True, help="the netCDF file to write")
    lammps.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    lammps.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    _no_compress_option(lammps)
    lammps.set_defaults(func=_convert)
    lmgc90 = formats.add_parser("lmgc90", help="an LMGC90 2D rigid run (DATBOX + OUTBOX text files)",
                                description="An LMGC90 2D rigid run: its folder holding DATBOX/BODIES.DAT and "
                                "BULK_BEHAV.DAT (RBDY2 bodies with one DISKx, convex POLYG or JONCx contactor) and "
                                "OUTBOX/DOF.OUT.n with Vloc_Rloc.OUT.n (DKDKx, DKJCx, PLPLx, PLJCx, DKPLx). "
                                "Contacts: body pairs with a compressive normal force; two points on a pair make a "
                                "double contact (docs/formats.md).")
    lmgc90.add_argument("run", help="the run folder (holding DATBOX/ and OUTBOX/)")
    lmgc90.add_argument("--x-period", type=float, default=None, metavar="L",
                        help="the run's period along x in m, as its script gave chipy.SetPeriodicCondition(xperiod=L) "
                             "(no output file records it; default: a run bounded by walls)")
    lmgc90.add_argument("--out", required=True, help="the netCDF file to write")
    lmgc90.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    lmgc90.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    _no_compress_option(lmgc90)
    lmgc90.set_defaults(func=_convert_lmgc90)
    mercury = formats.add_parser("mercurydpm", help="a MercuryDPM 2D run (.data + .fstat + .restart)",
                                 description="A MercuryDPM 2D run: its .data (particles), .fstat (contacts, each "
                                 "pair written from both sides) and .restart (dimensions, masses, walls). MercuryDPM "
                                 "has no units of its own: say which (--units). Contacts: overlapping pairs with a "
                                 "compressive normal force, one per pair (docs/formats.md).")
    mercury.add_argument("data", help="the run's .data file")
    mercury.add_argument("--fstat", help="the run's .fstat file (default: beside the .data, same name)")
    mercury.add_argument("--restart", help="the run's .restart file (default: beside the .data, same name)")
    mercury.add_argument("--units", required=True, help="si (the run is in m, kg, s), or length=L,mass=M,time=T: the "
                         "SI value of one length, mass and time unit of the run (m, kg, s)")
    mercury.add_argument("--out", required=True, help="the netCDF file to write")
    mercury.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    mercury.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    _no_compress_option(mercury)
    mercury.set_defaults(func=_convert_mercurydpm)
    pegs = formats.add_parser("pegs", help="a photoelastic experiment solved by PeGS2 (adjacency list + positions)",
                              description="A photoelastic experiment solved by PeGS2: its adjacency lists (rows "
                              "frame, id1, id2, tangential force, normal force; id2 -1 a wall) and the disks "
                              "(particle_positions.txt of particleTrack, or the *_centers.txt of particleDetect), in "
                              "pixels. The scale and the force unit are required (docs/formats.md).")
    pegs.add_argument("adjacency", nargs="+", help="Adjacency_list.txt, or the frames' *_Adjacency.txt")
    pegs.add_argument("--positions", nargs="+", required=True,
                      help="particle_positions.txt, or the frames' *_centers.txt")
    pegs.add_argument("--metres-per-pixel", type=float, required=True, help="the image scale, m per pixel "
                      "(PeGS2's metersperpixel)")
    pegs.add_argument("--force-unit-n", type=float, required=True, help="newtons per force unit of the adjacency "
                      "list (1 when PeGS2's fsigma is calibrated in N)")
    for flag, parameter, text in (("--frame-interval", "frame_interval_s", "time between frames, s (default: {:g})"),
                                  ("--thickness", "thickness_m", "the disks' thickness, m (default: {:g}; stresses "
                                   "are per this thickness)"),
                                  ("--density", "density_kg_m3", "the disks' density for their masses, kg/m^3 (not "
                                   "measured; default: {:g})")):
        default = library_default("grainview.formats.pegs", "convert_pegs", parameter)
        pegs.add_argument(flag, type=float, default=default, help=text.format(default))
    pegs.add_argument("--out", required=True, help="the netCDF file to write")
    pegs.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    pegs.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    _no_compress_option(pegs)
    pegs.set_defaults(func=_convert_pegs)
    for engine, version in (("box2d", "Box2D 2.3"), ("pymunk", "pymunk")):
        peer = formats.add_parser(engine, help=f"a {version} run of the cross-check (raw snapshots)",
                                  description=f"A {version} run of the cross-check harness (benchmarks/crosscheck/): "
                                  "the engine's folder of raw snapshots (snap_*.npz, meta.json) and the sample it "
                                  "started from (docs/formats.md).")
        peer.add_argument("raw", help="the engine's folder of raw snapshots")
        peer.add_argument("--sample", required=True, help="the cross-check sample's .npz the engine started from")
        peer.add_argument("--out", required=True, help="the netCDF file to write")
        peer.add_argument("--overwrite", action="store_true", help="replace an existing --out")
        _no_compress_option(peer)
        peer.set_defaults(func=_convert_peer)


def build_parser() -> argparse.ArgumentParser:
    """The command line: one subcommand per ``_<name>_parser``; the simulation's options are
    derived from the settings records (:func:`setting_option`)."""
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
    for add in (_study_parser, _run_parser, _report_parser, _ensemble_parser, _info_parser, _export_parser,
                _demo_parser, _warmup_parser, _convert_parser):
        add(sub)
    return parser


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
    parser = build_parser()
    args = parser.parse_args(_negative_values_attached(sys.argv[1:] if argv is None else list(argv)))
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
        from solver.interrupt import Terminated  # the command line runs the solver; this is stdlib only

        if not isinstance(exc, Terminated):
            raise
        print("grainview: terminated (SIGTERM)", file=sys.stderr)  # a batch scheduler's limit, after a whole step
        return 143


if __name__ == "__main__":
    sys.exit(main())
