"""Resuming a biaxial test from its own output file, and starting a test from any saved snapshot.

A run killed at any moment (SIGKILL, a cluster's wall-time limit, Ctrl-C) leaves a file whose
complete snapshots all open (:class:`grainview.contract.writer.SnapshotWriter` syncs the file after each
one and marks it ``complete`` last). The last complete snapshot holds the whole state of the
run, so :func:`resume` rebuilds the :class:`~solver.stepper.Simulation` from it and goes on
appending to the same file:

* particles: ``position``, ``angle``, ``velocity``, ``angular_velocity`` (f8, exact); their
  shapes from ``radius``, ``n_vertices`` and ``vertices`` (:meth:`solver.shapes.Shapes.of`:
  regular polygons when the file has no ``vertices`` or holds exactly the regular ones, any
  convex polygon otherwise, with the same tables as the run that wrote them);
* walls: ``wall_position``, ``wall_velocity`` per snapshot; ``wall_normal`` and the wall names;
  how each wall is driven (global attributes ``wall_mode``, ``wall_stress_Pa``,
  ``wall_mass_kg``, ``wall_max_speed_m_s``, ``wall_length_axis``, see
  :func:`solver.output.wall_settings`);
* the warm start of the next step: ``normal_impulse`` and ``tangential_impulse``, the impulses
  of the last step at each contact point, keyed by body pair and point rank as the stepper
  keys them (the resultant forces ``fn``, ``ft`` could not give the two points of a double
  contact back);
* ``time`` and ``step`` (the step index); the solver parameters (attributes ``solver_*``); the
  test itself (``strain_target``, ``wall_velocity_m_s``, ``snapshot_every``, ``biaxial_steps``,
  ``sigma0_Pa``).

There is no random state to restore: the only random draw of a step, the NLGS ordering when
``shuffle`` is on, is seeded with ``seed + step index``. The broad phase is redone at the first
resumed step; it only selects candidate pairs, and the narrow phase keeps the contacts in the
candidates' sorted order, so the contacts found are the same. A resumed run therefore writes
the same snapshots, bit for bit, as an uninterrupted one.

From a shell::

    python -m solver.restart run.nc
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from dataclasses import fields

import numpy as np

from grainview.contract.errors import ConvergenceWarning, FileFormatError, GrainviewError, ParameterError
from grainview.contract.reader import ContractFile

from .interrupt import Terminated, sigterm_raises
from .output import Recorder, compress_finished, compress_level
from .sample_history import SampleHistory
from .scenes import biaxial_steps
from .shapes import Shapes
from .stepper import Parameters, Simulation
from .walls import Walls

STATE_VARIABLES = ("velocity", "angular_velocity", "wall_normal", "wall_position", "wall_velocity",
                   "normal_impulse", "tangential_impulse", "step")
"""Variables a file needs, besides the required ones, to be resumed."""
WALL_ATTRIBUTES = ("wall_mode", "wall_stress_Pa", "wall_mass_kg", "wall_max_speed_m_s", "wall_length_axis")
BIAXIAL_ATTRIBUTES = ("strain_target", "wall_velocity_m_s", "snapshot_every", "biaxial_steps")


LATER_PARAMETERS = {"solver": "nlgs", "anderson_memory": 5, "anderson_period": 1, "domains": 1,
                    "stall_sweeps": 0}
"""Parameters added after files were first written, with the value every older file ran with
(not the current default, which may change): absent from a file, they take that value. A file
from before ``solver_solver`` names its solver by ``solver_acceleration``
(:data:`solver.contact_solvers.ACCELERATIONS`: ``off`` is ``nlgs``)."""


def _parameters(attrs, source) -> Parameters:
    """The solver parameters written as global attributes ``solver_<name>``."""
    values = {}
    for field in fields(Parameters):
        key = f"solver_{field.name}"
        if key not in attrs and field.name in LATER_PARAMETERS:
            values[field.name] = LATER_PARAMETERS[field.name]  # a file from before the parameter existed
            continue
        if key not in attrs:
            raise FileFormatError(f"{source}: cannot resume, global attribute {key!r} is missing")
        value = attrs[key]
        kind = str(field.type).split("|")[0].strip()  # the field's declared type (float | None: float)
        if isinstance(value, str):
            value = None if value == "none" else value
        elif kind == "tuple":
            value = tuple(float(g) for g in np.atleast_1d(value))
        else:
            value = {"bool": bool, "int": int}.get(kind, float)(value)
        values[field.name] = value
    acceleration = attrs.get("solver_acceleration") if "solver_solver" not in attrs else None
    return Parameters(**values, acceleration=acceleration)


SHEAR_ATTRIBUTES = ("strain_target", "snapshot_every", "shear_steps", "cell_shear_rate_s", "cell_stress_Pa",
                    "cell_mass_kg", "cell_max_speed_m_s")
"""What a periodic shear's file says of its test and its cell (:mod:`solver.periodic_shear`)."""
SHEAR_STATE_VARIABLES = ("velocity", "angular_velocity", "normal_impulse", "tangential_impulse", "step", "cell")


