"""Sample preparation as documented options: how a packing is made before it is tested.

The paper (Sec. II.B) builds "a dense packing ... following simple geometrical rules" and
compacts it isotropically under sigma0 = 10 kPa on the right and top walls, zero gravity,
friction 0.4 between grains and 0 with the walls, to solid fractions 0.80 (pentagons, S1) and
0.82 (disks, S2) with z = 3.20 and 3.95. It does not say how fast the walls closed, nor with
which friction the grains were compacted. Those choices set the initial state (not the
residual one), so they are options here, each recorded in the output file's attributes
(``preparation_*``):

* ``particles``, ``shape``, ``seed``: the sample (the paper's size mix, see
  :mod:`solver.packing`; shapes: regular ones, random convex polygons or a file of them,
  :mod:`solver.shape_families`);
* ``aspect``: h/l of the deposit's box (paper: about 2);
* ``sigma0``: the confining stress (Pa);
* ``friction``: grain-grain friction of the TEST; ``compaction_friction``: during compaction
  (None: the same). Compacting frictionless and switching friction on for the test is the
  usual way to a dense sample (``compaction_friction=0``);
* ``max_wall_speed`` (m s-1) and ``max_inertia_number``: caps on the closing speed of the
  pushed walls. The second makes compaction quasi-static in the sense of GDR MiDi (2004):
  I = eps_dot d sqrt(rho / sigma0) stays below the cap
  (:func:`solver.scenes.inertia_number_speed`);
* ``pressure_ramp`` (s): sigma0 raised linearly from 0 over that time.

:data:`PRESETS` names the preparations documented in docs/fidelity.md.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from grainview.contract.errors import ParameterError
from grainview.contract.schema import MAX_STEP_INDEX

from .parameters import FRICTION_EXPECTED, Parameters, coulomb, default_of, positive, problems, refusal, setting
from .shape_families import check_shape

MAX_SEED = 2**31 - 1
"""Largest seed: files store the seed as a 32-bit integer attribute (netCDF-3 has no wider one)."""
MIN_TEST_STEPS = 10
"""Fewest time steps a biaxial test may take to reach its strain (a test of fewer is no test)."""


def _integer(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


@dataclass(frozen=True)
class Preparation:
    """How a sample is prepared (see the module docstring); every default is the paper's or,
    where the paper is silent, this project's historical default. Each field's help, unit and
    check are its :func:`solver.parameters.setting`; :meth:`validate` is the one validator."""

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
        (:func:`solver.shape_families.check_shape`); one :class:`ParameterError` naming every
        bad value."""
        bad = [refusal(*p) for p in problems(self)]
        try:
            check_shape(self.shape)
        except ParameterError as exc:
            bad.append(str(exc))
        if bad:
            raise ParameterError("invalid preparation: " + "; ".join(bad))
        return self

    def check_time_step(self, time_step, test_velocity=None):
        """Refuse, before any work, a time step in which the closing walls of the compaction
        (at most ``max_wall_speed``) or the top wall of the test (``test_velocity``, m s-1)
        travel farther than the smallest particle radius of the paper's size mix
        (:func:`solver.stepper.check_time_step`)."""
        from .packing import PAPER_DIAMETERS
        from .parameters import check_time_step

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
            return float(self.deposit_height() * np.expm1(strain) / (float(velocity) * float(time_step)))

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
        velocity = float(velocity)
        if not (np.isfinite(velocity) and velocity > 0):
            raise ParameterError(f"velocity={velocity:g}: expected a finite wall speed > 0 in m/s")
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


BY_SHAPE = {"s1s2": {"pentagon": "paper", "disk": "frictionless"}}
"""Presets that differ by shape: ``s1s2`` gives each shape the preparation that reproduces the
paper's initial state of its sample (S1 pentagons: compaction friction 0.4; S2 disks: 0;
docs/fidelity.md, section 2)."""


def preset_name(prep: Preparation) -> str:
    """The first preset ``prep`` is (whatever its particles, shape and seed), or "custom"."""
    def core(p):
        return {k: v for k, v in asdict(p).items() if k not in ("particles", "shape", "seed")}
    return next((name for name, preset in PRESETS.items() if core(preset) == core(prep)), "custom")


def record(sim) -> dict:
    """File attributes of how ``sim`` was prepared: its history's
    (:meth:`solver.sample_history.SampleHistory.attrs`: the :class:`Preparation` as
    ``preparation_*`` with ``preparation_name``, and the compaction's outcome as
    ``compaction_*``); {} for a simulation that :func:`prepare_sample` did not make."""
    return sim.history.attrs()


def preset_names():
    """Every name :func:`preparation` accepts."""
    return sorted(PRESETS) + sorted(BY_SHAPE)


def preparation(name_or_prep=DEFAULT_PRESET, **changes) -> Preparation:
    """A :class:`Preparation` from a preset name (or an instance) with ``changes`` applied.
    A preset of :data:`BY_SHAPE` needs ``shape`` among the changes."""
    if isinstance(name_or_prep, Preparation):
        prep = name_or_prep
    elif name_or_prep in PRESETS:
        prep = PRESETS[name_or_prep]
    elif name_or_prep in BY_SHAPE:
        shape = changes.get("shape")
        key = {"disks": "disk", "pentagons": "pentagon"}.get(shape, shape)
        if key not in BY_SHAPE[name_or_prep]:
            raise ParameterError(f"preparation={name_or_prep!r} is defined for the shapes "
                                 f"{sorted(BY_SHAPE[name_or_prep])}, not for shape={shape!r}")
        prep = PRESETS[BY_SHAPE[name_or_prep][key]]
    else:
        raise ParameterError(f"preparation={name_or_prep!r}: expected one of {preset_names()} or a Preparation")
    return replace(prep, **{k: v for k, v in changes.items() if v is not None}).validate()


def prepare_sample(prep: Preparation, progress=None, **parameters):
    """Deposit and compact a sample as ``prep`` says; returns the compacted :class:`Simulation`
    with the test's friction set, and the sample's history in ``sim.history``
    (:class:`solver.sample_history.SampleHistory`: the preparation, whether the compaction
    settled, its wall stresses, largest inertia number, steps and unconverged steps).
    ``parameters`` go to :class:`solver.Parameters` (time step, tolerances...); the grains'
    friction is the preparation's (``prep.friction``, ``prep.compaction_friction``), not one of
    them."""
    prep = prep.validate()
    if "friction" in parameters:
        raise ParameterError(f"friction={parameters['friction']!r} among the solver parameters: the grains' "
                             "friction is the preparation's; expected Preparation(friction=..., "
                             "compaction_friction=...)")
    compaction_friction = prep.friction if prep.compaction_friction is None else prep.compaction_friction
    from .scenes import compaction_sample, isotropic_compaction  # the solver proper, on first use

    sim = compaction_sample(prep.particles, prep.shape, sigma0=prep.sigma0, friction=compaction_friction,
                            seed=prep.seed, aspect=prep.aspect, max_wall_speed=prep.max_wall_speed, **parameters)
    from .parameters import check_time_step

    check_time_step(sim.parameters.time_step, prep.max_wall_speed, float(sim.radius.min()),
                    "a closing wall of the compaction")
    steps = isotropic_compaction(sim, max_steps=prep.max_steps, max_inertia_number=prep.max_inertia_number,
                                 pressure_ramp=prep.pressure_ramp, progress=progress)
    sim.history.compaction_steps = steps
    sim.history.compaction_unconverged = sim.take_unconverged()
    sim.set_parameters(friction=prep.friction)
    sim.history.preparation = prep
    return sim
