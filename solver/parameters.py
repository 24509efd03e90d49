"""Every physical and numerical setting of a simulation, in one place: the records, their
defaults, units, help texts and validators.

* :class:`Parameters`: the time stepper's settings (time step, friction, density, the contact
  solver's tolerances and caps...); defaults are the paper's (Azema et al. 2007, Sec. II.B);
* :class:`BiaxialTest`: the biaxial test of a prepared sample (strain, top wall speed,
  snapshots);
* :class:`Preparation`: how a sample is made, and :data:`PRESETS`, the named ones
  (:mod:`solver.preparation` says what each setting means and prepares samples).

Each field is declared with :func:`setting`: its default, a one-line help, its unit, and the
check of its value with what is expected of it. The records validate themselves from these
declarations (:func:`problems`, then the checks that relate several fields), and the command
line (:mod:`grainview.app.cli`) derives its options, defaults and help from them
(:func:`dataclasses.fields`), so that a setting is declared, defaulted and checked once.

This module imports numpy, the contract's errors and the solver registry
(:mod:`solver.contact_solvers`, which loads no kernel before a solve) only: the command line
reads it to build its options without loading a numba kernel.
"""

from __future__ import annotations

import functools
import inspect
from dataclasses import MISSING, asdict, dataclass, field, fields

import numpy as np

from grainview.contract import portable_math
from grainview.contract.errors import ParameterError
from grainview.contract.schema import MAX_STEP_INDEX

from . import contact_solvers
from .contact_solvers import ACCELERATIONS  # noqa: F401 (the former acceleration's values, read from the registry)
from .shape_families import check_shape
from .solve_records import STALL_IMPROVEMENT

MAX_FRICTION = 10.0
"""Largest accepted friction coefficient: measured ones lie below ~1.5, and 10 already makes
every contact stick; a larger number is a typing mistake (1e9 for 1e-9?)."""

FRICTION_EXPECTED = f"in [0, {MAX_FRICTION:g}] (a Coulomb coefficient)"
"""What a friction coefficient is expected to be, in every refusal of one."""


def setting(default, help, *, unit="", check=None, expected="", choices=None, optional=False):
    """A field of a settings record with what the validators and the command line need.

    Parameters
    ----------
    default
        The field's default value (a hashable constant).
    help : str
        One line saying what the setting is (the command line's help, without the default).
    unit : str
        The unit of the value (SI), "" for a number without one.
    check : callable, optional
        ``check(value) -> bool``: whether a value is acceptable on its own (relations between
        fields are the record's ``validate``'s).
    expected : str
        What an acceptable value is, for the refusal ``name=value: expected ...``.
    choices : callable, optional
        ``choices() -> tuple``: the accepted names of a setting that is one of a list.
    optional : bool
        None is accepted (it means the default the help describes).
    """
    return field(default=default, metadata={"help": help, "unit": unit, "check": check, "expected": expected,
                                            "choices": choices, "optional": optional})


def problems(record) -> list[tuple[str, object, str]]:
    """The fields of ``record`` whose value fails its own :func:`setting` check, as
    ``(name, value, expected)``, in the order of the fields."""
    out = []
    for f in fields(record):
        value, meta = getattr(record, f.name), f.metadata
        if meta.get("optional") and value is None:
            continue
        choices = meta.get("choices")
        if choices is not None:
            ok = value in choices()
            expected = meta.get("expected") or f"one of {choices()}"
        else:
            check = meta.get("check")
            try:
                ok = check is None or bool(check(value))
            except (TypeError, ValueError):  # a value of the wrong kind (a string for a number...)
                ok = False
            expected = meta.get("expected", "")
        if not ok:
            out.append((f.name, value, expected))
    return out


def check_values(record_type, **values):
    """Refuse, in one :class:`ParameterError` line, the ``values`` of fields of the dataclass
    ``record_type`` that fail their own checks (:func:`setting`): for functions that take some
    of a record's settings as arguments."""
    bad = problems(record_type(**values))
    if bad:
        raise ParameterError("; ".join(refusal(*p) for p in bad))


