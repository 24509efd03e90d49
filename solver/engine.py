"""Simulation engines behind one interface: what the command line's ``run``, ``study`` and
``ensemble`` (and :mod:`grainview.app.ensemble`) ask of the code that simulates.

An engine makes a sample as a :class:`solver.preparation.Preparation` says (``prepare``),
shears it in the biaxial test a :class:`solver.parameters.BiaxialTest` describes into a file
of the grainview data contract (``shear``), and carries on an interrupted test from its file
(``resume``); ``check`` refuses bad settings before any work, ``write_state`` writes a
prepared sample as it is, ``file_state`` says how far the test in a file got. The settings
are the records of :mod:`solver.parameters` and :mod:`solver.preparation`, whatever the
engine; numerical settings of an engine's own go in ``parameters``, a dict of
:class:`solver.parameters.Parameters` fields.

:data:`ENGINES` names the engines (``"module:attribute"`` of a class whose instances follow
:class:`Engine`); packages add theirs through the entry-point group ``grainview.engines``
(``name = "package.module:Class"``), so that a new engine needs no edit of the command line.
The one engine here is :class:`ContactDynamics`, this package's Moreau–Jean solver.

Each engine declares the scenes it runs (``scenes``: :data:`BASE_SCENES`, and ``"shear"``,
the periodic cell's simple shear, for one that has :meth:`ContactDynamics.simple_shear`); the
command line refuses a scene its engine does not declare (:func:`check_scene`).

This module is the application's one door to the solver: :mod:`grainview.app` imports
nothing else of ``solver`` (tests/grainview/test_engine_door.py). The settings' records and
constants it needs are re-exported here from their homes (:data:`RECORDS`, each loaded when
first asked for); what would load numba kernels is reached through functions that import it
when called.

Loading this module, or listing the engines, imports no numba kernel.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from grainview.contract.errors import ParameterError

from .interrupt import PROGRESS_LINE_SECONDS, Terminated, handling, sigterm_raises  # noqa: F401 (stdlib only)

if TYPE_CHECKING:  # for readers and type checkers: RECORDS, loaded when first asked for (:func:`__getattr__`)
    from .compaction_checkpoint import CHECKPOINT_SECONDS  # noqa: F401
    from .contact_solvers import ACCELERATIONS, from_acceleration, stop_rule  # noqa: F401
    from .contact_solvers import method as solver_method  # noqa: F401
    from .parameters import SHEAR_STRAIN, BiaxialTest, Parameters, default_of, problems  # noqa: F401
    from .preparation import (DEFAULT_PRESET, MIN_TEST_STEPS, Preparation, preparation, preset_name,  # noqa: F401
                              preset_names)
    from .shape_families import MAX_VERTICES, SHAPE_FILE_SUFFIX, check_shape, shape_label  # noqa: F401

RECORDS = {"compaction_checkpoint": ("CHECKPOINT_SECONDS",),
           "contact_solvers": ("ACCELERATIONS", "from_acceleration", "stop_rule", "method"),
           "parameters": ("SHEAR_STRAIN", "BiaxialTest", "Parameters", "default_of", "problems"),
           "preparation": ("DEFAULT_PRESET", "MIN_TEST_STEPS", "Preparation", "preparation", "preset_name",
                           "preset_names"),
           "shape_families": ("MAX_VERTICES", "SHAPE_FILE_SUFFIX", "check_shape", "shape_label")}
"""The settings' records and constants the application reads, re-exported from their homes
(module of ``solver`` -> names; ``contact_solvers.method`` as ``solver_method``)."""
_RENAMED = {"solver_method": "method"}


def __getattr__(name):
    """A name of :data:`RECORDS`, imported from its home when first asked for, so that loading
    this module costs no more than the interrupt handling's standard library."""
    home_name = _RENAMED.get(name, name)
    home = next((module for module, names in RECORDS.items() if home_name in names), None)
    if home is None or name in _RENAMED.values():
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__package__}.{home}"), home_name)
    globals()[name] = value
    return value


ENTRY_POINT_GROUP = "grainview.engines"
"""Entry-point group through which installed packages register engines."""

ENGINES = {"solver": "solver.engine:ContactDynamics"}
"""Engine name -> ``"module:attribute"`` of its class."""

DEFAULT_ENGINE = "solver"
"""The engine used when none is named."""

BASE_SCENES = ("isotropic", "biaxial")
"""The scenes every engine runs (``prepare`` then ``write_state``, or ``shear``): those of an
engine that declares no ``scenes``."""


