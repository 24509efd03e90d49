"""The command line's settings: the options of the simulation's settings records
(:mod:`solver.parameters`, :mod:`solver.preparation`), each option's flag, type, choices,
default and help from its field (:func:`setting_option`), and the records the parsed
arguments ask for, each checked by its own validator before anything is simulated."""

from __future__ import annotations

import argparse

from ..contract.errors import GrainviewError

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


TEST_OPTIONS = ("strain", "velocity", "every", "wall_mass")
"""The :class:`solver.parameters.BiaxialTest` fields: the options of the biaxial test."""


def preparation_of(args, shape, particles=None):
    """The :class:`solver.preparation.Preparation` the command line asks for: the named preset
    with the preparation's settings given on the command line (:data:`PREPARATION_OPTIONS`);
    ``particles``: the sample's size (default ``--particles``)."""
    from solver.engine import preparation

    changes = {name: getattr(args, name) for name in PREPARATION_OPTIONS if name in given(args)}
    particles = args.particles if particles is None else particles
    return preparation(args.preparation, particles=particles, shape=shape, seed=args.seed, **changes)


def solver_parameters(args) -> dict:
    """The :class:`solver.Parameters` fields given on the command line (:data:`SOLVER_OPTIONS`;
    the others keep their defaults), validated."""
    from solver.engine import Parameters

    parameters = {name: getattr(args, name) for name in SOLVER_OPTIONS if name in given(args)}
    if getattr(args, "acceleration", None) is not None:  # the former name of --solver
        from solver.engine import from_acceleration

        if "solver" in parameters:
            raise GrainviewError("--acceleration and --solver name the same setting: expected one of them")
        parameters["solver"] = from_acceleration(args.acceleration)
    Parameters(**parameters).validate()  # one clear line before anything is simulated
    return parameters


def biaxial_test(args):
    """The :class:`solver.parameters.BiaxialTest` of the command line, checked by its own
    validator before anything is simulated; a bad value is named by its flag."""
    from solver.engine import BiaxialTest, problems

    test = BiaxialTest(**{name: getattr(args, name) for name in TEST_OPTIONS})
    for name, value, expected in problems(test)[:1]:
        shown = f"{value:g}" if isinstance(value, float) else value
        raise GrainviewError(f"{flag_of(name)} {shown}: expected {expected}")
    return test


def given(args) -> set:
    """The settings given on the command line (:class:`Given`)."""
    return getattr(args, "given", None) or set()


def flag_of(name) -> str:
    """The command-line flag of a setting: ``--`` and its name with dashes."""
    return "--" + name.replace("_", "-")


