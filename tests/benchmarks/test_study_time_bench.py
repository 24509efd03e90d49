"""benchmarks/study_time.py times what it says: a fresh process of the command line, each line
with its arrival time, the load then and the processor time so far, and a table with a row per
run (no time is asserted)."""

import os

from .conftest import load_benchmark as load


def test_a_run_is_timed_from_outside_line_by_line():
    bench = load("study_time")
    run = bench.timed(["--version"], dict(os.environ), os.getcwd())
    assert run["rc"] == 0 and run["wall"] > 0 and run["cpu"] >= 0
    assert run["lines"][0][2].startswith("grainview 0.")
    seconds, stream, _, load_then, cpu = run["lines"][0]
    assert 0 < seconds <= run["wall"] and stream == "out" and load_then >= 0 and cpu >= 0
    assert len(run["load_start"].split("/")) == 3


def test_the_table_has_a_row_per_run_and_leaves_progress_lines_out():
    bench = load("study_time")
    lines = [(1.0, "out", "estimate: the study ~12 min of wall time (compiling ~2 min)", 3.0, 0.5),
             (2.0, "out", "pentagons: biaxial test: step 120 of at most 300, 1 min", 3.0, 1.0),
             (3.0, "err", "pentagons: warning: something", 3.0, 2.0)]
    results = {"study-warm": {"wall": 100.0, "cpu": 60.0, "lines": lines, "load_start": "3.0/2.0/1.0",
                              "load_mean": 3.5, "rc": 0}}
    text = bench.table(results, "--jobs 1", "abc1234")
    assert "| study-warm | 1.7 min | 60 s | 1.0 s | 3.0/2.0/1.0 / 3.5 (" in text and "| ~12 min | 0 |" in text
    assert "step 120 of at most" not in text and "! pentagons: warning: something" in text
    assert "Code measured: abc1234; the study's options: `--jobs 1`." in text


def test_the_processor_time_of_a_process_tree_counts_this_process():
    bench = load("study_time")
    sum(i * i for i in range(200_000))
    assert bench.tree_cpu(os.getpid()) > 0
