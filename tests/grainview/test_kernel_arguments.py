"""No compiled kernel of grainview takes more than MAX_ARGUMENTS arguments, the solver's cap
(tests/solver/test_kernel_arguments.py): the analysis kernels' arrays reach them as records
(:mod:`grainview.analysis._kernels.records`), not as loose arrays."""

from pathlib import Path

import pytest

from ..solver.test_kernel_arguments import MAX_ARGUMENTS, kernel_arguments

GRAINVIEW = Path(__file__).resolve().parents[2] / "grainview"
MODULES = sorted(path.relative_to(GRAINVIEW).as_posix() for path in GRAINVIEW.rglob("*.py")
                 if "__pycache__" not in path.parts)


def test_the_walk_finds_grainviews_kernels():
    with_kernels = [name for name in MODULES if kernel_arguments((GRAINVIEW / name).read_text())]
    assert {"analysis/_kernels/coarse_graining.py", "analysis/_kernels/force_chains.py",
            "analysis/_kernels/network_topology.py"} <= set(with_kernels)


@pytest.mark.parametrize("module", MODULES)
def test_no_kernel_takes_more_than_eight_arguments(module):
    wide = {name: count for name, count in kernel_arguments((GRAINVIEW / module).read_text()).items()
            if count > MAX_ARGUMENTS}
    assert not wide, (f"grainview/{module}: kernels with more than {MAX_ARGUMENTS} arguments {wide}; pass the "
                      "arrays as records (grainview/analysis/_kernels/records.py)")
