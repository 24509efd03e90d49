"""The main job at a tiny size: `grainview study` simulates pentagons and disks, writes every
figure and a table whose values equal the accessors' own."""

import numpy as np
import pandas as pd
import pytest

import grainview
from grainview.app.cli import main
from grainview.plot import FIGURES
from grainview.app.report import FIGURE_NAMES, NOT_REACHED, PER_RUN_FIGURES, POLYGON_FIGURES, convergence_text
from grainview.analysis.strain import residual_window

WINDOW = 0.003
"""A residual window the tiny runs reach (they stop near eps_q ~0.008)."""


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    assert main(["study", "--out", str(out), "--particles", "30", "--strain", "0.004", "--every", "10",
                 "--residual-strain", str(WINDOW), "--progress", "off"]) == 0
    return out


def test_every_figure_file_exists(study):
    figures = study / "report" / "figures"
    for number in FIGURES:
        labels = ["pentagons"] if number in POLYGON_FIGURES else ["pentagons", "disks"]
        stems = ([f"fig{number}_{FIGURE_NAMES[number]}_{label}" for label in labels]
                 if number in PER_RUN_FIGURES else [f"fig{number}_{FIGURE_NAMES[number]}"])
        for stem in stems:
            for suffix in (".png", ".pdf"):
                path = figures / (stem + suffix)
                assert path.exists() and path.stat().st_size > 1000, path


def test_table_equals_the_accessors(study):
    table = pd.read_csv(study / "report" / "headline.csv", index_col=0)
    for label in ("pentagons", "disks"):
        ds = grainview.open_dataset(study / f"{label}.nc", validate=True)
        late = np.flatnonzero(residual_window(ds, WINDOW).values)
        assert 0 < late.size < ds.sizes["time"]
        res = ds.isel(time=late)
        column = pd.to_numeric(table[f"{label} (this run)"], errors="coerce")
        assert column["q/p (residual)"] == pytest.approx(float(res.grain.stress_invariants()["q_over_p"].mean()), rel=1e-12)
        assert column["z (residual)"] == pytest.approx(float(res.grain.coordination()["z"].mean()), rel=1e-12)
        assert column["a (residual)"] == pytest.approx(float(res.grain.fabric_anisotropy()["a"].mean()), rel=1e-12)
        assert column["solid fraction (initial)"] == pytest.approx(float(ds.grain.solid_fraction()[0]), rel=1e-12)
        prop = res.grain.contact_proportions().mean("time")
        assert column["weak fraction"] == pytest.approx(float(prop["weak_fraction"]), rel=1e-12)
        assert column["k_s"] == pytest.approx(float(prop["k_s"]), rel=1e-12)
        assert column["k_d"] == pytest.approx(float(prop["k_d"]), rel=1e-12)
        # the study writes near pairs, and the table counts those within 1% of d_min too
        gap = 0.01 * 2 * float(ds.radius.min())
        assert column["z, near pairs (residual)"] == pytest.approx(
            float(res.grain.coordination(near=gap)["z"].mean()), rel=1e-12)
        # counting near pairs adds contacts to every snapshot, never removes one
        counted = res.grain.contact_proportions(near=gap)["n_contacts"].values
        assert np.all(counted >= res.grain.contact_proportions()["n_contacts"].values)
        q_d = res.grain.stress_invariants(kind="double")["q_over_p"].mean()
        assert column["q_d/p"] == pytest.approx(float(q_d), rel=1e-12)
    # the CSV holds numbers only; the prose is in the Markdown table
    assert all(dtype.kind == "f" for dtype in table.dtypes)
    assert table.loc["q/p (residual)", "pentagons (paper)"] == 0.35
    assert table.loc["particles", "pentagons (this run)"] == 30  # the description rows as numbers
    assert table.loc["particles", "pentagons (paper)"] == 14400
    assert table.loc["residual window snapshots", "disks (this run)"] == late.size
    md = (study / "report" / "headline.md").read_text()
    assert "| particles | 30 5-gons | 14400 | 30 disks | 10000 |" in md
    assert "| preparation | paper |" in md
    assert f"| residual window | eps_q {WINDOW:.2f}"[:30] in md


def test_the_report_index_lists_every_figure_and_the_runs(study):
    index = (study / "report" / "index.md").read_text()
    figures = sorted((study / "report" / "figures").glob("*.png"))
    assert len(figures) > 20
    for path in figures:
        assert f"](figures/{path.name})" in index, path.name
    assert index.count("**Fig. ") == len(figures)
    for label in ("pentagons", "disks"):
        assert f"### {label}" in index and f"{label}.nc" in index
    assert "30 particles (30 5-gons)" in index and "sigma0 10 kPa" in index
    # each run's NLGS convergence, as its file records it, in the index and under the headline table
    headline = (study / "report" / "headline.md").read_text()
    for label in ("pentagons", "disks"):
        with grainview.open_dataset(study / f"{label}.nc") as ds:
            text = convergence_text(ds)
        assert text.startswith("NLGS convergence: ") and f"- {text}" in index and f"**{label}.** {text}" in headline


def test_a_run_short_of_the_residual_window_reports_not_reached(study, tmp_path):
    paths = [str(study / f"{label}.nc") for label in ("pentagons", "disks")]
    out = tmp_path / "report"
    assert main(["report", *paths, "--labels", "pentagons,disks", "--out", str(out), "--movie",
                 "--movie-every", "4"]) == 0  # window 0.3
    for label in ("pentagons", "disks"):  # --movie: one GIF per run
        from PIL import Image

        with Image.open(out / f"force_chains_{label}.gif") as gif:
            assert gif.n_frames >= 2
    table = pd.read_csv(out / "headline.csv", index_col=0)
    md = (out / "headline.md").read_text()
    for label in ("pentagons", "disks"):
        column = table[f"{label} (this run)"]
        assert np.isnan(column["q/p (residual)"]) and np.isnan(column["z (residual)"])
        assert 2 < column["z (initial)"] < 5  # initial values are still reported
    assert "| q/p (residual) | not reached | 0.350 | not reached | 0.280 |" in md
    assert f"| residual window | {NOT_REACHED}" in md
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


def test_report_draws_only_the_figures_asked_for_and_the_index_lists_those(study, tmp_path, capsys):
    files = [str(study / "pentagons.nc"), str(study / "disks.nc")]
    out = tmp_path / "some"
    assert main(["report", *files, "--labels", "pentagons,disks", "--out", str(out), "--figures", "3,13,6a",
                 "--residual-strain", str(WINDOW)]) == 0
    drawn = sorted(p.name for p in (out / "figures").glob("*.png"))
    assert drawn == ["fig03_q_over_p.png", "fig06a_coordination.png", "fig13_force_chains_disks.png",
                     "fig13_force_chains_pentagons.png"]
    index = (out / "index.md").read_text()
    assert index.count("**Fig. ") == 4 and "fig14_" not in index
    # the whole report's Fig. 3 and this one come from the same data: the same headline table
    assert (out / "headline.csv").read_text() == (study / "report" / "headline.csv").read_text()
    capsys.readouterr()
    assert main(["report", *files, "--out", str(tmp_path / "bad"), "--figures", "3,99"]) == 2
    assert "figures='99': expected paper figure numbers among 02, 03" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
