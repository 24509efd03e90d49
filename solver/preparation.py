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

from dataclasses import replace

from grainview.contract.errors import ParameterError

from .parameters import (DEFAULT_PRESET, MAX_SEED, MIN_TEST_STEPS, PRESETS, Preparation,  # noqa: F401 (their home)
                         preset_name)

BY_SHAPE = {"s1s2": {"pentagon": "paper", "disk": "frictionless"}}
"""Presets that differ by shape: ``s1s2`` gives each shape the preparation that reproduces the
paper's initial state of its sample (S1 pentagons: compaction friction 0.4; S2 disks: 0;
docs/fidelity.md, section 2)."""


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


def prepare_sample(prep: Preparation, progress=None, checkpoint=None, **parameters):
    """Deposit and compact a sample as ``prep`` says; returns the compacted :class:`Simulation`
    with the test's friction set, and the sample's history in ``sim.history``
    (:class:`solver.sample_history.SampleHistory`: the preparation, whether the compaction
    settled, its wall stresses, largest inertia number, steps and unconverged steps).
    ``parameters`` go to :class:`solver.Parameters` (time step, tolerances...); the grains'
    friction is the preparation's (``prep.friction``, ``prep.compaction_friction``), not one of
    them.

    ``checkpoint``: a path (or a :class:`solver.compaction_checkpoint.CompactionCheckpoint`)
    where the compaction writes its state every ten minutes of wall time and when Ctrl-C or
    SIGTERM stops it; when that file holds a checkpoint of this sample (the same preparation
    and parameters), the compaction goes on from it instead of from the deposit, and ends on
    the state an uninterrupted one reaches, bit for bit. A checkpoint of another sample is
    refused (:class:`grainview.contract.errors.FileFormatError`). The file is left in place:
    the caller removes it once the sample is written elsewhere."""
    prep = prep.validate()
    if "friction" in parameters:
        raise ParameterError(f"friction={parameters['friction']!r} among the solver parameters: the grains' "
                             "friction is the preparation's; expected Preparation(friction=..., "
                             "compaction_friction=...)")
    compaction_friction = prep.friction if prep.compaction_friction is None else prep.compaction_friction
    from .compaction_checkpoint import CompactionCheckpoint, describe
    from .scenes import compaction_sample, isotropic_compaction  # the solver proper, on first use

    if checkpoint is not None and not isinstance(checkpoint, CompactionCheckpoint):
        checkpoint = CompactionCheckpoint(checkpoint, of=describe(prep, parameters))
    resumed = None
    if checkpoint is not None and checkpoint.exists():
        sim, resumed = checkpoint.load()
    else:
        sim = compaction_sample(prep.particles, prep.shape, sigma0=prep.sigma0, friction=compaction_friction,
                                seed=prep.seed, aspect=prep.aspect, max_wall_speed=prep.max_wall_speed, **parameters)
    from .parameters import check_time_step

    check_time_step(sim.parameters.time_step, prep.max_wall_speed, float(sim.radius.min()),
                    "a closing wall of the compaction")
    steps = isotropic_compaction(sim, max_steps=prep.max_steps, max_inertia_number=prep.max_inertia_number,
                                 pressure_ramp=prep.pressure_ramp, progress=progress, checkpoint=checkpoint,
                                 resume=resumed)
    sim.history.compaction_steps = steps
    sim.history.compaction_unconverged = sim.take_unconverged()
    sim.set_parameters(friction=prep.friction)
    sim.history.preparation = prep
    return sim
