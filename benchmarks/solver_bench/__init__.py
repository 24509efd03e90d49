"""Solver benchmarks, one module per section (scaling, work_precision, acceleration,
peer_engines, skipping, stress), with their sizes in config.py and shared helpers in helpers.py.

Each ``section_*`` function runs one section and returns Markdown (text and tables) for
``benchmarks/RESULTS.md``; ``benchmarks/run.py`` calls them in turn. Sizes come from a
``Config`` so that ``--quick`` runs the same code on tiny problems.

Samples. A "dense sample" is :func:`solver.compaction_sample` (paper size mix, box h/l ~ 2,
sigma_0 = 10 kPa on the right and top walls, zero gravity, friction 0.4) compacted for a fixed
number of steps (the same in every run) with the pushed walls allowed to close at up to ``max_wall_speed`` (faster
than the library default, to fit the run in minutes); it is not always at full equilibrium,
so every table reports the contact points per particle actually reached. A "biaxial step" is
then a step with the top wall moved down at 1 cm/s and sigma_0 kept on the right wall.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # benchmarks/: common.py
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # the repository

from .acceleration import section_acceleration  # noqa: E402
from .config import Config  # noqa: E402
from .peer_engines import section_peers  # noqa: E402
from .scaling import section_scaling  # noqa: E402
from .skipping import section_skipping  # noqa: E402
from .stress import section_stress  # noqa: E402
from .work_precision import section_work_precision  # noqa: E402

__all__ = ["Config", "section_scaling", "section_work_precision", "section_acceleration", "section_peers",
           "section_skipping", "section_stress"]
