"""What ``grainview study`` and ``grainview run`` say of their time and steps: whether numba's
cache holds the kernels for this processor (grainview.app.warmup.cache_holds), and a resumed
test's unconverged steps in one line."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import warnings

import pytest

from grainview.app.cli import _study_sample, _warnings_as_notes, main
from grainview.contract.errors import ConvergenceWarning
from solver.parameters import BiaxialTest
from solver.preparation import preparation

KERNEL = """
import numba

@numba.njit(cache=True)
def twice(x):
    return 2.0 * x
"""


def _held(folder, cache, *, call=False, cpu=None):
    """In a fresh process with NUMBA_CACHE_DIR=cache: whether the cache holds the tiny kernel of
    ``folder``/tiny_kernel.py (calling it first when ``call``: compiles it into the cache)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(folder)}
    env.pop("NUMBA_CPU_NAME", None)
    env.pop("NUMBA_CPU_FEATURES", None)
    if cpu:
        env["NUMBA_CPU_NAME"] = cpu
    code = ("import tiny_kernel\nfrom grainview.app.warmup import cache_holds\n"
            + ("tiny_kernel.twice(1.0)\n" if call else "") + "print(cache_holds(tiny_kernel.twice))")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return done.stdout.strip()


def test_the_cache_check_sees_a_kernel_compiled_for_this_processor_only(tmp_path):
    (tmp_path / "tiny_kernel.py").write_text(textwrap.dedent(KERNEL))
    cache = tmp_path / "cache"
    assert _held(tmp_path, cache) == "False"  # an empty cache
    assert _held(tmp_path, cache, call=True) == "True"  # compiled in this process
    assert _held(tmp_path, cache) == "True"  # the next process finds it
    assert _held(tmp_path, cache, cpu="generic") == "False"  # made for another target: does not count
    (tmp_path / "tiny_kernel.py").write_text(textwrap.dedent(KERNEL) + "\n# edited\n")
    assert _held(tmp_path, cache) == "False"  # its source changed


def test_the_cache_check_on_an_empty_cache_finds_every_kernel_cold(tmp_path):
    code = ("import json\nfrom grainview.app.warmup import cache_state, cold_shares\n"
            "print(json.dumps([cache_state(), {g: s for g, (s, _) in cold_shares().items()}]))")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    import json

    state, shares = json.loads(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                              check=True).stdout)
    assert state["kernels"] > 50 and len(state["cold"]) == state["kernels"] and not state["unknown"]
    assert not any(name.startswith("solver.two_level.") for name in state["cold"])  # no run calls them
    assert shares == {"solver": 1.0, "analysis": 1.0}


def test_an_unreadable_cache_is_unknown_not_an_error():
    from grainview.app.warmup import cache_holds

    class Odd:  # what another numba's dispatcher might look like
        signatures = ()

    assert cache_holds(Odd()) is None


def test_a_resumed_test_sums_up_its_unconverged_steps_in_one_line(tmp_path, monkeypatch, capsys):
    from solver.engine import ContactDynamics

    path = tmp_path / "pentagons.nc"
    assert main(["run", "--shape", "pentagon", "--particles", "24", "--strain", "0.002", "--out", str(path),
                 "--progress", "off", "--no-compress"]) == 0
    capsys.readouterr()

    def resume(self, path, progress=None, compress=True):  # three unconverged steps and another warning
        for k in range(3):
            warnings.warn(f"step {k}: the NLGS stopped at its sweep cap", ConvergenceWarning)
        warnings.warn("something else", UserWarning)
        return 3

    monkeypatch.setattr(ContactDynamics, "resume", resume)
    prep = preparation("paper", particles=24, shape="pentagon")
    with _warnings_as_notes():
        _study_sample("pentagons", prep, path, "partial", tmp_path / "c.nc", test=BiaxialTest(strain=0.002),
                      near_contacts=True, overwrite=False, progress=False)
    captured = capsys.readouterr()
    assert "NLGS stopped" not in captured.out  # no line per step
    assert [line for line in captured.out.splitlines() if line.startswith("note:")] == ["note: something else"]
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pentagons: warning: the contact solver (")
    assert "did not converge in 3 of the resumed test's steps; in the whole test " in err[0]
    assert "pentagons: resumed for 3 steps" in captured.out


@pytest.mark.slow
def test_after_a_warm_up_the_cache_check_finds_every_kernel(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}
    subprocess.run([sys.executable, "-m", "grainview", "warmup"], env=env, capture_output=True, check=True)
    code = "from grainview.app.warmup import cache_state; s = cache_state(); print(s['cold'], s['unknown'])"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[] []", done.stdout  # every kernel the warm-up compiles, RESEARCH_MODULES' apart