def _check_resumable(ds, source):
    if ds.attrs.get("scene") == "shear":
        missing = [name for name in SHEAR_STATE_VARIABLES if name not in ds.variables]
        missing += [name for name in SHEAR_ATTRIBUTES if name not in ds.attrs]
        if missing:
            raise FileFormatError(f"{source}: cannot resume, the file lacks {missing}")
        if not isinstance(ds.attrs["cell_stress_Pa"], str) and "cell_velocity" not in ds.variables:
            raise FileFormatError(f"{source}: cannot resume a shear whose cell height follows a stress: the file "
                                  "does not hold the cell's rate of height (cell_velocity; written by a solver "
                                  "before it); a shear at a fixed height resumes")
        if ds.n_snapshots == 0:
            raise FileFormatError(f"{source}: cannot resume, the file holds no complete snapshot")
        return
    missing = [name for name in STATE_VARIABLES if name not in ds.variables]
    missing += [name for name in (*WALL_ATTRIBUTES, *BIAXIAL_ATTRIBUTES) if name not in ds.attrs]
    if missing:
        raise FileFormatError(f"{source}: cannot resume, the file lacks {missing} (written by a solver "
                              "without restart support, or not by this solver)")
    if ds.attrs.get("scene") != "biaxial":
        raise FileFormatError(f"{source}: cannot resume, scene={ds.attrs.get('scene')!r}: only a biaxial test "
                              "('biaxial') can be resumed")
    if ds.n_snapshots == 0:
        raise FileFormatError(f"{source}: cannot resume, the file holds no complete snapshot (the run was "
                              "stopped before its first one): start the run again")


def snapshot_state(ds, index, source):
    """The whole solver state at snapshot ``index`` of an open :class:`ContractFile` (plain numpy arrays)."""
    count = int(ds.snapshot("contact_count", index))
    periodic = "cell" in ds.variables
    names = ("position", "angle", "velocity", "angular_velocity") + (
        ("cell", "box_min") + (("cell_velocity",) if "cell_velocity" in ds.variables else ()) if periodic
        else ("wall_position", "wall_velocity"))
    state = {name: ds.snapshot(name, index).copy() for name in names}
    if periodic:
        state.update(wall_position=np.empty((0, 2)), wall_velocity=np.empty((0, 2)))
    for name, value in state.items():
        if not np.all(np.isfinite(value)):
            raise FileFormatError(f"{source}: cannot restart, {name} of snapshot {index} is not finite")
    state.update({name: ds.static(name) for name in ("radius", "n_vertices", "mass", "inertia")})
    state["wall_normal"] = ds.static("wall_normal") if "wall_normal" in ds.variables else np.empty((0, 2))
    state["vertices"] = ds.static("vertices") if "vertices" in ds.variables else None
    state.update({name: ds.snapshot(name, index)[:count].copy()
                  for name in ("i", "j", "normal_impulse", "tangential_impulse")})
    state.update(time=float(ds.snapshot("time", index)), step=int(ds.snapshot("step", index)),
                 first_step=int(ds.snapshot("step", 0)), names=ds.wall_names, attrs=dict(ds.attrs))
    return state