class Given(argparse.Action):
    """Stores an option's value and notes, in ``args.given``, that it was given: a named
    preparation's own values hold for the settings that were not."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        namespace.given = given(namespace) | {self.dest}


def setting_type(f):
    """The command-line type of a settings field: its annotation's first type (``str | int``:
    str, parsed further by the command); for ``float | None`` a float or the word ``none``
    (:func:`optional_float`)."""
    kinds = [kind.strip() for kind in str(f.type).split("|")]
    base = {"float": float, "int": int}.get(kinds[0], str)
    return optional_float if base is float and "None" in kinds else base


def optional_float(text: str) -> float | None:
    """A float of the command line, or None for ``none`` (the help's word for an unset setting)."""
    return None if str(text).strip().lower() == "none" else float(text)


optional_float.__name__ = "float"  # argparse says "invalid float value: 'x'"


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
    options = dict(dest=name, default=default, action=Given, help=text)
    options.update(dict(choices=choices) if choices is not None else dict(type=setting_type(f)))
    options.update(overrides)
    parser.add_argument(flag or flag_of(name), **options)


def shape_of(text, option=None):
    """A shape of the command line: a name of :data:`solver.shapes.SHAPES` (disk, pentagon...),
    a number of vertices from 3 to :data:`MAX_VERTICES` (as an integer), a family of random
    convex polygons (:data:`solver.shape_families.FAMILIES`: irregular) or a .json file of vertex
    lists (read and checked here, given on as an absolute path)."""
    import os

    from solver.engine import SHAPE_FILE_SUFFIX, check_shape

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


def progress_flag(args):
    return None if args.progress == "auto" else args.progress == "on"


def simulation_kwargs(args):
    return dict(test=biaxial_test(args), near_contacts=args.near_contacts, overwrite=args.overwrite,
                progress=progress_flag(args), parameters=solver_parameters(args), compress=not args.no_compress,
                engine=args.engine)


def shear_strain_default(args):
    """Scene shear: the test's strain is a shear gamma, SHEAR_STRAIN unless --strain is given
    (the biaxial test's default is an eps_1)."""
    if getattr(args, "scene", "biaxial") == "shear" and "strain" not in given(args):
        from solver.engine import SHEAR_STRAIN

        args.strain = SHEAR_STRAIN


def split_list(text, kind, name):
    """A comma-separated command-line list as values of ``kind``."""
    try:
        values = [kind(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise GrainviewError(f"--{name} {text}: expected a comma-separated list of {kind.__name__} values") from None
    if not values:
        raise GrainviewError(f"--{name} {text}: expected at least one value")
    return values


def no_compress_option(p):
    p.add_argument("--no-compress", action="store_true",
                   help="leave the finished netCDF files uncompressed (default: zlib, about half the size; "
                   "read the same either way)")


def residual_option(p):
    from ..analysis.arrays.strain import RESIDUAL_STRAIN as residual

    p.add_argument("--residual-strain", type=float, default=residual,
                   help=f"the residual state starts at this shear strain eps_q (default {residual}); "
                   "a run short of it reports 'not reached'")


def acceleration_option(p):
    """``--acceleration``, the former name of ``--solver`` (command lines written before it)."""
    from solver.engine import ACCELERATIONS

    p.add_argument("--acceleration", choices=tuple(ACCELERATIONS), default=None,
                   help="the former name of --solver: " + ", ".join(f"{old} is {new}" for old, new in
                                                                 ACCELERATIONS.items()) + " (default: --solver's)")


def engine_option(p):
    """``--engine``: the registry's engines (:mod:`solver.engine`), its default and its words."""
    from solver.engine import DEFAULT_ENGINE, engine_help, engine_names

    p.add_argument("--engine", choices=engine_names(), default=DEFAULT_ENGINE, help=engine_help())


def test_options(p):
    """The biaxial test's options, from :class:`solver.parameters.BiaxialTest`."""
    from solver.engine import MIN_TEST_STEPS, BiaxialTest

    setting_option(p, BiaxialTest, "strain")
    setting_option(p, BiaxialTest, "velocity", more=f": finite, > 0, and such that the test takes at least "
                   f"{MIN_TEST_STEPS} time steps and no more than a file's 32-bit step counter holds")
    setting_option(p, BiaxialTest, "every")
    setting_option(p, BiaxialTest, "wall_mass")


def simulation_options(p, samples=()):
    """The options of ``run`` and ``study``: the sample, the test, the solver's settings and
    the preparation, each from its record's field (:func:`setting_option`). ``samples``: the
    labels of the samples a command makes, when more than one (the study's ``--particles``
    takes one size or one per sample)."""
    from solver.engine import DEFAULT_PRESET, Parameters, Preparation, preset_names

    if len(samples) > 1:
        setting_option(p, Preparation, "particles", type=str, more=f"; or {len(samples)}, comma-separated, one "
                       f"per sample ({','.join(samples)}), e.g. 14400,10000")
    else:
        setting_option(p, Preparation, "particles")
    test_options(p)
    setting_option(p, Preparation, "seed")
    physics = p.add_argument_group("physics and numerics (defaults: the paper's)")
    for name in ("friction", "sigma0"):
        setting_option(physics, Preparation, name)
    for name in SOLVER_OPTIONS:
        setting_option(physics, Parameters, name)
    acceleration_option(physics)
    engine_option(physics)
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
    no_compress_option(p)
