"""The command line: one clear line per user error, and the demo main job."""

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import grainview
from grainview.app.cli import main
from grainview.datasets import harmonic_series
from grainview.contract.writer import is_compressed


def test_demo_writes_a_valid_file_and_a_table_equal_to_the_accessors(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--snapshots", "3", "--contacts", "2000"]) == 0
    ds = grainview.open_dataset(tmp_path / "synthetic.nc", validate=True)
    table = pd.read_csv(tmp_path / "harmonic_prediction.csv", index_col="time")
    np.testing.assert_allclose(table["q_over_p"], ds.grain.stress_invariants()["q_over_p"].values, rtol=1e-12)
    np.testing.assert_allclose(table["prediction"], ds.grain.harmonic_prediction()["prediction"].values, rtol=1e-12)
    assert "harmonic prediction" in capsys.readouterr().out
    # a second run refuses to overwrite
    assert main(["demo", "--out", str(tmp_path), "--snapshots", "3", "--contacts", "2000"]) == 2
    assert "--overwrite" in capsys.readouterr().err
    # written compressed by default; --no-compress keeps netCDF-3, read the same
    packed = ds.load()
    ds.close()
    assert is_compressed(tmp_path / "synthetic.nc")
    assert main(["demo", "--out", str(tmp_path), "--snapshots", "3", "--contacts", "2000", "--overwrite",
                 "--no-compress"]) == 0
    assert not is_compressed(tmp_path / "synthetic.nc")
    with grainview.open_dataset(tmp_path / "synthetic.nc", chunks=None) as plain:
        xr.testing.assert_identical(plain, packed)


def test_demo_says_where_it_writes_and_replaces_neither_file_without_overwrite(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # the default folder is demo-out in the current folder
    assert main(["demo", "--snapshots", "2", "--contacts", "50"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "demo: writing demo-out/synthetic.nc and demo-out/harmonic_prediction.csv ..."
    assert out[1].startswith("wrote demo-out/synthetic.nc and demo-out/harmonic_prediction.csv; q/p against")
    assert sorted(p.name for p in (tmp_path / "demo-out").iterdir()) == ["harmonic_prediction.csv", "synthetic.nc"]
    # the table alone is enough to refuse, before anything is written
    (tmp_path / "demo-out" / "synthetic.nc").unlink()
    table = (tmp_path / "demo-out" / "harmonic_prediction.csv").read_text()
    assert main(["demo", "--snapshots", "2", "--contacts", "50"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == ("grainview: error: demo-out/harmonic_prediction.csv exists; pass --overwrite to replace "
                            "it\n")
    assert not (tmp_path / "demo-out" / "synthetic.nc").exists()
    assert (tmp_path / "demo-out" / "harmonic_prediction.csv").read_text() == table
    assert main(["demo", "--snapshots", "2", "--contacts", "50", "--overwrite"]) == 0
    assert (tmp_path / "demo-out" / "synthetic.nc").exists()


def test_info_prints_summary_and_validates(tmp_path, capsys):
    ds = harmonic_series(n_snapshots=2, n_contacts=50)
    path = tmp_path / "s.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "100 particles" in out and "2 snapshots" in out and "valid" in out
    assert "grainview_schema_version" not in out
    assert main(["info", str(path), "--attrs"]) == 0
    assert "grainview_schema_version = " in capsys.readouterr().out


def test_errors_are_one_line_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.nc"
    bad.write_text("nope")
    assert main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("grainview: error:") and "Traceback" not in err


def test_harmonic_series_grows_its_anisotropy():
    ds = harmonic_series(n_snapshots=3, n_contacts=20000, anisotropy=(0.3, 0.4, 0.2), seed=1)
    fab = ds.grain.fabric_anisotropy()["a"].values
    assert fab[0] == pytest.approx(0.0, abs=0.03) and fab[-1] == pytest.approx(0.3, abs=0.03)


def test_physics_options_reach_the_solver_and_act(tmp_path, capsys):
    """--friction, --wall-friction, --sigma0, --time-step, --tolerance, --acceleration and --stall-sweeps are
    recorded in the file and obeyed: no contact exceeds its Coulomb cone, some slide on it, and
    the lateral stress is the requested sigma0."""
    path = tmp_path / "run.nc"
    argv = ["run", "--shape", "disk", "--particles", "30", "--strain", "0.01", "--every", "20",
            "--friction", "0.2", "--wall-friction", "0.1", "--sigma0", "5000", "--time-step", "4e-4",
            "--tolerance", "1e-5", "--acceleration", "anderson", "--stall-sweeps", "300", "--out", str(path),
            "--progress", "off"]
    assert main(argv) == 0
    with grainview.open_dataset(path, chunks=None) as ds:
        attrs = ds.attrs
        assert attrs["solver_friction"] == 0.2 and attrs["preparation_friction"] == 0.2
        assert attrs["solver_wall_friction"] == 0.1
        assert attrs["solver_time_step"] == 4e-4 and attrs["solver_tolerance"] == 1e-5
        assert attrs["solver_solver"] == "anderson" and attrs["solver_stall_sweeps"] == 300  # --acceleration: its old name
        assert attrs["sigma0_Pa"] == 5000.0
        used = ds.kind.values > 0
        wall = ds.j.values >= ds.sizes["particle"]
        ratio = np.abs(ds.ft.values) / np.maximum(ds.fn.values, 1e-300)
        for mu, which in ((0.2, used & ~wall), (0.1, used & wall)):
            assert ratio[which].max() <= mu * (1 + 1e-9)
            assert (ratio[which] > 0.99 * mu).mean() > 0.1  # sliding contacts exist at this friction
        sigma_xx = ds.grain.stress_tensor().sel(xy_a="x", xy_b="x")
        assert abs(float(sigma_xx.mean()) / 5000.0 - 1) < 0.2
        eps_1 = float(ds.grain.strains()["eps_1"][-1])
    assert is_compressed(path)  # a finished run is kept compressed
    capsys.readouterr()
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"strain reached: eps_1 {eps_1:.3f}" in out and abs(eps_1 - 0.01) < 0.002
    assert "sigma0 5 kPa" in out and "friction 0.2 (walls 0.1)" in out and "time step 0.4 ms" in out


def test_bad_solver_option_is_one_line_before_simulating(tmp_path, capsys):
    assert main(["run", "--particles", "10", "--time-step", "-1", "--out", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "time_step=-1.0" in err and "positive number of seconds" in err
    assert not (tmp_path / "x.nc").exists()
    assert main(["run", "--particles", "10", "--stall-sweeps", "-5", "--out", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "stall_sweeps=-5" in err and "(0: no stall test)" in err
    assert not (tmp_path / "x.nc").exists()


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.startswith("grainview 0.")


def test_interruptions_exit_with_the_shells_codes(monkeypatch, capsys):
    """Ctrl-C -> 130, SIGTERM (solver.interrupt.Terminated, raised after a whole step) -> 143."""
    import grainview.app.cli as cli
    from solver.interrupt import Terminated

    for exc, code, text in ((KeyboardInterrupt(), 130, "interrupted"), (Terminated(), 143, "terminated (SIGTERM)")):
        def stopped(args, exc=exc):
            raise exc
        monkeypatch.setattr(cli, "_info", stopped)
        assert cli.main(["info", "whatever.nc"]) == code
        assert text in capsys.readouterr().err


@pytest.mark.parametrize("argv, fragment", [
    (["run", "--particles", "10", "--out", "{tmp}"], "is a folder"),
    (["run", "--particles", "10", "--out", "{tmp}/missing/run.nc"], "does not exist"),
    (["demo", "--snapshots", "0", "--out", "{tmp}/d"], "at least 2 snapshots"),
    (["demo", "--contacts", "-1", "--out", "{tmp}/d"], "at least 2 snapshots and 1 contact"),
    (["run", "--time-step", "1", "--out", "{tmp}/r.nc"], "contacts would be missed; expected time_step <= 0.25 s"),
    (["study", "--time-step", "0.02", "--velocity", "1", "--out", "{tmp}/s"], "the top wall of the test"),
    (["run", "--domains", "0", "--out", "{tmp}/r.nc"], "domains=0: expected an integer in 1..64"),
    (["ensemble", "--seeds", "0", "--out", "{tmp}/e"], "at least 1 seed"),
    (["ensemble", "--friction", "0.2,high", "--out", "{tmp}/e"], "comma-separated list of float"),
    (["ensemble", "--workers", "0", "--out", "{tmp}/e"], "at least 1 worker"),
    (["ensemble", "--workers", "2", "--scheduler", "tcp://x:1", "--out", "{tmp}/e"], "workers= applies to the local cluster"),
    (["ensemble", "--strain", "2", "--out", "{tmp}/e"], "vertical strain"),
    (["ensemble", "--shapes", "cube", "--out", "{tmp}/e"], "cube"),
    (["report", "--ensemble", "{tmp}/none*.nc", "--out", "{tmp}/r"], "no such file"),
])
def test_ordinary_mistakes_get_one_line_at_once(tmp_path, capsys, argv, fragment):
    import time

    start = time.perf_counter()
    assert main([a.format(tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert time.perf_counter() - start < 5  # refused before any compaction


def test_system_errors_are_one_line_and_a_closed_pipe_is_quiet(monkeypatch, capsys):
    import errno

    import grainview.app.cli as cli

    def full(args):
        raise OSError(errno.ENOSPC, "No space left on device", "run.nc")
    monkeypatch.setattr(cli, "_info", full)
    assert cli.main(["info", "x.nc"]) == 2
    assert capsys.readouterr().err.strip() == "grainview: error: No space left on device: run.nc"

    def closed(args):
        raise BrokenPipeError
    monkeypatch.setattr(cli, "_info", closed)
    assert cli.main(["info", "x.nc"]) == 141
    assert capsys.readouterr().err == ""


def test_library_advice_is_given_as_the_flag(monkeypatch, capsys):
    import grainview.app.cli as cli

    def lost_race(args):
        raise FileExistsError("run.nc exists; pass overwrite=True to replace it")
    monkeypatch.setattr(cli, "_info", lost_race)
    assert cli.main(["info", "run.nc"]) == 2
    assert capsys.readouterr().err.strip() == "grainview: error: run.nc exists; pass --overwrite to replace it"


def test_report_of_an_ensemble_shows_mean_and_spread(tmp_path, capsys):
    from grainview.contract.dataset import netcdf_encoding

    paths = []
    for seed in range(3):
        ds = harmonic_series(n_snapshots=4, n_contacts=200, seed=seed)
        ds.attrs.update(preparation_seed=np.int32(seed), preparation_shape="pentagon")
        paths.append(tmp_path / f"p_s{seed}.nc")
        ds.to_netcdf(paths[-1], encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    argv = ["report", "--ensemble", *map(str, paths), "--residual-strain", "0", "--out", str(tmp_path / "r")]
    assert main(argv) == 0
    stats = pd.read_csv(tmp_path / "r" / "headline.csv", header=[0, 1], index_col=0)["pentagon"]
    per_run = pd.read_csv(tmp_path / "r" / "runs.csv", index_col=0)
    q = per_run["q/p (residual)"].to_numpy()
    assert stats.loc["q/p (residual)", "std"] == pytest.approx(np.std(q, ddof=1), rel=1e-9)
    assert f"{q.mean():.3f} ± {np.std(q, ddof=1):.3f} (3 seeds)" in capsys.readouterr().out
    assert main(argv) == 2  # the report exists: refused without --overwrite


def test_info_reports_variables_without_units(tmp_path, capsys):
    from grainview.contract.dataset import netcdf_encoding

    ds = harmonic_series(n_snapshots=2, n_contacts=20)
    del ds["fn"].attrs["units"], ds["radius"].attrs["units"]
    path = tmp_path / "no_units.nc"
    ds.to_netcdf(path, encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    assert main(["info", str(path)]) == 0  # accepted: taken in the contract's units...
    out = capsys.readouterr().out
    assert "note: 2 variable(s) carry no units attribute" in out and "radius, " in out and "fn" in out  # ...and said


INFO_IMPORTS = """
import sys
from grainview.app.cli import main
assert main(["info", sys.argv[1]]) == 0
print(sorted(m for m in ("xarray", "dask", "pandas", "scipy") if m in sys.modules))
"""


def test_info_reads_the_file_without_xarray_and_says_what_the_accessors_say(tmp_path, capsys):
    """``info`` is fast because it imports neither xarray, dask nor pandas (checked in a fresh
    interpreter); its lines, computed from netCDF4 and the pure array functions, are those of
    the report's index, computed through the accessors (two computations of strain, solid
    fraction and q/p)."""
    import subprocess
    import sys

    from grainview.app.file_summary import describe_file
    from grainview.app.summary import describe

    path = tmp_path / "run.nc"
    ds = harmonic_series(n_snapshots=4, n_contacts=300, anisotropy=(0.2, 0.3, 0.1), seed=3)
    ds.attrs.update(scene="biaxial", sigma0_Pa=1e4, solver_friction=0.4, solver_time_step=5e-4)
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds))
    done = subprocess.run([sys.executable, "-c", INFO_IMPORTS, str(path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "[]"
    with grainview.open_dataset(path, chunks=None) as opened:
        expected = describe(opened)
        q_over_p = opened.grain.stress_invariants()["q_over_p"].values
    lines, attrs = describe_file(path)
    assert lines[:-1] == expected and attrs["sigma0_Pa"] == 1e4
    assert lines[-1].startswith("file: ") and f"({path.stat().st_size:,} bytes)" in lines[-1]  # info's own line
    assert f"last {q_over_p[-1]:.3f}" in lines[2] and q_over_p[-1] > 0.1
    assert "sigma0 10 kPa" in lines[3] and "time step 0.5 ms" in lines[4]


def test_info_checks_structure_at_once_and_every_value_with_check(tmp_path, capsys):
    import netCDF4

    ds = harmonic_series(n_snapshots=3, n_contacts=50)
    path = tmp_path / "s.nc"
    ds.to_netcdf(path, **grainview.contract.dataset.netcdf_options(ds, compress=False))
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["kind"][1, 3] = 7  # a value fault: the structure is intact
    assert main(["info", str(path)]) == 0
    assert "--check also checks every value" in capsys.readouterr().out
    assert main(["info", str(path), "--check"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("grainview: error:") and "kind: 1 occupied slot(s) with a kind other than 1" in err
    # a structural fault is found without --check
    bad = tmp_path / "bad.nc"
    ds.drop_vars("fn").to_netcdf(bad, **grainview.contract.dataset.netcdf_options(ds.drop_vars("fn")))
    assert main(["info", str(bad)]) == 2
    assert "variable 'fn' is missing" in capsys.readouterr().err
    # a netCDF-3 file cut in half: refused, one line
    cut = tmp_path / "cut.nc"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    assert main(["info", str(cut)]) == 2
    assert "truncated" in capsys.readouterr().err


def test_run_shear_shears_the_cell_at_the_biaxial_tests_pace(tmp_path, capsys):
    """`grainview run shear`: the compacted sample in its biperiodic cell, sheared to gamma =
    --strain at gamma_dot = 2 v / h0 (v the --velocity, h0 the compacted box's height: the
    biaxial test's pace in eps_q) under sigma_yy = sigma0."""
    path = tmp_path / "shear.nc"
    argv = ["run", "shear", "--shape", "disk", "--particles", "60", "--strain", "0.004", "--every", "20",
            "--velocity", "0.02", "--out", str(path), "--progress", "off"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "periodic simple shear to gamma = 0.004 at" in out
    with grainview.open_dataset(path, chunks=None) as ds:
        np.testing.assert_array_equal(ds.periodic.values, [1, 1])
        h0 = float(ds.cell.values[0, 1, 1])
        assert ds.attrs["scene"] == "shear"
        assert ds.attrs["cell_shear_rate_s"] == pytest.approx(2 * 0.02 / h0, rel=1e-12)
        assert float(ds.grain.strains()["gamma"][-1]) == pytest.approx(0.004, rel=0.03)  # gamma over h0; the height moves


def test_run_shear_refuses_a_solver_that_cannot_hold_the_cell_before_any_work(tmp_path, capsys):
    """Under a normal stress the cell's rate is swept with the contacts by NLGS or Anderson:
    --solver pcg is refused in one line before the compaction."""
    path = tmp_path / "shear.nc"
    assert main(["run", "shear", "--particles", "60", "--solver", "pcg", "--out", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "solver='pcg'" in err[0] and "anderson or nlgs" in err[0]
    assert not path.exists()


def test_study_shears_both_samples_in_their_cells_and_keeps_them_apart_from_biaxial_runs(tmp_path, capsys):
    """`grainview study --scene shear`: both samples sheared in their periodic cells to gamma =
    --strain; the same command again skips them; a biaxial study in the same folder is refused
    before any work (the files hold another run)."""
    out = tmp_path / "study"
    argv = ["study", "--scene", "shear", "--particles", "60", "--strain", "0.004", "--every", "20", "--no-report",
            "--jobs", "1", "--out", str(out), "--progress", "off"]
    assert main(argv) == 0
    for name in ("pentagons", "disks"):
        with grainview.open_dataset(out / f"{name}.nc", chunks=None) as ds:
            assert ds.attrs["scene"] == "shear"
            np.testing.assert_array_equal(ds.periodic.values, [1, 1])
            assert float(ds.grain.strains()["gamma"][-1]) == pytest.approx(0.004, rel=0.03)  # gamma over h0; the height moves
    capsys.readouterr()
    assert main(argv) == 0
    assert capsys.readouterr().out.count("is complete (skipped)") == 2
    biaxial = [a for a in argv if a not in ("--scene", "shear")]
    assert main(biaxial) == 2
    err = capsys.readouterr().err
    assert "holds another run (scene = shear" in err
