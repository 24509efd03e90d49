"""Ensembles of biaxial tests: one simulation per (parameters, seed), run on a dask.distributed
cluster, each into its own file of the contract.

A study that separates a shape effect from noise needs several seeds per setting, and a
parameter sweep (friction, size, confining stress...) multiplies the runs. :func:`grid` spells
the runs out as :class:`RunSpec` values; :func:`run_one` simulates one of them into
``<folder>/<spec.name>.nc``; :func:`run_ensemble` submits every run to a dask.distributed
cluster — a :class:`distributed.LocalCluster` with one single-threaded worker process per core
by default, or any scheduler by its address (``tcp://...``, a dask-jobqueue cluster's
``scheduler_address``) whose workers can import this package and see the output folder.

Resuming is the files' business, not the scheduler's: :func:`run_one` looks at the file first.

* no file, or one without a complete snapshot (a run killed during its compaction): the run
  starts from its compaction's checkpoint ``<folder>/.<spec.name>.compaction.nc`` when there is
  one (written every ten minutes of the compaction, :mod:`solver.compaction_checkpoint`; removed
  once the test's file is complete), else from its deposit;
* a file whose test is unfinished (a run killed mid-test, by a lost worker, a wall-time limit
  or Ctrl-C): the test goes on from its last complete snapshot (:func:`solver.restart.resume`:
  the same snapshots, bit for bit, as an uninterrupted run);
* a finished file: nothing is done.

So when a worker dies, the scheduler hands its run to another worker, which resumes the file;
and running the same ensemble again after a crash of the whole job redoes only what is missing.
A file that exists with other settings than its spec is refused (``overwrite=True`` replaces
it), so that nothing a user owns is overwritten by a changed command line.

Each worker runs one simulation at a time on one thread; the numba, OpenMP and BLAS thread
counts of its process are set to 1 so that the workers do not oversubscribe the cores.
"""

from __future__ import annotations

import itertools
import logging
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from grainview.contract.errors import ConvergenceWarning, FileFormatError, ParameterError

from solver.engine import DEFAULT_ENGINE, DEFAULT_PRESET, BiaxialTest, Preparation, engine, prepare

EVENT_TOPIC = "grainview-ensemble"
"""Topic of the progress events the workers send to the client (``Worker.log_event``)."""

SINGLE_THREAD_ENV = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                     "MKL_NUM_THREADS": "1"}
"""Environment of each worker process of a local cluster: one thread per library."""


@dataclass(frozen=True)
class RunSpec:
    """One biaxial test of an ensemble: the sample (shape, particles, seed, grain friction,
    named preparation, confining stress sigma0 in Pa) and the test (vertical strain eps_1, top
    wall speed in m s-1, steps between snapshots). ``solver``: further :class:`solver.Parameters`
    as sorted (name, value) pairs. ``None`` keeps the preparation's default. ``engine``: the
    name of the :mod:`solver.engine` that simulates it."""

    shape: str | int = Preparation.shape  # a name of solver.shapes.SHAPES, a number of vertices, a family or a file
    particles: int = Preparation.particles
    seed: int = Preparation.seed
    friction: float | None = None
    preparation: str = DEFAULT_PRESET
    sigma0: float | None = None
    strain: float = BiaxialTest.strain
    velocity: float = BiaxialTest.velocity
    every: int = BiaxialTest.every
    near_contacts: bool = True
    solver: tuple = field(default=())
    engine: str = DEFAULT_ENGINE

    @property
    def name(self) -> str:
        """File stem naming the run by its parameters, e.g. ``pentagon_n400_mu0.4_s2``."""
        from solver.engine import shape_label

        parts = [shape_label(self.shape), f"n{self.particles}"]
        if self.preparation != "paper":
            parts.append(self.preparation)
        if self.friction is not None:
            parts.append(f"mu{self.friction:g}")
        if self.sigma0 is not None:
            parts.append(f"p{self.sigma0:g}Pa")
        parts += [f"{k}{v:g}" if isinstance(v, (int, float)) else f"{k}-{v}" for k, v in self.solver]
        parts.append(f"s{self.seed}")
        return "_".join(parts)

    def validate(self) -> RunSpec:
        """The spec itself, checked: one clear :class:`ParameterError` naming the bad field."""
        BiaxialTest(self.strain, self.velocity, self.every).validate()
        try:  # the sample's settings (seed, shape, particles, ...) are checked once, by its Preparation
            engine(self.engine).check(self.sample(), dict(self.solver), self.test())
        except TypeError as exc:
            raise ParameterError(f"solver={self.solver!r}: {exc}; expected fields of solver.Parameters") from None
        return self

    def test(self) -> BiaxialTest:
        """The :class:`solver.parameters.BiaxialTest` of the run."""
        return BiaxialTest(self.strain, self.velocity, self.every)

    def sample(self):
        """The :class:`solver.preparation.Preparation` of the run's sample."""
        from solver.engine import preparation

        return preparation(self.preparation, particles=self.particles, shape=self.shape, seed=self.seed,
                           friction=self.friction, sigma0=self.sigma0)

    def expected_attrs(self) -> dict:
        """File attributes a file of this run holds (to recognise it when resuming): the test,
        the whole preparation, and the solver parameters the spec sets."""
        from solver.engine import preset_name

        prep = self.sample()
        expected = {"strain_target": self.strain, "wall_velocity_m_s": self.velocity, "snapshot_every": self.every,
                    "solver_friction": prep.friction, "sigma0_Pa": prep.sigma0,
                    "preparation_name": preset_name(prep), **prep.attrs()}
        expected.update({f"solver_{k}": v for k, v in self.solver})
        return expected


