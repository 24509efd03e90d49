"""The notebooks run top to bottom (small sizes), as a user would run them, with the warnings
of grainview and the solver turned into errors: a notebook must not need to silence them. The
claims their text makes about their outputs are asserted by cells of the notebooks themselves,
so a run whose numbers no longer match the text fails here. The committed notebooks carry their
outputs (read without running), small enough to keep in the repository. With GRAINVIEW_STUDY naming
a folder of `grainview study`'s files, the notebooks that read them also run on them."""

import os
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).parent.parent
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
MAX_BYTES = 1_500_000


STRICT = """import warnings
for module in ("grainview", "solver"):
    warnings.filterwarnings("error", module=module)
import grainview
warnings.simplefilter("error", grainview.ConvergenceWarning)"""


def outputs(nb):
    return [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]


def text_of(nb):
    """Every stream and plain-text output, joined."""
    return "".join(o.get("text", "") + o.get("data", {}).get("text/plain", "") for o in outputs(nb))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path, monkeypatch):
    for name in ("GRAINVIEW_NB_PARTICLES", "GRAINVIEW_NB_STRAIN", "GRAINVIEW_NB_SEED", "GRAINVIEW_STUDY"):
        monkeypatch.delenv(name, raising=False)  # the default samples, whose ranges the text quotes; no study files in tmp_path
    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(STRICT))
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    errors = [o for o in outputs(nb) if o.get("output_type") == "error"]
    assert not errors, "\n".join(f"{o['ename']}: {o['evalue']}" for o in errors)
    assert len(outputs(nb)) >= 3
    if path.stem == "paper_figures":  # without the study's files it says so, and runs the small samples
        assert "no study files" in text_of(nb).lower()


STUDY_NOTEBOOKS = [p for p in NOTEBOOKS if "GRAINVIEW_STUDY" in p.read_text(encoding="utf-8")]


@pytest.mark.parametrize("path", STUDY_NOTEBOOKS, ids=[p.stem for p in STUDY_NOTEBOOKS])
def test_notebook_runs_on_the_study(path, tmp_path, monkeypatch):
    """The notebooks that read the study's files run on them and their checks hold: run when
    GRAINVIEW_STUDY names a folder with the files of `grainview study` (skipped otherwise)."""
    study = Path(os.environ.get("GRAINVIEW_STUDY") or tmp_path / "none")
    if not all((study / f"{label}.nc").is_file() for label in ("pentagons", "disks")):
        pytest.skip("GRAINVIEW_STUDY does not name a folder with the study's pentagons.nc and disks.nc")
    for name in ("GRAINVIEW_NB_PARTICLES", "GRAINVIEW_NB_STRAIN", "GRAINVIEW_NB_SEED"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("GRAINVIEW_STUDY", str(study.resolve()))
    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(STRICT))
    NotebookClient(nb, timeout=1200, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    errors = [o for o in outputs(nb) if o.get("output_type") == "error"]
    assert not errors, "\n".join(f"{o['ename']}: {o['evalue']}" for o in errors)
    assert "drawing from the study's files" in text_of(nb).lower()
    assert "does not hold" not in text_of(nb)


def test_there_are_notebooks():
    assert {p.stem for p in NOTEBOOKS} >= {"tutorial", "paper_figures", "lifetimes_and_maps"}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_stored_outputs(path):
    """A committed notebook was run once, top to bottom, and keeps its outputs (figures among them,
    no error), in a small file."""
    nb = nbformat.read(path, as_version=4)
    code = [cell for cell in nb.cells if cell.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1))
    assert [i for i, cell in enumerate(code[1:], start=1) if not cell.get("outputs")] == []  # all but the set-up
    assert not [o for o in outputs(nb) if o.get("output_type") == "error"]
    assert path.stat().st_size < MAX_BYTES
    images = [o for o in outputs(nb) if {"image/png", "image/gif"} & set(o.get("data", {}))]
    assert images, "no figure stored"


def test_stored_movie_and_study():
    lifetimes = nbformat.read(ROOT / "notebooks" / "lifetimes_and_maps.ipynb", as_version=4)
    assert [o for o in outputs(lifetimes) if "image/gif" in o.get("data", {})], "the movie is not shown"
    figures = nbformat.read(ROOT / "notebooks" / "paper_figures.ipynb", as_version=4)
    assert "Drawing from the study's files" in text_of(figures)  # the stored outputs are the study's
    assert "400 particles (400 5-gons)" in text_of(figures) and "400 particles (400 disks)" in text_of(figures)
    assert "does not hold" not in text_of(figures)
    assert len([o for o in outputs(figures) if "image/png" in o.get("data", {})]) >= 4


def test_notebooks_extra():
    """`pip install -e ".[notebooks]"` brings Jupyter and a kernel, and the README says so."""
    tomllib = pytest.importorskip("tomllib") if sys.version_info >= (3, 11) else pytest.importorskip("tomli")
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    names = {requirement.split(">")[0].split("=")[0].strip() for requirement in extras["notebooks"]}
    assert {"jupyterlab", "ipykernel"} <= names
    assert '.[notebooks]"' in (ROOT / "README.md").read_text() and "jupyter lab notebooks/" in (
        ROOT / "README.md").read_text()
