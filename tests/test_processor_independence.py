"""The same bits on any x86-64 processor: trajectories, files, analyses and the report compiled
for three targets on this one machine.

Each target runs :mod:`tests.portability` in a subprocess with its own numba cache (the host's is
``NUMBA_CACHE_DIR`` when set, the one the rest of the suite uses):

- ``host``: numba's default, the host's processor and all its instructions;
- ``generic``: ``NUMBA_CPU_NAME=generic`` (numba keeps the host's instruction set, the tuning
  is the generic one's);
- ``narrower``: a processor one instruction-set level below the host (AVX2 with FMA on a host
  with AVX-512, SSE4.2 on a host without), in numba (``NUMBA_CPU_NAME`` and
  ``NUMBA_CPU_FEATURES``), in numpy's own dispatch (``NPY_DISABLE_CPU_FEATURES``) and in
  OpenBLAS's kernels (``OPENBLAS_CORETYPE``): what another machine's build would run.

All three must give the recorded fingerprint digests and identical digests of everything else.
Slow (every kernel compiles three times); ``.ci/run`` runs it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent

# Instruction-set families switched off, by name prefix, when one level down is emulated.
AVX512 = ("avx512", "amx", "avx10", "avxvnni", "avxifma", "avxneconvert", "evex512")
AVX = AVX512 + ("avx", "fma", "f16c", "vaes", "vpclmulqdq", "bmi", "bmi2", "lzcnt", "movbe")


def host_features() -> list[str]:
    """The host's LLVM feature flags, e.g. ``['+avx2', '-avx512f', ...]``."""
    import llvmlite.binding as llvm

    llvm.initialize_native_target()
    return llvm.get_host_cpu_features().flatten().split(",")


def numpy_dispatch_above(level: str) -> list[str]:
    """numpy's runtime-dispatched CPU features of this host at or above ``level`` ('X86_V4',
    'X86_V3', or the older names 'AVX512F', 'AVX2')."""
    import numpy as np

    core = np._core._multiarray_umath if hasattr(np, "_core") else np.core._multiarray_umath
    found = [name for name in core.__cpu_dispatch__ if core.__cpu_features__.get(name)]
    order = ["X86_V3", "AVX2", "FMA3", "X86_V4", "AVX512F", "AVX512CD", "AVX512_SKX", "AVX512_CLX",
             "AVX512_CNL", "AVX512_ICL", "AVX512_SPR", "AVX512_KNL", "AVX512_KNM"]
    start = order.index(level)
    return [name for name in found if name in order[start:] or name.startswith("AVX512")]


def narrower_environment() -> dict:
    """Environment variables that make numba, numpy and OpenBLAS compute as on a processor one
    instruction-set level below this host's."""
    features = host_features()
    if "+avx512f" in features:
        drop, cpu, numpy_level, blas = AVX512, "haswell", "X86_V4", "Haswell"
    else:
        drop, cpu, numpy_level, blas = AVX, "nehalem", "X86_V3", "Nehalem"
    flags = ["-" + f[1:] if f[1:].startswith(drop) else f for f in features]
    env = {"NUMBA_CPU_NAME": cpu, "NUMBA_CPU_FEATURES": ",".join(flags), "OPENBLAS_CORETYPE": blas}
    disabled = numpy_dispatch_above(numpy_level)
    if disabled:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(disabled)
    return env


TARGETS = {
    "host": lambda: {},
    "generic": lambda: {"NUMBA_CPU_NAME": "generic"},
    "narrower": narrower_environment,
}


def digests_for(target: str, base: Path) -> dict:
    """The digests of :mod:`tests.portability` compiled for ``target`` (own numba cache and
    working folder under ``base``)."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("NUMBA_CPU", "NPY_DISABLE_CPU", "OPENBLAS_CORETYPE"))}
    shared = os.environ.get("NUMBA_CACHE_DIR")  # the host's kernels are the rest of the suite's
    cache = Path(shared) if shared and target == "host" else Path(shared or base) / "targets" / target
    env.update(TARGETS[target](), NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-m", "tests.portability", str(base / target)], cwd=ROOT,
                          env=env, capture_output=True, text=True, timeout=3000)
    lines = [line for line in done.stdout.splitlines() if line.startswith("DIGESTS ")]
    assert done.returncode == 0 and lines, f"{target}: {done.stderr[-3000:]}"
    return json.loads(lines[-1][len("DIGESTS "):])


def test_narrower_target_drops_the_wide_instructions():
    env = narrower_environment()
    flags = env["NUMBA_CPU_FEATURES"].split(",")
    assert not [f for f in flags if f.startswith("+avx512")]
    assert env["NUMBA_CPU_NAME"] in ("haswell", "nehalem")
    if env["NUMBA_CPU_NAME"] == "haswell":
        assert "+avx2" in flags and "+fma" in flags


@pytest.mark.slow
def test_every_target_gives_the_same_bits(tmp_path):
    with ThreadPoolExecutor(2) as pool:
        found = dict(zip(TARGETS, pool.map(lambda t: digests_for(t, tmp_path), TARGETS)))
    recorded = json.loads((ROOT / "tests" / "solver" / "fingerprints.json").read_text())
    differ = {}
    for key in sorted(set().union(*found.values())):
        values = {target: digests.get(key) for target, digests in found.items()}
        expected = recorded.get(key.removeprefix("trajectory/"), values["host"])
        if key.startswith("trajectory/"):
            expected = expected[:16]
        if any(v != expected for v in values.values()):
            differ[key] = values
    assert not differ, "differ between targets: " + json.dumps(differ, indent=1)