SEEDS_PER_SETTING = 3
"""Seeds per setting of an ensemble when none are named (:func:`grid`, ``grainview ensemble``):
the fewest that give a spread over seeds beside each mean."""


def grid(*, shapes=(RunSpec.shape,), frictions=(None,), seeds=SEEDS_PER_SETTING, particles=(RunSpec.particles,), sigma0=(None,),
         first_seed=0, **common):
    """Every combination of the values given, with ``seeds`` seeds each (a count: seeds
    ``first_seed`` .. ``first_seed + seeds - 1``, or a sequence of seeds): a list of
    :class:`RunSpec`, validated. ``common``: the other :class:`RunSpec` fields, the same for
    every run."""
    if isinstance(seeds, (int, np.integer)):
        if seeds < 1:
            raise ParameterError(f"seeds={seeds}: expected at least 1 seed")
        seed_list = range(int(first_seed), int(first_seed) + int(seeds))
    else:
        seed_list = tuple(seeds)
        if len(seed_list) == 0:
            raise ParameterError(f"seeds={seeds!r}: expected at least 1 seed")
    specs = [RunSpec(shape=shape, particles=int(n), seed=int(seed), friction=mu, sigma0=p0, **common).validate()
             for shape, n, mu, p0, seed in itertools.product(shapes, particles, frictions, sigma0, seed_list)]
    names = [s.name for s in specs]
    if len(set(names)) != len(names):
        raise ParameterError("the grid names the same run twice (repeated values?)")
    return specs


def file_state(path) -> str:
    """What the file of a run holds (:func:`solver.restart.file_state`)."""
    from solver.engine import file_state

    return file_state(path)


def _check_settings(path, spec: RunSpec):
    """Refuse to resume a file written with other settings than ``spec``
    (:func:`solver.restart.check_settings`)."""
    from solver.engine import check_settings

    check_settings(path, spec.expected_attrs())