def _periodic_cell(state):
    """The :class:`solver.periodic_cell.PeriodicCell` of a shear's snapshot state (its vectors,
    corner and the attributes of how it is driven)."""
    from .periodic_cell import PeriodicCell

    attrs, vectors = state["attrs"], state["cell"]
    stress = attrs["cell_stress_Pa"]
    return PeriodicCell(state["box_min"], float(vectors[0, 0]), float(vectors[1, 1]), tilt=float(vectors[1, 0]),
                        shear_rate=float(attrs["cell_shear_rate_s"]),
                        height_rate=float(state["cell_velocity"][1, 1]) if "cell_velocity" in state else 0.0,
                        stress=None if isinstance(stress, str) else float(stress),
                        mass=float(attrs["cell_mass_kg"]), max_speed=float(attrs["cell_max_speed_m_s"]))


def simulation_from_state(state, source) -> Simulation:
    """Rebuild a :class:`Simulation` (walls or periodic cell, parameters, warm start) from
    :func:`snapshot_state`."""
    attrs = state["attrs"]
    if "cell" in state:
        return _finish(Simulation(state["position"], state["angle"], walls=None, parameters=_parameters(attrs, source),
                                  velocity=state["velocity"], angular_velocity=state["angular_velocity"],
                                  shapes=_shapes(state, source), cell=_periodic_cell(state)), state, source)
    walls = Walls(state["wall_position"], state["wall_normal"], state["names"],
                  mode=np.asarray(attrs["wall_mode"], np.int64), velocity=state["wall_velocity"],
                  stress=np.asarray(attrs["wall_stress_Pa"], float), mass=np.asarray(attrs["wall_mass_kg"], float),
                  length_axis=np.asarray(attrs["wall_length_axis"], np.int64),
                  max_speed=np.asarray(attrs["wall_max_speed_m_s"], float))
    sim = Simulation(state["position"], state["angle"], walls=walls, parameters=_parameters(attrs, source),
                     velocity=state["velocity"], angular_velocity=state["angular_velocity"],
                     shapes=_shapes(state, source))
    return _finish(sim, state, source)


def _shapes(state, source):
    try:
        return Shapes.of(state["radius"], state["n_vertices"], state["vertices"])
    except ParameterError as exc:
        raise FileFormatError(f"{source}: cannot restart, its shapes are not the contract's: {exc}") from None


def _finish(sim, state, source):
    """Check the masses, set the time, the history and the warm start of a rebuilt ``sim``."""
    attrs = state["attrs"]
    if not (np.array_equal(sim.mass, state["mass"]) and np.array_equal(sim.inertia, state["inertia"])):
        raise FileFormatError(f"{source}: cannot restart, the masses and inertias of the file differ from those "
                              "of its solver parameters (density, thickness)")
    sim.time, sim.step_index = state["time"], state["step"]
    sim.history = SampleHistory.from_attrs(attrs)
    sim.set_warm_start(state["i"], state["j"], state["normal_impulse"], state["tangential_impulse"])
    return sim


