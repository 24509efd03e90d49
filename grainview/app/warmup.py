"""Compile every numba kernel of the solver and the analysis into numba's on-disk cache.

The kernels are compiled with ``cache=True``: the first process that calls one compiles it
(about half a minute for the whole solver on one core) and writes the machine code to the
cache folder, and every later process loads it in a fraction of a second. A run started on a
cold cache spends its first step compiling, and a signal such as SIGTERM, which the solver
acts on between whole steps, waits for that step. :func:`warm_up` runs a tiny workload that
calls every kernel with the argument types a run uses (pentagons and disks; plain and
Anderson sweeps; one and two domains; the stall test; the written snapshots and their
residuals; the analyses' kernels), so that the runs that follow start at once.

The cache lives where numba puts it: ``NUMBA_CACHE_DIR`` when it is set, otherwise a
``__pycache__`` folder beside each module (or a user cache folder when that one is not
writable). :func:`cache_location` says which, and :func:`cache_state` whether it holds every
kernel for this processor (numba keys each compiled version by the target's CPU name and
features, so a cache filled on another processor, or for ``NUMBA_CPU_NAME=generic``, does not
count): the command line compiles ahead, with progress, only when it does not.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import pkgutil
import tempfile
import warnings
from pathlib import Path

__all__ = ["warm_up", "kernels", "cache_location", "cache_holds", "cache_state"]

PACKAGES = ("solver", "grainview.analysis._kernels")
"""The packages whose modules hold numba kernels."""
SOLVER_PACKAGES = ("solver",)
"""The packages whose kernels a simulation calls (``grainview run``); the analysis's are
:data:`PACKAGES`' others."""
GROUPS = {"solver": SOLVER_PACKAGES, "analysis": ("grainview.analysis._kernels",)}
"""The kernels by what needs them: a simulation the solver's, a report the analysis's too (the
keys of :data:`grainview.app.paper_size.COMPILE_SECONDS`)."""
NOT_IN_RUNS = ("solver.residuals.local_law_residuals",)
"""Kernels that no run, study or report calls, by module or by name: a public helper of the
residuals that only a user's own code calls (the solver research, which no run reaches either,
lives outside the solver, in benchmarks/research/). The warm-up's workload does not compile them and
:func:`cache_state` leaves them out (tests/grainview/test_study_time.py checks that after a
warm-up no other kernel is missing from the cache)."""


def _in_runs(name) -> bool:
    """Whether the kernel "module.name" is one a run, a study or a report may call (not one of
    :data:`NOT_IN_RUNS`)."""
    return name not in NOT_IN_RUNS and name.rpartition(".")[0] not in NOT_IN_RUNS


def cache_location() -> str:
    """Where numba writes and reads its compiled kernels: ``NUMBA_CACHE_DIR`` (made absolute)
    when it is set, else the ``__pycache__`` folders beside the modules."""
    from numba.core.config import CACHE_DIR

    if CACHE_DIR:
        return f"{os.path.abspath(CACHE_DIR)} (NUMBA_CACHE_DIR)"
    from solver import engine

    return (f"__pycache__ folders beside the modules, e.g. {Path(engine.__file__).parent / '__pycache__'} "
            "(NUMBA_CACHE_DIR unset; set it to choose a folder)")


def kernels(packages=PACKAGES) -> dict:
    """Every numba kernel of ``packages`` (default :data:`PACKAGES`): {"module.name":
    dispatcher}, in module order. Kernels marked ``inline="always"`` are compiled into their
    callers and not listed."""
    from numba.core.registry import CPUDispatcher

    found = {}
    for package in packages:
        root = importlib.import_module(package)
        for info in pkgutil.iter_modules(root.__path__):
            module = importlib.import_module(f"{package}.{info.name}")
            for name, value in vars(module).items():
                if (isinstance(value, CPUDispatcher) and value.__module__ == module.__name__
                        and value.targetoptions.get("inline", "never") != "always"):
                    found[f"{module.__name__}.{name}"] = value
    return found


def cache_holds(dispatcher) -> bool | None:
    """Whether the kernel ``dispatcher`` can run in this process without compiling.

    True when it has a compiled version in this process already, or when numba's on-disk
    cache holds one for this processor: an entry of its index file (which numba reads only
    when the index's numba version and source file's stamp are current) whose key matches the
    one numba would look up, i.e. the same bytecode and the same target (the CPU name and
    features of ``NUMBA_CPU_NAME``/``NUMBA_CPU_FEATURES``, or the host's).

    Parameters
    ----------
    dispatcher : numba.core.registry.CPUDispatcher
        A kernel of :func:`kernels`.

    Returns
    -------
    bool or None
        True or False as above; None when ``dispatcher`` has no on-disk cache (``cache=False``)
        or numba's internals are not those this reads (another numba version): unknown.
    """
    try:
        if dispatcher.signatures:
            return True
        from numba.core.caching import Cache

        cache = dispatcher._cache
        if not isinstance(cache, Cache):
            return None
        codegen = dispatcher.targetctx.codegen()
        index = cache._cache_file._load_index()
        return any(cache._index_key(key[0], codegen) == key for key in index)
    except Exception:  # numba's private layout differs: say nothing rather than guess
        return None