@runtime_checkable
class Engine(Protocol):
    """What an engine does. A *sample* is the engine's own object for a prepared packing; the
    command line reads ``sample.history`` (:class:`solver.sample_history.SampleHistory`: how it
    was made, whether its compaction settled) and ``sample.parameters`` (the numerical
    settings it ran with, for the warning on unconverged steps).

    An engine that keeps compaction checkpoints (``prepare(..., checkpoint=)``) also has
    ``check_checkpoint(checkpoint, preparation, parameters)``, which refuses in one line a
    checkpoint file made with other settings (:func:`check_checkpoint`); one without them
    leaves both out.

    ``scenes`` names what the engine runs (default :data:`BASE_SCENES`); one that declares
    ``"shear"`` also has ``check_simple_shear(parameters)``, ``shear_rate(sample, velocity)``
    and ``simple_shear(sample, path, test, shear_rate, ...)``, as :class:`ContactDynamics`."""

    name: str

    def check(self, preparation, parameters: dict, test=None):
        """Refuse, before any work and in one :class:`ParameterError` line, settings with
        which the sample could not be made or tested (``test``: a
        :class:`solver.parameters.BiaxialTest`, or None for a preparation only)."""

    def prepare(self, preparation, parameters: dict, progress=None, checkpoint=None):
        """Deposit and compact the sample ``preparation`` describes; returns it. ``checkpoint``:
        a file where the compaction saves its state as it goes and from which it resumes (an
        engine without checkpoints may leave the argument out; the command line then starts
        its compaction afresh)."""

    def shear(self, sample, path, test, *, attrs=None, near_contacts=False, overwrite=False, progress=None,
              compress=True) -> int:
        """Shear ``sample`` in the biaxial ``test``, written to ``path``; returns the steps."""

    def write_state(self, sample, path, *, attrs=None, near_contacts=False, overwrite=False, compress=True):
        """Write ``sample`` as it is (one snapshot) to ``path``."""

    def resume(self, path, progress=None, compress=True) -> int:
        """Carry on the test written to ``path`` until its end; returns the steps taken."""

    def file_state(self, path) -> str:
        """How far the test in ``path`` got: "missing", "empty", "partial" or "finished"."""


class ContactDynamics:
    """This package's engine: Moreau–Jean contact dynamics of rigid disks and polygons
    (:mod:`solver.stepper`), the paper's preparation (:func:`solver.preparation.prepare_sample`)
    and biaxial test (:func:`solver.scenes.biaxial_test`), resumed by :mod:`solver.restart`."""

    name = "solver"
    summary = "this package's contact dynamics"
    """The engine in a few words (the ``--engine`` help and the docs' table of engines)."""
    scenes = (*BASE_SCENES, "shear")
    test_settings = ("wall_mass",)
    """The :class:`BiaxialTest` settings beyond the strain, speed and snapshots that it takes."""

    def check(self, preparation, parameters: dict, test=None):
        from .parameters import Parameters

        time_step = Parameters(**parameters).validate().time_step
        preparation.validate()
        if test is None:
            preparation.check_time_step(time_step)
            return
        test.validate()
        preparation.check_time_step(time_step, test.velocity)
        preparation.check_test_speed(time_step, test.velocity, test.strain)

    def prepare(self, preparation, parameters: dict, progress=None, checkpoint=None):
        from .preparation import prepare_sample

        return prepare_sample(preparation, progress=progress, checkpoint=checkpoint, **parameters)

    def check_checkpoint(self, checkpoint, preparation, parameters: dict):
        from .compaction_checkpoint import CompactionCheckpoint, describe

        CompactionCheckpoint(checkpoint, of=describe(preparation, parameters)).check()

    def shear(self, sample, path, test, *, attrs=None, near_contacts=False, overwrite=False, progress=None,
              compress=True) -> int:
        from .scenes import biaxial_test

        return biaxial_test(sample, path, strain=test.strain, velocity=test.velocity, every=int(test.every),
                            wall_mass=test.wall_mass, overwrite=overwrite, attrs=attrs, progress=progress,
                            near_contacts=near_contacts, compress=compress)

    def write_state(self, sample, path, *, attrs=None, near_contacts=False, overwrite=False, compress=True):
        from .output import Recorder

        with Recorder(path, sample, attrs={**sample.history.attrs(), **(attrs or {})}, overwrite=overwrite,
                      near_contacts=near_contacts, compress=compress) as rec:
            rec.write()

    def resume(self, path, progress=None, compress=True) -> int:
        from .restart import resume

        return resume(path, progress=progress, compress=compress)

    def file_state(self, path) -> str:
        from .restart import file_state

        return file_state(path)

    def check_simple_shear(self, parameters: dict):
        """Refuse, in one line, the settings the periodic cell's shear does not take
        (:func:`solver.contact_solvers.check_cell_coupling`)."""
        from .contact_solvers import check_cell_coupling
        from .parameters import Parameters

        check_cell_coupling(Parameters(**parameters))

    def shear_rate(self, sample, velocity: float) -> float:
        """The shear rate (s-1) of the biaxial test at wall speed ``velocity``
        (:func:`solver.periodic_shear.matching_shear_rate`)."""
        from .periodic_shear import matching_shear_rate

        return matching_shear_rate(sample, velocity)

    def simple_shear(self, sample, path, test, shear_rate, *, attrs=None, near_contacts=False, overwrite=False,
                     progress=None, compress=True) -> int:
        """Shear ``sample`` in the biperiodic cell of its box at ``shear_rate`` (s-1) to gamma =
        ``test.strain`` (:func:`solver.periodic_shear.shear_test`), written to ``path``."""
        from .periodic_shear import periodic_sample, shear_test

        return shear_test(periodic_sample(sample), path, strain=test.strain, shear_rate=shear_rate,
                          every=int(test.every), overwrite=overwrite, attrs=attrs, progress=progress,
                          near_contacts=near_contacts, compress=compress)

    def warm_up_stages(self, folder) -> list:
        """The solver's part of ``grainview warmup``'s workload, as (what it compiles, callable)
        pairs (:func:`solver.warm_up.stages`)."""
        from .warm_up import stages

        return stages(folder)