def load_sample(path, index=-1) -> Simulation:
    """The simulation at snapshot ``index`` (default: the last complete one) of a file this
    solver wrote, whatever its scene: positions, velocities, walls (or a periodic shear's cell)
    driven as recorded, solver parameters, the sample's history ``sim.history`` (its confining stress ``sigma0`` in Pa, NaN if
    the file does not say; :class:`solver.sample_history.SampleHistory`) and the
    warm start of the next step. Use it to start a test from a saved compacted sample::

        sim = load_sample("pentagons_compacted.nc")
        biaxial_test(sim, "biaxial.nc", strain=0.25)

    Raises :class:`FileFormatError` naming what is missing. The file is only read.
    """
    source = os.fspath(path)
    with ContractFile(source) as ds:
        if "cell" in ds.variables:  # a periodic shear's file: its cell instead of walls
            missing = [name for name in SHEAR_STATE_VARIABLES if name not in ds.variables]
            missing += [name for name in SHEAR_ATTRIBUTES if name not in ds.attrs and name.startswith("cell_")]
        else:
            missing = [name for name in STATE_VARIABLES if name not in ds.variables]
            missing += [name for name in WALL_ATTRIBUTES if name not in ds.attrs]
        if missing:
            raise FileFormatError(f"{source}: cannot restart from it, the file lacks {missing} (written by a "
                                  "solver without restart support, or not by this solver)")
        if ds.n_snapshots == 0:
            raise FileFormatError(f"{source}: the file holds no complete snapshot")
        if not -ds.n_snapshots <= int(index) < ds.n_snapshots:
            raise FileFormatError(f"{source}: index={index!r} is outside its {ds.n_snapshots} snapshots")
        state = snapshot_state(ds, int(index), source)
    sim = simulation_from_state(state, source)
    sim.show_warm_start()  # a test's first snapshot shows the sample's contacts and forces
    return sim


def load_state(path):
    """The simulation at the last complete snapshot of ``path`` and the test's settings.

    Returns ``(sim, test)``: ``sim`` a :class:`Simulation` whose next step is the one after the
    snapshot, with its warm start; ``test`` a dict with ``first_step`` (step index of the
    test's first snapshot), ``n_steps``, ``every``, ``snapshots`` (complete snapshots in the
    file). Raises :class:`FileFormatError` naming what is missing when the file cannot be
    resumed. The file is only read.
    """
    source = os.fspath(path)
    with ContractFile(source) as ds:
        _check_resumable(ds, source)
        state = snapshot_state(ds, -1, source)
        snapshots = ds.n_snapshots
    sim = simulation_from_state(state, source)
    attrs = state["attrs"]
    steps = attrs["shear_steps"] if attrs.get("scene") == "shear" else attrs["biaxial_steps"]
    test = {"first_step": state["first_step"], "n_steps": int(steps), "every": int(attrs["snapshot_every"]),
            "snapshots": snapshots}
    return sim, test


def file_state(path) -> str:
    """What the file of a run holds: "missing", "empty" (no complete snapshot: the run died
    before its test began), "partial" (an unfinished test) or "finished"."""
    if not os.path.exists(path):
        return "missing"
    try:
        sim, test = load_state(path)
    except FileFormatError as exc:
        if "no complete snapshot" in str(exc):
            return "empty"
        raise
    done = sim.step_index - test["first_step"]
    return "finished" if done >= test["n_steps"] else "partial"


def check_settings(path, expected, advice="pass overwrite=True to replace it"):
    """Refuse, in one :class:`FileExistsError` line naming the first difference and ``advice``,
    to resume or keep the run in ``path`` when its global attributes differ from ``expected``
    (name -> value: numbers equal to 1e-12 relative, other values as text; a bool as 0/1; None
    or "none" also matches a file without the attribute, written before the setting existed):
    a run of other settings than the ones asked for is neither resumed nor taken as finished."""
    import math

    with ContractFile(os.fspath(path)) as ds:
        attrs = dict(ds.attrs)
    for key, want in expected.items():
        have = attrs.get(key)
        if isinstance(want, bool):
            want = int(want)
        if want is None:
            want = "none"
        if have is None and want == "none":  # a file older than the setting: it ran with the setting's none
            continue
        numeric = isinstance(want, (int, float, np.integer, np.floating)) and not isinstance(have, str)
        same = have is not None and (math.isclose(float(have), float(want), rel_tol=1e-12) if numeric
                                     else str(have) == str(want))
        if not same:
            shown = "none recorded" if have is None else have
            raise FileExistsError(f"{path} holds another run ({key} = {shown}, this run's is {want}); {advice}")


