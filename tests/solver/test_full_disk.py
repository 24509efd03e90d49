"""A real full disk: a run writing onto a 256 KiB tmpfs ends with one line and exit code 2 —
not a segmentation fault — and leaves a valid file that, once space is freed, resumes to the
same snapshots as an uninterrupted run. Needs root to mount the tmpfs (skipped otherwise); the
simulated ENOSPC of tests/grainview covers the writer everywhere."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import grainview

RUN = ["run", "--shape", "disk", "--particles", "30", "--strain", "0.02", "--every", "10", "--progress", "off"]


def _mount(folder, size):
    folder.mkdir(exist_ok=True)
    opts = f"size={size}"
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(folder)], capture_output=True)
    return done.returncode == 0


@pytest.fixture
def tiny_disk(tmp_path):
    if not hasattr(os, "geteuid") or os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a small tmpfs needs root")
    folder = tmp_path / "tiny"
    if not _mount(folder, "256k"):
        pytest.skip("cannot mount a tmpfs here")
    yield folder
    subprocess.run(["umount", str(folder)], capture_output=True)


def test_full_disk_is_one_line_and_the_file_resumes_exactly(tiny_disk, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    target = tiny_disk / "run.nc"
    done = subprocess.run([sys.executable, "-m", "grainview", *RUN, "--out", str(target)],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 2, done.stderr[-2000:]  # not 139 (a segmentation fault)
    errors = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(errors) == 1 and "No space left on device" in errors[0] and "Traceback" not in done.stderr
    kept = grainview.open_dataset(target, chunks=None, validate=True)
    assert 0 < kept.sizes["time"]
    # more space, then resume: the same snapshots as a run that never stopped
    subprocess.run(["mount", "-o", "remount,size=16m", str(tiny_disk)], check=True)
    resumed = subprocess.run([sys.executable, "-m", "solver.restart", str(target), "--progress", "off"],
                             capture_output=True, text=True, env=env, timeout=600)
    assert resumed.returncode == 0, resumed.stderr[-2000:]
    whole = tmp_path / "whole.nc"
    subprocess.run([sys.executable, "-m", "grainview", *RUN, "--out", str(whole)], check=True,
                   capture_output=True, env=env, timeout=600)
    a, b = grainview.open_dataset(target, chunks=None), grainview.open_dataset(whole, chunks=None)
    assert a.sizes == b.sizes and a.sizes["time"] > kept.sizes["time"]
    for name in ("position", "angle", "fn", "ft", "i", "j", "step"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