def check_checkpoint(runner, checkpoint, preparation, parameters: dict):
    """``runner.check_checkpoint`` where the engine keeps checkpoints (an engine of the
    entry-point group may not, and then starts its compactions afresh)."""
    check = getattr(runner, "check_checkpoint", None)
    if check is not None:
        check(checkpoint, preparation, parameters)


def prepare(runner, preparation, parameters: dict, progress=None, checkpoint=None):
    """``runner.prepare``, with the compaction's ``checkpoint`` when the engine takes one
    (an engine of the entry-point group may not)."""
    import inspect

    if checkpoint is not None and "checkpoint" in inspect.signature(runner.prepare).parameters:
        return runner.prepare(preparation, parameters, progress=progress, checkpoint=checkpoint)
    return runner.prepare(preparation, parameters, progress=progress)


def scenes_of(runner) -> tuple:
    """The scenes ``runner`` declares (:data:`BASE_SCENES` for one that declares none)."""
    return tuple(getattr(runner, "scenes", BASE_SCENES))


def check_test(name, test, scene: str = "biaxial"):
    """Refuse, in one :class:`ParameterError` line, a biaxial ``test`` whose right wall's mass
    (``test.wall_mass``) is set for another scene than ``scene="biaxial"``, or for the engine
    registered as ``name`` (None: the default) when it does not declare ``wall_mass`` among its
    ``test_settings``."""
    if test is None or test.wall_mass is None:
        return
    if scene != "biaxial":
        raise ParameterError(f"wall_mass={test.wall_mass:g}: the right wall's mass is the biaxial test's; scene "
                             f"{scene} has no such wall")
    if "wall_mass" not in getattr(engine(name or DEFAULT_ENGINE), "test_settings", ()):
        raise ParameterError(f"wall_mass={test.wall_mass:g}: the right wall's mass is set by this package's solver "
                             f"({DEFAULT_ENGINE}), not by engine {name}")


def check_scene(name, scene: str):
    """Refuse, in one :class:`ParameterError` line, ``scene`` for the engine registered as
    ``name`` (None: the default) when the engine does not declare it."""
    if scene not in scenes_of(engine(name or DEFAULT_ENGINE)):
        raise ParameterError(f"scene {scene}: the periodic cell is this package's solver's ({DEFAULT_ENGINE}), "
                             f"not engine {name}'s")


def file_state(path) -> str:
    """How far the test in ``path`` got (:func:`solver.restart.file_state`)."""
    from .restart import file_state

    return file_state(path)


def check_settings(path, expected: dict, *advice):
    """Refuse to go on with the file ``path`` written with other settings than ``expected``
    (:func:`solver.restart.check_settings`, with its ``advice``)."""
    from .restart import check_settings

    check_settings(path, expected, *advice)


def _registered() -> dict:
    """:data:`ENGINES` and the engines of the entry-point group, by name."""
    from importlib.metadata import entry_points

    found = dict(ENGINES)
    for point in entry_points(group=ENTRY_POINT_GROUP):
        found.setdefault(point.name, point.value)
    return found


def engine_names() -> list[str]:
    """Every engine's name, the default first."""
    names = sorted(_registered())
    return [DEFAULT_ENGINE] + [name for name in names if name != DEFAULT_ENGINE]


def engine_class(name: str = DEFAULT_ENGINE):
    """The class of the engine registered as ``name``; a :class:`ParameterError` naming the
    known ones otherwise."""
    target = _registered().get(name)
    if target is None:
        raise ParameterError(f"engine={name!r}: expected one of {', '.join(engine_names())}")
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


def engine_help() -> str:
    """``--engine``'s help text: the registry's default and its summary."""
    return (f"the simulation engine (solver.engine; default {DEFAULT_ENGINE}: "
            f"{engine_class(DEFAULT_ENGINE).summary})")


def engine(name: str = DEFAULT_ENGINE) -> Engine:
    """An instance of the engine registered as ``name``; a :class:`ParameterError` naming the
    known ones otherwise."""
    return engine_class(name)()
