"""What the report, export, ensemble, demo and warmup commands print and write: tables that fit
the terminal, the same 'not reached' everywhere, CSV columns that say what they hold, paths
that resolve, help that gives every default, and a warm numba cache."""

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import grainview
from grainview.app.cli import build_parser, main
from grainview.contract.dataset import netcdf_encoding
from grainview.datasets import harmonic_series

from .test_near_contacts import chain

ROOT = Path(__file__).resolve().parents[2]


def _write(ds, path):
    ds.to_netcdf(path, encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    return path


def _seeds(tmp_path, n=2, shape="pentagon"):
    paths = []
    for seed in range(n):
        ds = harmonic_series(n_snapshots=3, n_contacts=100, seed=seed)
        ds.attrs.update(preparation_seed=np.int32(seed), preparation_shape=shape)
        paths.append(_write(ds, tmp_path / f"{shape[0]}_s{seed}.nc"))
    return paths


# 13. terminal tables ---------------------------------------------------------------------

def _wide_table():
    values = {"q/p (residual)": 0.123456789012, "z (residual)": 3.987654321098, "particles": "400 5-gons",
              "preparation": "geometric construction, isotropic compaction at 10 kPa",
              "residual window": "not reached: eps_q >= 0.3 wanted, run ends at 0.147"}
    columns = {f"{label} ({what})": values for label in ("pentagons", "disks") for what in ("this run", "paper")}
    return pd.DataFrame(columns)


@pytest.mark.parametrize("width", [60, 80, 237])
def test_terminal_table_fits_the_width_and_rounds_as_the_markdown(width):
    from grainview.app.table_text import terminal_table

    text = terminal_table(_wide_table(), width=width)
    lines = text.splitlines()
    assert max(map(len, lines)) <= width
    assert "0.123" in text and "0.1234" not in text and "3.988" in text and "3.9876" not in text
    for column in _wide_table().columns:  # every column is shown, with its header
        assert column in text.replace("\n", " ") or all(word in text for word in column.split())
    # every word of the long cells survives the wrapping
    for word in "geometric construction, isotropic compaction at 10 kPa".split():
        assert word in text


def test_report_and_study_print_the_table_fitted_to_the_terminal(tmp_path, monkeypatch, capsys):
    import grainview.app.report as report

    monkeypatch.setenv("COLUMNS", "80")
    monkeypatch.setattr(report, "write_report", lambda runs, out, **kw: {"table": _wide_table(), "files": []})
    path = _write(harmonic_series(n_snapshots=2, n_contacts=20), tmp_path / "a.nc")
    assert main(["report", str(path), "--out", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    table = [line for line in out.splitlines() if not line.startswith("wrote ")]  # the path line is a path
    assert len(table) > 5 and max(map(len, table)) <= 80
    assert "0.123" in out and "0.1234" not in out


# 14. the ensemble command's report -----------------------------------------------------

def test_ensemble_report_says_not_reached_as_study_and_report_do(tmp_path, capsys):
    paths = _seeds(tmp_path)
    assert main(["report", "--ensemble", *map(str, paths), "--residual-strain", "5", "--out", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    md = (tmp_path / "r" / "headline.md").read_text()
    for row in ("q/p (residual)", "z (residual)", "a (residual)", "weak fraction"):
        assert f"| {row} | not reached (0 of 2 seeds reach eps_q >= 5) |" in md, row
    assert "not reached" in out
    # a run's initial values are still there
    runs = pd.read_csv(tmp_path / "r" / "runs.csv", index_col=0)
    assert runs["z (initial)"].notna().all() and runs["q/p (residual)"].isna().all()


def test_ensemble_report_counts_the_seeds_short_of_the_window(tmp_path):
    from grainview.analysis.ensemble import open_ensemble
    from grainview.app.ensemble_report import ensemble_table, format_table

    paths = _seeds(tmp_path)
    with grainview.open_dataset(paths[1]) as ds:
        short = ds.isel(time=slice(0, 2)).load()  # stops at eps_q ~0.07
    _write(short, tmp_path / "short.nc")
    ens = open_ensemble([paths[0], tmp_path / "short.nc"])
    stats, runs = ensemble_table(ens, residual_strain=0.1)
    text = format_table(stats, runs, residual_strain=0.1).iloc[:, 0]
    q = runs["q/p (residual)"].dropna()
    assert list(runs["residual window reached"]) == [True, False] and len(q) == 1
    assert text["q/p (residual)"] == f"{q.iloc[0]:.3f} (1 seed; 1 not reached)"
    assert text["z (initial)"].endswith("(2 seeds)")  # initial rows count both


def test_ensemble_refuses_to_replace_its_report_before_any_run(tmp_path, monkeypatch, capsys):
    import grainview.app.ensemble

    report = tmp_path / "ens" / "report"
    report.mkdir(parents=True)
    (report / "headline.csv").write_text("mine")

    def no_work(*args, **kwargs):
        raise AssertionError("ran before refusing")
    monkeypatch.setattr(grainview.app.ensemble, "run_ensemble", no_work)
    assert main(["ensemble", "--out", str(tmp_path / "ens"), "--seeds", "1", "--progress", "off"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("grainview: error:") and "--overwrite-report" in err
    assert (report / "headline.csv").read_text() == "mine"


def test_ensemble_replaces_its_report_when_asked_and_keeps_the_runs(tmp_path, monkeypatch, capsys):
    import grainview.app.ensemble

    paths = _seeds(tmp_path)
    report = tmp_path / "ens" / "report"
    report.mkdir(parents=True)
    (report / "headline.csv").write_text("mine")
    calls = []

    def finished(specs, folder, **kwargs):  # every run already finished: nothing redone
        calls.append(kwargs["overwrite"])
        return [{"path": str(p)} for p in paths]
    monkeypatch.setattr(grainview.app.ensemble, "run_ensemble", finished)
    argv = ["ensemble", "--out", str(tmp_path / "ens"), "--seeds", "2", "--progress", "off", "--residual-strain", "0"]
    assert main([*argv, "--overwrite-report"]) == 0
    assert calls == [False]  # the runs' files are kept
    stats = pd.read_csv(report / "headline.csv", header=[0, 1], index_col=0)
    assert stats.loc["q/p (residual)", ("pentagon", "n")] == 2
    assert "(2 seeds)" in capsys.readouterr().out


# 16. CSV export and headline.csv -------------------------------------------------------

def test_csv_export_flags_the_pairs_without_force_and_names_kinds_and_units(tmp_path):
    from grainview.export import write_csv

    ds = chain()
    kind = ds["kind"].values.copy()
    kind[0, :4] = [1, 2, 1, 2]
    ds["kind"] = ds["kind"].copy(data=kind)
    table = pd.read_csv(write_csv(ds, tmp_path))
    assert list(table["loaded"]) == [True, True, False, False]  # f_n = 5, 3, 0, 0 N
    assert list(table["kind"]) == ["simple", "double", "simple", "double"]
    assert list(table["fn_N"]) == [5.0, 3.0, 0.0, 0.0] and list(table["gap_m"]) == [-1e-4, 0.0, 5e-4, 2e-3]
    for column in ("time_s", "ft_N", "point_x_m", "branch_y_m", "normal_x"):
        assert column in table.columns
    assert "fn" not in table.columns and "gap" not in table.columns


def test_export_refusal_names_the_flag_once(tmp_path, capsys):
    path = _write(chain(), tmp_path / "c.nc")
    assert main(["export", str(path), "--to", "csv", "--out", str(tmp_path / "csv")]) == 0
    assert "CSV export" in capsys.readouterr().err  # its progress bar
    assert main(["export", str(path), "--to", "csv", "--out", str(tmp_path / "csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("--overwrite") == 1 and err.count("\n") == 1


def test_headline_csv_holds_particles_seed_and_window_as_numbers(tmp_path):
    from grainview.app.report import headline_table, write_table

    ds = harmonic_series(n_snapshots=5, n_contacts=50, seed=3)  # eps_q 0 .. 0.147
    ds.attrs.update(preparation_seed=np.int32(3))
    table = headline_table({"disks": ds}, residual_strain=0.05)
    csv = write_table(table, tmp_path)[0]
    rows = {line.split(",")[0]: line.split(",")[1:] for line in csv.read_text().splitlines()}
    assert rows["particles"] == ["100", "10000"]
    assert rows["seed"] == ["3", ""]
    eps_q = grainview.analysis.strain.strains(ds)["eps_q"].values
    late = eps_q[eps_q >= 0.05]
    assert float(rows["residual window from eps_q"][0]) == pytest.approx(late.min(), rel=1e-12)
    assert float(rows["residual window to eps_q"][0]) == pytest.approx(late.max(), rel=1e-12)
    assert rows["residual window snapshots"][0] == str(late.size)
    loaded = pd.read_csv(csv, index_col=0)
    assert all(dtype.kind == "f" for dtype in loaded.dtypes)  # still loads as numbers
    assert loaded.loc["q/p (residual)", "disks (paper)"] == 0.28


# 17. demo, paper column, .gitignore, index paths, help ------------------------------------

def test_the_demo_series_has_a_true_solid_fraction_and_its_grains_in_the_box():
    ds = harmonic_series(n_snapshots=3, n_contacts=20000)  # the demo's size
    phi = ds.grain.solid_fraction().values
    area = np.pi * ds["radius"].values ** 2
    box = np.prod(ds["box_max"].values - ds["box_min"].values, axis=-1)
    np.testing.assert_allclose(phi, area.sum() / box, rtol=1e-12)
    assert np.all((0 < phi) & (phi < 1))
    r = ds["radius"].values[None, :, None]
    position = ds["position"].values
    assert np.all(position - r >= ds["box_min"].values[:, None, :])
    assert np.all(position + r <= ds["box_max"].values[:, None, :])


def test_info_on_the_demo_file_prints_a_solid_fraction_below_one(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--snapshots", "2", "--contacts", "20000"]) == 0
    capsys.readouterr()
    assert main(["info", str(tmp_path / "synthetic.nc")]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "solid fraction" in s)
    low, high = (float(v) for v in line.split("solid fraction")[1].split(".."))
    assert 0 < low <= high < 1


def test_a_run_labelled_freely_keeps_the_paper_column_of_its_shape():
    from grainview.app.report import PAPER, headline_table

    disks = harmonic_series(n_snapshots=2, n_contacts=20)
    table = headline_table({"run1": disks}, residual_strain=0.0)
    assert list(table.columns) == ["run1 (this run)", "run1 (paper: disks)"]
    assert table.loc["q/p (residual)", "run1 (paper: disks)"] == PAPER["disks"]["q/p (residual)"]
    pentagons = disks.assign(n_vertices=disks["n_vertices"] + 5)
    assert "run2 (paper: pentagons)" in headline_table({"run2": pentagons}, residual_strain=0.0).columns
    triangles = disks.assign(n_vertices=disks["n_vertices"] + 3)  # no sample of the paper
    assert list(headline_table({"run3": triangles}, residual_strain=0.0).columns) == ["run3 (this run)"]
    # a label that names the paper's sample still decides, as before
    assert "pentagons (paper)" in headline_table({"pentagons": pentagons}, residual_strain=0.0).columns


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="not a git checkout (an archive or an sdist)")
def test_default_output_folders_are_ignored_by_git():
    for path in ("study/pentagons.nc", "study/report/index.md", "report/headline.md", "ensemble/report/index.md",
                 "demo-out/harmonic_prediction.csv"):
        done = subprocess.run(["git", "check-ignore", "-q", path], cwd=ROOT)
        assert done.returncode == 0, path


def test_index_links_resolve_from_the_index_folder(tmp_path, monkeypatch):
    from grainview.app.report import write_index

    runs_dir = tmp_path / "runs"
    runs_dir.mkdir()
    path = _write(harmonic_series(n_snapshots=2, n_contacts=20), runs_dir / "a.nc")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out" / "report").mkdir(parents=True)
    with grainview.open_dataset("runs/a.nc") as ds:  # opened by a path relative to the working folder
        index = write_index({"a": ds}, Path("out") / "report", {})
    text = index.read_text()
    assert "[runs/a.nc](../../runs/a.nc)" not in text  # the link target is relative to index.md
    link = text.split("File: [")[1].split("](")[1].split(")")[0]
    assert (index.parent / link).resolve() == path.resolve()


def _options(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from ((f"{name} {o}", a) for o, a in _options(sub))
        elif action.option_strings and action.nargs != 0 and action.dest not in ("help", "version"):
            yield action.option_strings[-1], action


def test_every_option_states_its_default():
    missing = [name for name, action in _options(build_parser())
               if not action.required and "default" not in (action.help or "")]
    assert not missing, missing


def test_the_s1s2_preparation_is_explained_in_words():
    for command in ("study", "run"):
        help_text = " ".join(build_parser()._subparsers._group_actions[0].choices[command].format_help().split())
        assert "s1s2: the paper's two initial states" in help_text
        assert "disks compacted frictionless" in help_text


# 7. warm-up -----------------------------------------------------------------------------

def test_warmup_compiles_the_kernels_and_says_where_the_cache_is(capsys, monkeypatch):
    from grainview.app.warmup import kernels

    assert main(["warmup"]) == 0
    first = capsys.readouterr().out
    compiled = {name for name, dispatcher in kernels().items() if dispatcher.signatures}
    for name in ("solver.nlgs.solve", "solver.acceleration.solve_anderson", "solver.parallel_nlgs.solve_domains",
                 "solver.narrowphase._detect_kernel", "solver.broadphase._candidate_pairs_kernel",
                 "solver.packing._deposit_kernel", "solver.residuals.natural_maps",
                 "grainview.analysis._kernels.xi_network.count_below",
                 "grainview.analysis._kernels.network_topology.flag_persistence_1"):
        assert name in compiled, name
    cache = os.path.abspath(os.environ["NUMBA_CACHE_DIR"]) if os.environ.get("NUMBA_CACHE_DIR") else "__pycache__"
    assert cache in first and "[1/" in first
    started = time.perf_counter()
    assert main(["warmup"]) == 0
    assert time.perf_counter() - started < 30
    assert capsys.readouterr().out == first  # idempotent: the same lines


def test_warmup_refuses_a_cache_folder_it_cannot_write_in_one_line(tmp_path, monkeypatch, capsys):
    blocked = tmp_path / "a_file"
    blocked.write_text("not a folder")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocked))
    assert main(["warmup"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"grainview: error: NUMBA_CACHE_DIR={blocked}: cannot create the folder") and err.count("\n") == 1


@pytest.mark.slow
def test_warmup_fills_a_cold_cache_that_the_next_process_loads(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}
    command = [sys.executable, "-m", "grainview", "warmup"]
    times, outputs = [], []
    for _ in range(2):
        started = time.perf_counter()
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
        times.append(time.perf_counter() - started)
        outputs.append(done.stdout)
    assert outputs[0] == outputs[1] and str(tmp_path / "cache") in outputs[0]
    assert any((tmp_path / "cache").rglob("*.nbi"))
    assert times[1] < times[0] / 3
