"""The command line: one clear line per user error, and the demo main job."""

import numpy as np
import pandas as pd
import pytest

import grainview
from grainview.cli import main
from grainview.synthetic import harmonic_series


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


def test_info_prints_summary_and_validates(tmp_path, capsys):
    ds = harmonic_series(n_snapshots=2, n_contacts=50)
    path = tmp_path / "s.nc"
    ds.to_netcdf(path, encoding=grainview.schema.netcdf_encoding(ds))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "2 snapshots, 100 particles" in out and "valid" in out


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