def refusal(name, value, expected) -> str:
    """The library's words for a refused value: ``name=value: expected ...``."""
    return f"{name}={value!r}: expected {expected}"


def default_of(record_type, name):
    """The default of field ``name`` of the dataclass ``record_type``."""
    f = next(f for f in fields(record_type) if f.name == name)
    return f.default if f.default is not MISSING else f.default_factory()


# -- the checks of single values -----------------------------------------------------------------
def whole(value) -> bool:
    """Whether ``value`` is a whole number (an int, a numpy integer or a float without a
    fraction; not a bool)."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer, float, np.floating)) \
        and np.isfinite(value) and int(value) == value


def positive(value) -> bool:
    """A finite number > 0."""
    return bool(np.isfinite(value) and value > 0)


def coulomb(value) -> bool:
    """A Coulomb friction coefficient in [0, :data:`MAX_FRICTION`]."""
    return bool(np.isfinite(value) and 0 <= value <= MAX_FRICTION)


def check_time_step(time_step, speed, smallest_radius, what="a wall"):
    """Refuse a time step in which a body driven at ``speed`` (m s-1) moves farther than the
    smallest particle radius ``smallest_radius`` (m): the contacts it meets during a step would
    be found deep inside the particles, or missed. This is the bound at which the stepper's
    detection distance is capped (:meth:`solver.stepper.Simulation.alert_for_step`), checked
    once before any work instead of warned at every step. Raises :class:`ParameterError` naming
    the largest time step allowed."""
    speed = float(speed)
    if not np.isfinite(speed) or speed <= 0:
        return
    travel = speed * float(time_step)
    if travel > smallest_radius:
        raise ParameterError(
            f"time_step={time_step:g} s: {what} moving at {speed:g} m s-1 travels {travel:.3g} m per step, more "
            f"than the smallest particle radius {smallest_radius:.3g} m, so contacts would be missed; expected "
            f"time_step <= {smallest_radius / speed:.3g} s (the paper's is 5e-4 s)")


@dataclass
class Parameters:
    """Numerical and physical parameters of the time stepper (:mod:`solver.stepper`);
    defaults are the paper's (Sec. II.B). Each field's help, unit and check are its
    :func:`setting`; :meth:`validate` is the one validator."""

    time_step: float = setting(5e-4, "time step", unit="s", check=positive, expected="a positive number of seconds")
    theta: float = setting(0.5, "theta of the Moreau-Jean scheme", check=lambda v: 0.5 <= v <= 1,
                           expected="in [0.5, 1]")
    friction: float = setting(0.4, "grain-grain friction coefficient", check=coulomb, expected=FRICTION_EXPECTED)
    wall_friction: float = setting(0.0, "grain-wall friction coefficient", check=coulomb, expected=FRICTION_EXPECTED)
    gravity: tuple = setting((0.0, 0.0), "gravity vector", unit="m s-2",
                             check=lambda v: len(v) == 2 and bool(np.all(np.isfinite(v))),
                             expected="a finite 2-vector in m s-2")
    density: float = setting(2600.0, "density of the grains (not given in the paper; glass-like grains assumed)",
                             unit="kg m-3", check=positive, expected="> 0 kg m-3")
    thickness: float = setting(1.0, "slab thickness of the 2D sample", unit="m", check=positive, expected="> 0 m")
    tolerance: float = setting(1.7e-4, "NLGS tolerance, quadratic norm of the velocity changes over a sweep "
                               "(docs/solver.md)", check=positive, expected="> 0")
    max_tolerance: float = setting(1e-2, "NLGS max norm: largest single change over the RMS", check=positive,
                                   expected="> 0")
    max_iterations: int = setting(2000, "cap of the NLGS sweeps of a step", check=lambda v: whole(v) and v >= 1,
                                  expected=">= 1")
    stall_sweeps: int = setting(0, f"stop a step's NLGS when its quadratic norm has fallen less than "
                                f"{100 * STALL_IMPROVEMENT:g}% over this many sweeps (a step that would creep to the "
                                "sweep cap; 0: never; docs/solver.md)",
                                check=lambda v: whole(v) and v >= 0,
                                expected="a whole number of sweeps >= 0 (0: no stall test)")
    alert: float | None = setting(None, "alert distance (None: 2% of the smallest diameter)", unit="m",
                                  check=positive, expected="a positive length in m", optional=True)
    skin: float | None = setting(None, "broad-phase skin (None: 10% of the smallest diameter)", unit="m",
                                 check=positive, expected="a positive length in m", optional=True)
    shuffle: bool = setting(False, "random NLGS ordering (a solver that has one: 'nlgs')",
                            check=lambda v: isinstance(v, (bool, np.bool_)), expected="True or False")
    seed: int = setting(0, "seed of the random NLGS ordering", check=lambda v: whole(v) and 0 <= v <= MAX_SEED,
                        expected="a whole number in 0..2147483647")
    solver: str = setting(contact_solvers.default_method(), "the contact solver of each step, a method of the "
                          f"registry solver.contact_solvers (docs/solver.md): {contact_solvers.choices_help()}",
                          choices=contact_solvers.stepper_methods)
    anderson_memory: int = setting(3, "past iterates combined by the Anderson extrapolation",
                                   check=lambda v: whole(v) and 1 <= v <= 50, expected="an integer in 1..50")
    anderson_period: int = setting(1, "NLGS sweeps between two Anderson extrapolations",
                                   check=lambda v: whole(v) and 1 <= v <= 50, expected="an integer in 1..50")
    domains: int = setting(1, "NLGS domains swept at once, one per core, and as many blocks of the narrow phase "
                           "(1: the serial sweep; deterministic for a given number; combines with either --solver; "
                           "on free cores only; docs/solver.md)",
                           check=lambda v: isinstance(v, (int, np.integer)) and not isinstance(v, bool)
                           and 1 <= v <= 64, expected="an integer in 1..64")
    overlap_recovery_speed: float = setting(1e-3, "cap of the split-impulse separation of overlaps", unit="m s-1",
                                            check=lambda v: v >= 0, expected=">= 0 m s-1")
    overlap_recovery_rate: float = setting(0.2, "fraction of an overlap removed per step, below the cap",
                                           check=lambda v: 0 <= v <= 1, expected="in [0, 1]")
    overlap_recovery_threshold: float = setting(1e-4, "fraction of the smallest diameter: smaller overlaps are left",
                                                check=lambda v: bool(np.isfinite(v) and v >= 0), expected=">= 0")
    overlap_recovery_tolerance: float = setting(1e-2, "NLGS tolerance of the recovery pass (a correction, not "
                                                "physics)", check=positive, expected="> 0")
    overlap_recovery_iterations: int = setting(50, "sweep cap of the recovery pass",
                                               check=lambda v: whole(v) and v >= 1, expected="a whole number >= 1")

    def __setstate__(self, state):
        """Unpickle, also a record pickled before ``solver`` existed (its ``acceleration``)."""
        if "solver" not in state and "acceleration" in state:
            state = dict(state)
            state["solver"] = contact_solvers.from_acceleration(state.pop("acceleration"))
        self.__dict__.update(state)

    def validate(self):
        """The parameters themselves, checked: each field's own check (:func:`setting`), then
        the relations between fields; one :class:`ParameterError` naming every bad value."""
        bad = [refusal(*p) for p in problems(self)]
        relations = [
            ("stall_sweeps", not whole(self.stall_sweeps) or not whole(self.max_iterations)
             or 2 * int(self.stall_sweeps) <= int(self.max_iterations),
             f"at most max_iterations/2 = {_half(self.max_iterations)} (the first check only records the best "
             "norm, so a stall can show at the second; 0: no stall test)"),
        ]
        bad += [refusal(name, getattr(self, name), expected) for name, ok, expected in relations if not ok]
        if self.solver in contact_solvers.stepper_methods():  # what the solver cannot run with
            bad += contact_solvers.method(self.solver).problems(self)
        if bad:
            raise ParameterError("invalid solver parameters: " + "; ".join(bad))
        from .parallel_nlgs import warn_if_threads_sleep

        warn_if_threads_sleep(self.domains)
        return self


def _acceleration(self):
    return contact_solvers.acceleration_of(self.solver)


def _set_acceleration(self, value):
    self.solver = contact_solvers.from_acceleration(value)


def _accepting_acceleration(init):
    """The dataclass's ``__init__`` with the keyword ``acceleration``, the former name of
    ``solver`` (files, scripts and command lines from before it): ``'off'`` is
    ``solver='nlgs'``, ``'anderson'`` ``solver='anderson'``
    (:data:`solver.contact_solvers.ACCELERATIONS`); given, it sets ``solver``. It is not a field
    (a file records ``solver``; :func:`dataclasses.replace` keeps the record's solver)."""
    @functools.wraps(init)
    def __init__(self, *args, acceleration=None, **kwargs):
        init(self, *args, **kwargs)
        if acceleration is not None:
            self.solver = contact_solvers.from_acceleration(acceleration)

    signature = inspect.signature(init)
    __init__.__signature__ = signature.replace(parameters=[
        *signature.parameters.values(), inspect.Parameter("acceleration", inspect.Parameter.KEYWORD_ONLY, default=None)])
    return __init__


Parameters.__init__ = _accepting_acceleration(Parameters.__init__)
Parameters.acceleration = property(_acceleration, _set_acceleration, doc="The former name of ``solver``: ``'off'`` "
                                   "for 'nlgs', ``'anderson'`` for 'anderson' (None for another solver); set, it sets "
                                   "``solver`` (:data:`solver.contact_solvers.ACCELERATIONS`).")


def _half(value):
    return int(value) // 2 if whole(value) else "?"


SHEAR_STRAIN = 0.5
"""The final shear gamma of the periodic shear scene by default (:mod:`solver.periodic_shear`;
the biaxial test's strain, :class:`BiaxialTest`, is an eps_1)."""


MIN_WALL_MASS = 1e-6
"""The lightest right wall of a biaxial test, in units of the sample's mass: lighter than any
grain of a sample of fewer than a million, and far from where its inverse mass overflows."""


@dataclass(frozen=True)
class BiaxialTest:
    """The biaxial test of a prepared sample (:func:`solver.scenes.biaxial_test`): the top wall
    moves down at ``velocity`` until the vertical strain eps_1 = ln(1 + dh/h0) reaches
    ``strain``, with a snapshot every ``every`` steps; the right wall, pushed by sigma0, has
    ``wall_mass`` times the sample's mass (None: the mass the compaction gave it)."""

    strain: float = setting(0.2, "vertical strain eps_1 of the biaxial test (eps_q ~0.6, into the residual state)",
                            check=lambda v: 0 < v < 1, expected="a vertical strain eps_1 in (0, 1)")
    velocity: float = setting(0.01, "speed of the top wall (the paper's)", unit="m/s", check=positive,
                              expected="a finite wall speed > 0 in m/s")
    every: int = setting(200, "steps between snapshots", check=lambda v: whole(v) and v >= 1,
                         expected="a positive whole number of steps between snapshots")
    wall_mass: float | None = setting(None, "mass of the stress-controlled right wall, in units of the sample's mass "
                                      "(none: the compaction's wall, of the whole sample's mass)",
                                      check=lambda v: positive(v) and v >= MIN_WALL_MASS,
                                      expected=f"a finite multiple >= {MIN_WALL_MASS:g} of the sample's mass, or none",
                                      optional=True)

    def validate(self):
        """The test itself, checked: one :class:`ParameterError` naming every bad value."""
        bad = problems(self)
        if bad:
            raise ParameterError("; ".join(refusal(*p) for p in bad))
        return self


MAX_SEED = 2**31 - 1
"""Largest seed: files store the seed as a 32-bit integer attribute (netCDF-3 has no wider one)."""
MIN_TEST_STEPS = 10
"""Fewest time steps a biaxial test may take to reach its strain (a test of fewer is no test)."""


def _integer(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


@dataclass(frozen=True)
class Preparation:
    """How a sample is prepared (see the module docstring); every default is the paper's or,
    where the paper is silent, this project's historical default (:mod:`solver.preparation`
    says what each means, names presets and prepares samples). Each field's help, unit and check
    are its :func:`setting`; :meth:`validate` is the one validator."""

    particles: int = setting(400, "particles per sample", check=lambda v: _integer(v) and v >= 2,
                             expected="an integer >= 2")
    shape: str | int = setting("pentagon", "a name of solver.shapes.SHAPES, a number of vertices, a family or "
                               "a file (solver.shape_families.check_shape)")
    seed: int = setting(0, "random seed of the deposit", check=lambda v: _integer(v) and 0 <= v <= MAX_SEED,
                        expected=f"an integer in 0 .. {MAX_SEED} (files store it as a 32-bit integer)")
    aspect: float = setting(2.0, "h/l of the sample box", check=lambda v: np.isfinite(v) and 0.2 <= v <= 20,
                            expected="h/l in [0.2, 20]")
    sigma0: float = setting(1e4, "confining stress", unit="Pa", check=positive, expected="a positive stress in Pa")
    friction: float = setting(default_of(Parameters, "friction"), "grain-grain friction coefficient of the test",
                              check=coulomb, expected=FRICTION_EXPECTED)
    compaction_friction: float | None = setting(None, "grain friction during compaction (None: the test's)",
                                                check=coulomb, expected=FRICTION_EXPECTED + " or None",
                                                optional=True)
    max_wall_speed: float = setting(0.05, "cap of the closing speed of the pushed walls", unit="m s-1",
                                    check=lambda v: v > 0, expected="a positive speed in m s-1 (inf: no cap)")
    max_inertia_number: float | None = setting(None, "cap of the inertia number I = (v/L) d sqrt(rho/sigma0) of "
                                               "the closing walls (None: the walls close at up to max_wall_speed)",
                                               check=positive, expected="a positive number or None", optional=True)
    pressure_ramp: float = setting(0.0, "time over which sigma0 rises from 0 (0: applied at once)", unit="s",
                                   check=lambda v: np.isfinite(v) and v >= 0, expected="a duration >= 0 in s")
    max_steps: int = setting(40000, "compaction step limit", check=lambda v: _integer(v) and v >= 1,
                             expected="an integer >= 1")

    def validate(self):
        """The preparation itself, checked: each field's own check, then the shape
        (:func:`solver.shape_families.check_shape`) and whether the deposit's box is wide enough
        for its largest particle (:meth:`box_problem`); one :class:`ParameterError` naming every
        bad value."""
        bad = [refusal(*p) for p in problems(self)]
        try:
            check_shape(self.shape)
        except ParameterError as exc:
            bad.append(str(exc))
        if not bad and self.box_problem():
            bad.append(self.box_problem())
        if bad:
            raise ParameterError("invalid preparation: " + "; ".join(bad))
        return self

    def box_problem(self) -> str:
        """What is wrong with the deposit's box, in words, or "": its width,
        :func:`solver.packing.box_width_for` at this ``aspect``, must hold the largest particle
        of the size mix that ``particles`` draws (too few particles, or too tall a box, and the
        deposit could not place it)."""
        from .packing import PAPER_DIAMETERS, PAPER_FRACTIONS, box_width_for, size_classes

        width = box_width_for(self.particles, aspect_ratio=self.aspect)
        counts = size_classes(self.particles, PAPER_DIAMETERS, PAPER_FRACTIONS)
        largest = float(np.asarray(PAPER_DIAMETERS)[counts > 0].max())
        if width >= largest:
            return ""
        return (f"particles={self.particles}, aspect={self.aspect:g}: the deposit's box would be {width:.3g} m wide, "
                f"narrower than its largest particle ({largest:.3g} m); expected more particles or a smaller aspect")

    def check_time_step(self, time_step, test_velocity=None):
        """Refuse, before any work, a time step in which the closing walls of the compaction
        (at most ``max_wall_speed``) or the top wall of the test (``test_velocity``, m s-1)
        travel farther than the smallest particle radius of the paper's size mix
        (:func:`check_time_step`)."""
        from .packing import PAPER_DIAMETERS

        smallest = 0.5 * min(PAPER_DIAMETERS)
        check_time_step(time_step, self.max_wall_speed, smallest, "a closing wall of the compaction")
        if test_velocity is not None:
            check_time_step(time_step, test_velocity, smallest, "the top wall of the test")
        return self

    def test_steps(self, time_step, velocity, strain) -> float:
        """About how many time steps the biaxial test takes to reach ``strain``: the top wall,
        at ``velocity`` (m s-1), travels h (e^strain - 1) at ``time_step`` (s) per step, where
        h is the deposit's height, aspect x :func:`solver.packing.box_width_for` (m): the
        compacted sample is lower, so its test takes somewhat fewer steps."""
        with np.errstate(over="ignore", divide="ignore"):
            return float(self.deposit_height() * portable_math.expm1(float(strain)) / (float(velocity) * float(time_step)))

    def deposit_height(self) -> float:
        """The deposit's height in m: aspect x :func:`solver.packing.box_width_for`."""
        from .packing import box_width_for

        return self.aspect * box_width_for(self.particles, aspect_ratio=self.aspect)

    def check_test_speed(self, time_step, velocity, strain):
        """Refuse, before any work, a top-wall speed of the biaxial test that is not finite and
        positive, with which the test would reach ``strain`` in fewer than
        :data:`MIN_TEST_STEPS` steps, or would take more steps than a file's step counter
        holds (:data:`MAX_STEP_INDEX`, less the compaction's :attr:`max_steps`); the count is
        :meth:`test_steps`. Raises :class:`ParameterError` naming the speeds allowed (m s-1)."""
        check_values(BiaxialTest, velocity=velocity)  # the field's own check, then what this sample adds
        velocity = float(velocity)
        steps = self.test_steps(time_step, velocity, strain)
        at_unit_speed = self.test_steps(time_step, 1.0, strain)  # steps x velocity
        most = MAX_STEP_INDEX - self.max_steps
        if steps < MIN_TEST_STEPS:
            raise ParameterError(
                f"velocity={velocity:g}: the test would reach eps_1 = {strain:g} in about {steps:.2g} steps of "
                f"{time_step:g} s ({self.particles} particles deposited about {self.deposit_height():.2g} m high); "
                f"expected at most {at_unit_speed / MIN_TEST_STEPS:.3g} m/s, for at least "
                f"{MIN_TEST_STEPS} steps")
        if steps > most:
            raise ParameterError(
                f"velocity={velocity:g}: the test would take about {steps:.3g} steps of {time_step:g} s to reach "
                f"eps_1 = {strain:g}, more than a file's 32-bit step counter leaves for the test ({most} after the "
                f"compaction's {self.max_steps}); expected at least {at_unit_speed / most:.3g} m/s")
        return self

    def attrs(self) -> dict:
        """The preparation as file attributes ``preparation_<name>`` ("none" for None), and
        ``preparation_name``, the preset it is (:func:`preset_name`)."""
        return {**{f"preparation_{k}": ("none" if v is None else v) for k, v in asdict(self).items()},
                "preparation_name": preset_name(self)}


DEFAULT_PRESET = "paper"
"""The preparation used when none is named."""

PRESETS = {
    DEFAULT_PRESET: Preparation(),
    "frictionless": Preparation(compaction_friction=0.0),
    "quasistatic": Preparation(max_inertia_number=2e-4, max_steps=200000),
    "fast": Preparation(max_wall_speed=0.2),
}
"""Named preparations (docs/fidelity.md): ``paper`` compacts with the test's friction 0.4
and walls closing at up to 5 cm/s (this project's default); ``frictionless`` compacts with
friction 0 (then 0.4 for the test); ``quasistatic`` caps the closing walls at I = 2e-4
(about 6 mm/s for 400 particles, ten times slower than ``paper``); ``fast`` as ``paper`` with
the walls closing at up to 20 cm/s: half the NLGS sweeps of ``paper`` for the same solid
fraction and coordination within the scatter between seeds (docs/solver.md, "Compaction")."""


def preset_name(prep: Preparation) -> str:
    """The first preset ``prep`` is (whatever its particles, shape and seed), or "custom"."""
    def core(p):
        return {k: v for k, v in asdict(p).items() if k not in ("particles", "shape", "seed")}
    return next((name for name, preset in PRESETS.items() if core(preset) == core(prep)), "custom")
