"""What ``grainview study`` and ``grainview run`` say of their time: whether numba's cache holds
the kernels for this processor (grainview.app.warmup.cache_holds), the first line on a cold
cache, the estimate's parts and its arithmetic under a given load
(grainview.app.paper_size.study_estimate), and a resumed test's unconverged steps in one line. No
time is measured here (benchmarks/study_time.py measures them)."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import warnings

import pytest

from grainview.app.cli import _warnings_as_notes, main
from grainview.app.estimates import compile_line as _compile_line
from grainview.app.estimates import print_estimate as _print_estimate
from grainview.app.study import study_sample as _study_sample
from grainview.contract.errors import ConvergenceWarning
from grainview.app import paper_size
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
    assert "solver.residuals.local_law_residuals" not in state["cold"]  # no run calls it (NOT_IN_RUNS)
    assert shares == {"solver": 1.0, "analysis": 1.0}


def test_an_unreadable_cache_is_unknown_not_an_error():
    from grainview.app.warmup import cache_holds

    class Odd:  # what another numba's dispatcher might look like
        signatures = ()

    assert cache_holds(Odd()) is None


def test_the_costs_are_the_measured_ones_at_the_measured_sizes_and_a_power_law_between():
    test = BiaxialTest()
    for shape, kind in (("pentagon", "pentagon"), ("disk", "disk")):
        small, large = paper_size.COSTS[(kind, "compaction")]
        shear_small, shear_large = paper_size.COSTS[(kind, "test")]
        prep = preparation("paper", particles=400, shape=shape)
        at_400 = paper_size.estimate(prep, test, 5e-4)
        assert at_400["compaction"][:2] == (small.steps, small.serial)
        assert at_400["test"][1] == shear_small.serial
        assert at_400["test"][2] == pytest.approx(prep.test_steps(5e-4, test.velocity, test.strain) * 400
                                                  * shear_small.serial * 1e-6)
        at_large = paper_size.estimate(preparation("paper", particles=14400, shape=shape), test, 5e-4, domains=2)
        assert at_large["compaction"][:2] == (large.steps, large.two_domains)
        assert at_large["test"][1] == shear_large.two_domains
        compacted_only = paper_size.estimate(preparation("paper", particles=14400, shape=shape), None, 5e-4, domains=2)
        assert compacted_only == {"compaction": at_large["compaction"]}  # a sample compacted only: no test
        n = 2400  # between: the power law through the two sizes
        between = paper_size.estimate(preparation("paper", particles=n, shape=shape), test, 5e-4)
        exponent = math.log(shear_large.serial / shear_small.serial) / math.log(14400 / 400)
        assert between["test"][1] == pytest.approx(shear_small.serial * (n / 400) ** exponent)
        assert "between 400" in between["test"][3]
        beyond = paper_size.estimate(preparation("paper", particles=4 * 14400, shape=shape), test, 5e-4)
        assert beyond["test"][1] == shear_large.serial  # outside: the nearer size's cost
        assert beyond["compaction"][0] == min(round(large.steps * 2), preparation(
            "paper", particles=4 * 14400, shape=shape).max_steps)  # its steps as sqrt(N)


def test_the_load_factor_is_the_fair_share_of_the_cores():
    assert paper_size.load_factor(2, 0.0, 2) == 1.0  # two processes on two idle cores
    assert paper_size.load_factor(1, 0.5, 2) == 1.0
    assert paper_size.load_factor(2, 5.2, 2) == pytest.approx(3.6)  # each gets 2 / 7.2 of a core
    assert paper_size.load_factor(1, 5.2, 2) == pytest.approx(3.1)


def _samples(particles=400):
    return {label: (preparation("paper", particles=particles, shape=shape), BiaxialTest())
            for label, shape in (("pentagons", "pentagon"), ("disks", "disk"))}


def test_the_study_estimate_adds_compiling_the_samples_and_the_report_each_under_its_load():
    samples = _samples()
    idle = paper_size.study_estimate(samples, 5e-4, jobs=2, load=0.0, cores=2)
    assert idle["idle"]["compile"] == 0.0 and idle["factor"] == {"compile": 1.0, "simulation": 1.0, "report": 1.0}
    per_sample = [sum(stage[2] for stage in paper_size.estimate(p, t, 5e-4).values()) for p, t in samples.values()]
    assert idle["idle"]["simulation"] == pytest.approx(max(per_sample))  # side by side
    seconds, particles = paper_size.REPORT_SECONDS
    assert idle["idle"]["report"] == pytest.approx(seconds * 800 / particles)
    assert idle["total"] == pytest.approx(max(per_sample) + seconds * 800 / particles)

    busy = paper_size.study_estimate(samples, 5e-4, jobs=2, compile_share={"solver": 1.0, "analysis": 0.5},
                                     load=5.2, cores=2)
    compile_idle = paper_size.COMPILE_SECONDS["solver"] + 0.5 * paper_size.COMPILE_SECONDS["analysis"]
    assert busy["idle"]["compile"] == pytest.approx(compile_idle)
    assert busy["factor"] == pytest.approx({"compile": 3.1, "simulation": 3.6, "report": 3.1})
    assert busy["total"] == pytest.approx(3.1 * compile_idle + 3.6 * max(per_sample) + 3.1 * seconds * 800 / particles)

    small = paper_size.study_estimate(_samples(20), 5e-4, load=0.0, cores=2)  # the report's figures cost the same
    assert small["idle"]["report"] == pytest.approx(seconds)
    paper = {"pentagons": (preparation("paper", particles=14400, shape="pentagon"), BiaxialTest()),
             "disks": (preparation("paper", particles=10000, shape="disk"), BiaxialTest())}
    assert paper_size.study_estimate(paper, 5e-4, load=0.0, cores=2)["idle"]["report"] == pytest.approx(
        seconds * 24400 / particles)  # in proportion to the particles

    one_after_the_other = paper_size.study_estimate(samples, 5e-4, jobs=1, report=False, load=0.0, cores=2)
    assert one_after_the_other["total"] == pytest.approx(sum(per_sample))
    assert one_after_the_other["processes"] == 1


def test_the_printed_estimate_names_the_load_and_the_parts(capsys):
    preps = {label: prep for label, (prep, _) in _samples().items()}
    tests = {label: test for label, (_, test) in _samples().items()}
    shares = {"solver": (1.0, ["solver.nlgs.solve"]), "analysis": (0.0, [])}
    _print_estimate(preps, tests, {}, 2, shares, report=True, load=(5.2, 2))
    lines = capsys.readouterr().out.splitlines()
    assert all(line.startswith("estimate: ") for line in lines)
    assert lines[-3].startswith("estimate: compiling 100% of the solver's kernels (not in numba's cache for this "
                                "processor) ~") and ", the report ~" in lines[-3]
    assert lines[-2].startswith("estimate: this machine is busy (load 5.2 on 2 cores)") and "~3.6x" in lines[-2]
    whole = paper_size.study_estimate({k: (preps[k], tests[k]) for k in preps}, 5e-4, jobs=2,
                                      compile_share={"solver": 1.0}, load=5.2, cores=2)
    assert lines[-1].startswith(f"estimate: the study ~{paper_size.hours(whole['total'])} of wall time (compiling ~")
    _print_estimate(preps, tests, {}, 2, {}, report=False, load=(0.0, 2))
    lines = capsys.readouterr().out.splitlines()
    assert "compiling" not in " ".join(lines) and "report" not in " ".join(lines)
    assert "the cores are free (load 0.0 on 2 cores)" in lines[-2]
    _print_estimate(preps, tests, {}, 2, {}, report=False, load=(0.3, 2))
    assert "this machine is lightly loaded (load 0.3 on 2 cores)" in capsys.readouterr().out  # 2.3 / 2


def test_the_compile_line_says_how_long_under_the_load():
    shares = {"solver": (1.0, ["a"]), "analysis": (0.0, [])}
    seconds = paper_size.COMPILE_SECONDS["solver"] * paper_size.load_factor(1, 5.2, 2)
    assert _compile_line("study", shares, (5.2, 2)) == (
        f"study: compiling the kernels, first run only, about {paper_size.hours(seconds)} (grainview warmup does "
        "it ahead of time)")
    assert _compile_line("study", {"solver": (0.0, []), "analysis": (0.0, [])}, (5.2, 2)) == ""


@pytest.mark.parametrize("command, then", [
    (["study", "--particles", "20", "--strain", "0.002", "--out", "study"], "estimate: "),
    (["run", "--particles", "20", "--strain", "0.002", "--out", "run.nc"], "run: compiling, stage [1/"),
])
def test_on_a_cold_cache_the_first_line_comes_before_any_compiling(tmp_path, command, then):
    cache = tmp_path / "cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "MPLBACKEND": "Agg"}
    proc = subprocess.Popen([sys.executable, "-m", "grainview", *command, "--progress", "off"], env=env, cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stdout.readline()
        compiled = list(cache.rglob("*.nbi")) if cache.exists() else []
        second = line = proc.stdout.readline()
        while line and not line.startswith(f"{command[0]}: compiling, stage "):
            line = proc.stdout.readline()
        proc.send_signal(signal.SIGTERM)  # while compiling: stopped at once, as after a whole step
        _, err = proc.communicate(timeout=300)
    finally:
        proc.kill()
        proc.communicate()
    assert first.startswith(f"{command[0]}: compiling the kernels, first run only, about ")
    assert first.rstrip().endswith("(grainview warmup does it ahead of time)")
    assert not compiled  # nothing compiled yet
    assert second.startswith(then)
    assert proc.returncode == 143 and err.strip().splitlines()[-1] == "grainview: terminated (SIGTERM)"


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
    assert done.stdout.strip() == "[] []", done.stdout  # every kernel a run calls: NOT_IN_RUNS' apart
