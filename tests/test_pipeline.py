"""The main job at a tiny size: `grainview study` simulates pentagons and disks, writes every
figure and a table whose values equal the accessors' own."""

import numpy as np
import pandas as pd
import pytest

import grainview
from grainview.cli import main
from grainview.plot import FIGURES
from grainview.report import FIGURE_NAMES, MAP_FIGURES, POLYGON_FIGURES, residual_times


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    assert main(["study", "--out", str(out), "--particles", "30", "--strain", "0.004", "--every", "10",
                 "--progress", "off"]) == 0
    return out


def test_every_figure_file_exists(study):
    figures = study / "report" / "figures"
    for number in FIGURES:
        labels = ["pentagons"] if number in POLYGON_FIGURES else ["pentagons", "disks"]
        stems = ([f"fig{number}_{FIGURE_NAMES[number]}_{label}" for label in labels]
                 if number in MAP_FIGURES else [f"fig{number}_{FIGURE_NAMES[number]}"])
        for stem in stems:
            for suffix in (".png", ".pdf"):
                path = figures / (stem + suffix)
                assert path.exists() and path.stat().st_size > 1000, path


def test_table_equals_the_accessors(study):
    table = pd.read_csv(study / "report" / "headline.csv", index_col=0)
    for label in ("pentagons", "disks"):
        ds = grainview.open_dataset(study / f"{label}.nc", validate=True)
        late = np.flatnonzero(residual_times(ds).values)
        res = ds.isel(time=late)
        column = table[f"{label} (this run)"].astype(float)
        assert column["q/p (residual)"] == pytest.approx(float(res.grain.stress_invariants()["q_over_p"].mean()), rel=1e-12)
        assert column["z (residual)"] == pytest.approx(float(res.grain.coordination()["z"].mean()), rel=1e-12)
        assert column["a (residual)"] == pytest.approx(float(res.grain.fabric_anisotropy()["a"].mean()), rel=1e-12)
        assert column["solid fraction (initial)"] == pytest.approx(float(ds.grain.solid_fraction()[0]), rel=1e-12)
        prop = res.grain.contact_proportions().mean("time")
        assert column["weak fraction"] == pytest.approx(float(prop["weak_fraction"]), rel=1e-12)
        assert column["k_s"] == pytest.approx(float(prop["k_s"]), rel=1e-12)
    assert table.loc["q/p (residual)", "pentagons (paper)"] == "0.35"
    md = (study / "report" / "headline.md").read_text()
    assert md.startswith("| quantity | pentagons (this run) |")


def test_run_refuses_to_overwrite(tmp_path, capsys):
    path = tmp_path / "x.nc"
    path.write_bytes(b"keep")
    assert main(["run", "--particles", "10", "--out", str(path)]) == 2
    assert "--overwrite" in capsys.readouterr().err and path.read_bytes() == b"keep"


def test_report_refuses_to_overwrite_an_existing_report(study, capsys):
    files = [str(study / "pentagons.nc"), str(study / "disks.nc")]
    before = (study / "report" / "headline.csv").read_bytes()
    assert main(["report", *files, "--out", str(study / "report")]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert (study / "report" / "headline.csv").read_bytes() == before
