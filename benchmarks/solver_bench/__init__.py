"""Solver benchmarks, one module per section (scaling, work_precision, acceleration,
peer_engines, skipping, stress), with their sizes in config.py and shared helpers in helpers.py.

Each ``section_*`` function runs one section and returns Markdown (text and tables) for
its section file; ``benchmarks/sections.py`` calls one per run (``python -m benchmarks``). Sizes come from a
``Config`` so that ``--quick`` runs the same code on tiny problems.

Samples. A "dense sample" is :func:`solver.compaction_sample` (paper size mix, box h/l ~ 2,
sigma_0 = 10 kPa on the right and top walls, zero gravity, friction 0.4) compacted for a fixed
number of steps (the same in every run) with the pushed walls allowed to close at up to ``max_wall_speed`` (faster
than the library default, to fit the run in minutes); it is not always at full equilibrium,
so every table reports the contact points per particle actually reached. A "biaxial step" is
then a step with the top wall moved down at 1 cm/s and sigma_0 kept on the right wall.
"""

from .acceleration import section_acceleration
from .config import Config
from .peer_engines import section_peers
from .scaling import section_scaling
from .skipping import section_skipping
from .stress import section_stress
from .work_precision import section_work_precision

__all__ = ["Config", "section_scaling", "section_work_precision", "section_acceleration", "section_peers",
           "section_skipping", "section_stress"]