def run_one(spec: RunSpec, folder, *, overwrite=False, progress=None, compress=True) -> dict:
    """Simulate, resume or skip the run ``spec`` into ``<folder>/<spec.name>.nc`` (see the
    module docstring). Returns a dict: ``name``, ``path``, ``action`` ("ran", "resumed",
    "finished already"), ``steps`` (steps taken now), ``seconds``, ``unconverged`` (steps
    where NLGS stopped unconverged: sweep cap or stall test). ``progress`` and ``compress`` (the finished file kept
    compressed): as for :func:`solver.biaxial_test`."""
    spec = spec.validate()
    runner = engine(spec.engine)
    path = Path(folder) / f"{spec.name}.nc"
    checkpoint = Path(folder) / f".{spec.name}.compaction.nc"
    start = time.perf_counter()
    if overwrite:
        checkpoint.unlink(missing_ok=True)
    state = "missing" if overwrite else runner.file_state(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if state == "finished":
            _check_settings(path, spec)
            # resume() of a finished test takes nothing further: it compresses a file whose
            # compression was stopped and removes what killed writers left beside it
            action, steps = "finished already", runner.resume(path, progress=progress, compress=compress)
        elif state == "partial":
            _check_settings(path, spec)
            action, steps = "resumed", runner.resume(path, progress=progress, compress=compress)
        else:
            sample = prepare(runner, spec.sample(), dict(spec.solver), progress=progress, checkpoint=checkpoint)
            steps = runner.shear(sample, path, spec.test(), overwrite=True,
                                 attrs={**sample.history.attrs(), "ensemble_run": spec.name}, progress=progress,
                                 near_contacts=spec.near_contacts, compress=compress)
            action = "ran"
    checkpoint.unlink(missing_ok=True)  # the compaction is in the test's file now
    unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    others = list(dict.fromkeys(str(w.message).splitlines()[0] for w in caught
                                if not issubclass(w.category, (ConvergenceWarning, DeprecationWarning))))
    return {"name": spec.name, "path": str(path), "action": action, "steps": int(steps),
            "seconds": time.perf_counter() - start, "unconverged": unconverged, "warnings": others}


class _EventBar:
    """A progress bar that sends its count to the client as a worker event (at most twice a
    second), for :func:`run_ensemble`'s display."""

    def __init__(self, name, total, desc):
        from distributed import get_worker

        self.worker, self.name, self.total, self.desc = get_worker(), name, int(total), desc
        self.n, self.sent = 0, 0.0

    def __enter__(self):
        self._send()
        return self

    def __exit__(self, *exc):
        self._send()

    def update(self, n=1):
        self.n += n
        if time.monotonic() - self.sent > 0.5:
            self._send()

    def _send(self):
        self.sent = time.monotonic()
        self.worker.log_event(EVENT_TOPIC, {"run": self.name, "stage": self.desc, "n": self.n, "total": self.total,
                                            "pid": os.getpid()})


def _run_on_worker(spec: RunSpec, folder: str, compress: bool = True) -> dict:
    """The task of one run on a dask worker: :func:`run_one` (never overwriting: a retried task
    resumes its file) reporting progress as events."""
    return run_one(spec, folder, progress=lambda total, desc: _EventBar(spec.name, total, desc), compress=compress)


class _Display:
    """One tqdm bar per run on the client, fed by the workers' events."""

    def __init__(self, specs, enabled, on_event=None):
        from tqdm.auto import tqdm

        self.enabled, self.on_event = enabled, on_event
        self.bars = {s.name: tqdm(total=1, desc=s.name, unit="step", disable=not enabled, leave=True, position=k)
                     for k, s in enumerate(specs)}

    def __call__(self, event):
        _, msg = event
        if self.on_event is not None:
            self.on_event(msg)
        bar = self.bars.get(msg.get("run"))
        if bar is None:
            return
        bar.set_description_str(f"{msg['run']}: {msg['stage']}", refresh=False)
        bar.total = msg["total"]
        bar.n = msg["n"]
        bar.refresh()

    def close(self):
        for bar in self.bars.values():
            bar.close()


def check_cluster(scheduler=None, workers=None):
    """Refuse, in one line, a cluster that cannot be had: ``workers`` (processes of a new local
    cluster) not a whole number >= 1, or given with the address of an existing ``scheduler``,
    which has its own workers. The one check of these settings, for the library and the
    command line."""
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
            raise ParameterError(f"workers={workers!r}: expected at least 1 worker process (a whole number)")
        if scheduler is not None:
            raise ParameterError("workers= applies to the local cluster only; an existing scheduler has its own "
                                 "workers")


def local_cluster(workers=None, memory_limit="auto"):
    """A :class:`distributed.LocalCluster` of ``workers`` single-threaded processes (default:
    one per core), each with :data:`SINGLE_THREAD_ENV`."""
    from distributed import LocalCluster

    check_cluster(None, workers)
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, memory_limit=memory_limit,
                        env=dict(SINGLE_THREAD_ENV), dashboard_address=None, silence_logs=logging.CRITICAL)


def _client(scheduler, workers):
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - distributed is a dependency
        raise ParameterError("ensembles need dask.distributed: pip install distributed") from exc
    if scheduler is None:
        cluster = local_cluster(workers)
        return Client(cluster), cluster
    return Client(scheduler), None