def resume(path, progress=None, compress=True) -> int:
    """Continue the biaxial test (or periodic shear, :mod:`solver.periodic_shear`) written to
    ``path`` from its last complete snapshot until its strain target, appending the snapshots to the same file. Returns the number of steps
    taken (0 when the test had already finished).

    The snapshots written are those an uninterrupted run writes, bit for bit (see the module
    docstring). Ctrl-C stops again after the current step, with instructions to resume.
    ``progress``: a tqdm bar (None: when stderr is a terminal). A compressed file is made
    netCDF-3 again to append to and, once the test has finished, compressed again
    (``compress``: True, a zlib level 1-9, or False); a finished test whose file is still
    netCDF-3 (its compression was stopped) is compressed now.

    The file's writer lock is taken before its last snapshot is read and held until the file
    is closed and compressed, so two resumes of one file never both append: the second raises
    :class:`grainview.contract.locks.FileLockedError` naming the first. Taking the lock also removes the
    temporary files of killed writers (:func:`grainview.contract.writer.remove_strays`).
    """
    from grainview.contract.writer import is_compressed, lock_file

    level = compress_level(compress)
    source = os.fspath(path)
    if not os.path.exists(source):
        raise FileFormatError(f"{source}: no such file")
    lock = None
    try:
        try:  # SIGTERM before the first step: one line, the file as it was
            with sigterm_raises():
                lock = lock_file(source)
                sim, test = load_state(source)
                first = sim.step_index - test["first_step"] + 1
                finished = first > test["n_steps"]
                if not finished:  # a compressed file is made netCDF-3 again here
                    recorder = Recorder.append_to(source, sim, compress=level, lock=lock)
        except Terminated:
            print(f"terminated (SIGTERM) before the run went on: {source} is as it was", file=sys.stderr)
            raise
        if finished:
            if level and not is_compressed(source):
                compress_finished(source, level, lock)
            return 0
        if sim.cell is not None:  # a periodic shear (solver.periodic_shear)
            from .periodic_shear import shear_steps as steps
        else:
            steps = biaxial_steps
        with recorder:
            steps(sim, recorder, first=first, n_steps=test["n_steps"], every=test["every"], progress=progress)
        return test["n_steps"] - first + 1
    finally:
        if lock is not None:
            lock.release()


def main(argv=None) -> int:
    """``python -m solver.restart PATH``: resume the biaxial test written to PATH."""
    parser = argparse.ArgumentParser(prog="python -m solver.restart", description=main.__doc__)
    parser.add_argument("path", help="the netCDF file of an interrupted biaxial test")
    parser.add_argument("--progress", choices=("auto", "on", "off"), default="auto", help="progress bar")
    parser.add_argument("--no-compress", action="store_true",
                        help="leave the finished file uncompressed netCDF-3 (default: compressed with zlib)")
    args = parser.parse_args(argv)
    progress = None if args.progress == "auto" else args.progress == "on"
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            steps = resume(args.path, progress=progress, compress=not args.no_compress)
    except (GrainviewError, FileNotFoundError) as exc:
        print(f"solver.restart: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        return 143
    except KeyboardInterrupt:
        return 130
    for w in caught:
        if not issubclass(w.category, ConvergenceWarning):
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    if unconverged:
        print(f"warning: the contact solver did not converge in {unconverged} step(s) (stopped at its iteration cap "
              "or stall test); the file counts them per snapshot (nlgs_unconverged_steps) with their largest "
              "residuals", file=sys.stderr)
    print(f"{args.path}: {'already complete' if steps == 0 else f'resumed for {steps} steps, complete'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