def cache_state(packages=PACKAGES) -> dict:
    """Which kernels of ``packages`` a process would compile before it runs (:func:`cache_holds`),
    :data:`NOT_IN_RUNS`' left out.

    Parameters
    ----------
    packages : tuple of str
        The packages to look at: :data:`PACKAGES` (a study: the solver and the analysis) or
        :data:`SOLVER_PACKAGES` (a run).

    Returns
    -------
    dict
        ``{"kernels": how many were looked at, "cold": [names of those not in the cache],
        "unknown": [names of those whose state could not be read]}``; the cache is warm when
        both lists are empty.
    """
    found = {name: d for name, d in kernels(packages).items() if _in_runs(name)}
    state = {name: cache_holds(d) for name, d in found.items()}
    return {"kernels": len(found), "cold": [n for n, held in state.items() if held is False],
            "unknown": [n for n, held in state.items() if held is None]}


def cold_shares(groups=tuple(GROUPS)) -> dict:
    """For each group of :data:`GROUPS` named in ``groups``, the share of its kernels that a
    process would compile (:func:`cache_state`: those not in the cache and those whose state is
    unknown), with their names.

    Returns
    -------
    dict
        ``{group: (share from 0 to 1, [names of the kernels to compile])}``.
    """
    out = {}
    for group in groups:
        state = cache_state(GROUPS[group])
        names = state["cold"] + state["unknown"]
        out[group] = (len(names) / state["kernels"] if state["kernels"] else 0.0, names)
    return out


def _stages(folder):
    """The workload, as (what it compiles, callable) pairs in the order they run: the engine's
    (:meth:`solver.engine.ContactDynamics.warm_up_stages`, which writes the ``pentagon.nc``
    the analysis's stage reads), then the analysis's."""
    from solver.engine import engine

    def analysis():
        from ..contract.io import open_dataset

        with open_dataset(Path(folder) / "pentagon.nc") as ds:
            ds.grain.xi_network().compute()
            ds.grain.coarse_grained(width=0.05, spacing=0.05).compute()
            ds.grain.network_persistence().compute()
            ds.grain.force_chains(follow=True)

    return [*engine().warm_up_stages(folder),
            ("analysis: the xi-network, the coarse-grained fields, the network's topology, the force chains",
             analysis)]


@contextlib.contextmanager
def compiled_kernels(callback):
    """Within the block, ``callback(name)`` is called each time numba finishes compiling a
    kernel of :func:`kernels` (``name``: "module.name"; a kernel loaded from the cache is not
    compiled), through numba's event API (``numba.core.event``, event "numba:compile"). Where
    that API is missing, the block runs without calls."""
    try:
        from numba.core import event
    except ImportError:
        yield
        return

    class Listener(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            dispatcher = (ev.data or {}).get("dispatcher")
            function = getattr(dispatcher, "py_func", None)
            if function is not None:
                callback(f"{function.__module__}.{function.__name__}")

    try:
        listening = event.install_listener("numba:compile", Listener())
    except Exception:  # another numba's event API
        yield
        return
    with listening:
        yield


def warm_up(log=print, packages=PACKAGES, compiled=None) -> dict:
    """Compile (or load from the cache) every numba kernel the solver and the analysis use.

    Runs :func:`_stages`' tiny workload in a temporary folder, calling ``log`` with a line per
    stage, then checks that each kernel of :func:`kernels` has a compiled version.

    Parameters
    ----------
    log : callable, default print
        Called with one line per stage (progress).
    packages : tuple of str, default PACKAGES
        :data:`PACKAGES` for every stage, :data:`SOLVER_PACKAGES` for the solver's alone
        (what a run needs: the analysis's stage left out).
    compiled : callable, optional
        Called with a kernel's name each time one is compiled (:func:`compiled_kernels`): a
        progress bar's update.

    Returns
    -------
    dict
        ``{"kernels": number of kernels, "compiled": kernels with a compiled version,
        "missing": [names of the others, :data:`NOT_IN_RUNS`' left out], "cache":
        cache_location()}``.
    """
    from ..contract.errors import ConvergenceWarning

    events = compiled_kernels(compiled) if compiled is not None else contextlib.nullcontext()
    with tempfile.TemporaryDirectory(prefix="grainview-warmup-") as folder, warnings.catch_warnings(), events:
        warnings.simplefilter("ignore", ConvergenceWarning)
        warnings.simplefilter("ignore", RuntimeWarning)  # 2 domains on a machine told to let threads sleep
        analysis = any(package.startswith("grainview") for package in packages)
        stages = [(what, run) for what, run in _stages(folder) if analysis or not what.startswith("analysis:")]
        for k, (what, run) in enumerate(stages, 1):
            log(f"[{k}/{len(stages)}] {what}")
            run()
    found = {name: d for name, d in kernels(packages).items() if _in_runs(name)}
    missing = [name for name, dispatcher in found.items() if not dispatcher.signatures]
    return {"kernels": len(found), "compiled": len(found) - len(missing), "missing": missing,
            "cache": cache_location()}
