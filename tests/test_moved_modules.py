"""The modules' former names (before the rooms of docs/map.md) still import, as the same module
objects, with a DeprecationWarning naming the new place (grainview/_moved.py)."""

import importlib
import subprocess
import sys

import pytest

from grainview._moved import MOVED, new_name


@pytest.mark.parametrize("old", sorted(MOVED))
def test_every_former_name_is_the_module_at_its_new_place(old):
    with pytest.warns(DeprecationWarning, match=MOVED[old].replace(".", r"\.")):
        sys.modules.pop(old, None)
        former = importlib.import_module(old)
    assert former is importlib.import_module(MOVED[old])


def test_former_package_submodules_and_from_imports():
    code = ("import warnings; warnings.simplefilter('ignore')\n"
            "from grainview.strain import residual_window\n"
            "from grainview import sample\n"
            "import grainview.arrays.stress as old, grainview.analysis.arrays.stress as new\n"
            "import grainview.analysis.strain as s\n"
            "assert residual_window is s.residual_window and old is new\n"
            "assert sample.__name__ == 'grainview.analysis.sample'\n"
            "print('ok')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "ok", done.stderr


def test_names_that_did_not_move_are_left_to_python():
    assert new_name("grainview.plot.maps") is None and new_name("grainview.stressx") is None
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("grainview.no_such_module")
