"""The notebooks run top to bottom (small sizes), as a user would run them, with the warnings
of grainview and the solver turned into errors: a notebook must not need to silence them."""

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = sorted((Path(__file__).parent.parent / "notebooks").glob("*.ipynb"))


STRICT = """import warnings
for module in ("grainview", "solver"):
    warnings.filterwarnings("error", module=module)
import grainview
warnings.simplefilter("error", grainview.ConvergenceWarning)"""


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path):
    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(STRICT))
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert len(outputs) >= 3


def test_there_are_notebooks():
    assert {p.stem for p in NOTEBOOKS} >= {"tutorial", "paper_figures"}
