"""The throughput benchmarks of the force chains, coarse-grained fields and force-network topology
refuse an argument they do not take in one line, before measuring anything or rewriting their
results (``--help`` ran the whole benchmark and rewrote its file under benchmarks/results/)."""

import os
import subprocess
import sys

import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
RESULTS = {"force_chains": "force-chains.md", "coarse_graining": "coarse-graining.md",
           "network_topology": "network-topology.md"}


def run_script(name, *args):
    return subprocess.run([sys.executable, "-m", f"benchmarks.{name}", *args], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)


@pytest.mark.parametrize("name", sorted(RESULTS))
def test_help_and_unknown_arguments_measure_nothing(name):
    results = os.path.join(ROOT, "benchmarks", "results", RESULTS[name])
    before = os.stat(results).st_mtime_ns
    shown = run_script(name, "--help")
    assert shown.returncode == 0 and shown.stdout.startswith("usage:") and "--" in shown.stdout
    refused = run_script(name, "--frobnicate")
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr.strip().splitlines()[-1].endswith("unrecognized arguments: --frobnicate")
    assert "Traceback" not in refused.stderr
    assert os.stat(results).st_mtime_ns == before


def test_repeats_must_be_a_positive_integer():
    for bad in ("0", "two"):
        refused = run_script("network_topology", "--repeats", bad)
        assert refused.returncode == 2 and "--repeats" in refused.stderr.strip().splitlines()[-1]
        assert "Traceback" not in refused.stderr