def run_ensemble(specs, folder, *, scheduler=None, workers=None, client=None, overwrite=False, progress=None,
                 log=None, on_event=None, compress=True) -> list[dict]:
    """Run every :class:`RunSpec` of ``specs`` into ``folder`` on a dask.distributed cluster.

    ``client``: an existing :class:`distributed.Client`, whose workers have one thread each
    (the netCDF/HDF5 library cannot write two files from two threads of a process at once: a
    worker with more threads is refused); otherwise one to ``scheduler`` (an address) or to a
    new local cluster of ``workers`` single-threaded processes (default one per core), closed
    at the end. A run whose worker dies is given to another worker by the scheduler and
    resumes its file (up to the scheduler's ``allowed-failures``); a run that raises is
    reported and the others go on. ``progress``: one bar per run (None: when stderr is a
    terminal); ``log``: called with one line per finished or failed run; ``on_event``: called
    with each progress event, a dict (``run``, ``stage``, ``n`` steps of ``total``, the worker's
    ``pid``), in the client's event thread. ``compress``: keep each finished file compressed
    (:func:`solver.biaxial_test`).

    Returns one dict per run, in the order of ``specs``: :func:`run_one`'s, or ``name``,
    ``path`` and ``error`` (the exception's one line) for a run that failed. Call it again to
    resume what did not finish.
    """
    import sys

    from distributed import as_completed

    if client is None:
        check_cluster(scheduler, workers)
    specs = [s.validate() for s in specs]
    names = [s.name for s in specs]
    if len(set(names)) != len(names):
        raise ParameterError("specs name the same run twice")
    folder = Path(folder)
    for spec in specs:
        path = folder / f"{spec.name}.nc"
        if overwrite:  # removed here, once: a run retried after a lost worker then resumes its file
            if path.exists():
                path.unlink()
            continue
        try:  # a changed command line must not resume, or skip, another run's file
            if engine(spec.engine).file_state(path) in ("partial", "finished"):
                _check_settings(path, spec)
        except FileFormatError as exc:
            raise FileFormatError(f"{exc}; remove the file to run {spec.name} again, or pass overwrite=True to "
                                  "redo every run") from None
    folder.mkdir(parents=True, exist_ok=True)
    own = client is None
    cluster = None
    if own:
        client, cluster = _client(scheduler, workers)
    enabled = sys.stderr.isatty() if progress is None else bool(progress)
    display = _Display(specs, enabled, on_event)
    try:
        threaded = {worker: n for worker, n in client.nthreads().items() if n > 1}
        if threaded:
            raise ParameterError(f"workers with {max(threaded.values())} threads ({', '.join(sorted(threaded))}): "
                                 "expected one thread per worker, since two runs in one process would write "
                                 "their netCDF (HDF5) files at once, which the library does not support")
        client.subscribe_topic(EVENT_TOPIC, display)
        futures = {client.submit(_run_on_worker, spec, str(folder.resolve()), compress, pure=False,
                                 key=f"grainview-run-{spec.name}-{time.time_ns()}"): spec for spec in specs}
        results = {}
        for future in as_completed(futures):
            spec = futures[future]
            try:
                result = future.result()
            except Exception as exc:  # the run's own error, or KilledWorker after repeated losses
                result = {"name": spec.name, "path": str(folder / f"{spec.name}.nc"),
                          "error": f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"}
            results[spec.name] = result
            if log is not None:
                log(describe_result(result))
        client.unsubscribe_topic(EVENT_TOPIC)
    finally:
        display.close()
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    return [results[name] for name in names]


def describe_result(result: dict) -> str:
    """One line saying what happened to a run."""
    if "error" in result:
        return f"{result['name']}: FAILED ({result['error']})"
    extra = f", NLGS unconverged in {result['unconverged']} step(s)" if result.get("unconverged") else ""
    warned = result.get("warnings") or []
    if warned:
        extra += f"; {len(warned)} warning(s), the first: {warned[0]}"
    if result["action"] == "finished already":
        return f"{result['name']}: finished already ({result['path']})"
    return f"{result['name']}: {result['action']}, {result['steps']} steps in {result['seconds']:.1f} s{extra}"

