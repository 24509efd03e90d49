"""Sizes of every solver benchmark section (``--quick`` shrinks them), and the speed targets."""

from __future__ import annotations

import os
from dataclasses import dataclass


HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
"""benchmarks/: where the plots and RESULTS.md go."""
DATA = os.path.join(HERE, "_data")
PEER_PYTHON = os.environ.get("PEER_PYTHON", "/tmp/peervenv/bin/python")

TARGET_SWEEP_NS = 25.0
TARGET_STEP_US = 10.0
TARGET_DETECTION_SHARE = 0.20


@dataclass
class Config:
    quick: bool = False
    plot_dir: str = HERE  # where plots go: next to the RESULTS file that links them
    # scaling
    sizes: tuple = (500, 1000, 4000, 14400, 57600)
    compaction_steps: dict = None  # per (shape, N): a fixed count, so that every run measures the same state
    timed_steps: dict = None
    # work-precision
    wp_particles: int = 250
    wp_compaction_steps: int = 8000  # a fixed count, so that every run starts from the same state
    wp_duration: float = 0.04  # s of biaxial test
    wp_tolerances: tuple = (1e-2, 1e-3, 1.7e-4, 3e-5, 1e-5)
    wp_time_steps: tuple = (2.5e-4, 5e-4, 1e-3)
    wp_budgets: tuple = (20, 100, 500)  # fixed sweep counts (no tolerance) at dt = 5e-4
    # peers
    peer_particles: int = 1000
    peer_settle_steps: int = 3000
    peer_steps: int = 200
    peer_budgets: tuple = (10, 25, 50)
    peer_tolerances: tuple = (1e-5, 1e-6)  # besides the default: what a smaller floor-force error costs
    # skipping
    skip_particles: int = 1000
    skip_steps: int = 40
    # stress
    stress_scale: int = 1
    # acceleration: candidates against the NLGS on one dense sheared state
    acc_particles: int = 1000
    acc_strain: float = 0.08
    acc_steps: int = 1000
    acc_compaction_steps: int = 400

    def __post_init__(self):
        if self.quick:
            self.sizes = (300, 1000)
            self.compaction_steps = {(shape, n): 200 for shape in ("disk", "pentagon") for n in self.sizes}
            self.timed_steps = {300: 10, 1000: 5}
            self.wp_particles = 80
            self.wp_compaction_steps = 500
            self.wp_duration = 0.004
            self.wp_tolerances = (1e-2, 1.7e-4)
            self.wp_time_steps = (5e-4, 1e-3)
            self.wp_budgets = (20,)
            self.peer_particles = 60
            self.peer_settle_steps = 100
            self.peer_steps = 20
            self.peer_budgets = (10,)
            self.peer_tolerances = ()
            self.skip_particles = 200
            self.acc_particles = 80
            self.acc_steps = 20
            self.skip_steps = 10
            self.stress_scale = 0
        else:
            # ~25-150 s of compaction each on the 2-core VM of RESULTS.md; the samples of 4000 and
            # more stay loose (contact points / particle in the table)
            self.compaction_steps = self.compaction_steps or {
                ("disk", 500): 30_000, ("disk", 1000): 19_000, ("disk", 4000): 350, ("disk", 14400): 135,
                ("disk", 57600): 60, ("pentagon", 500): 12_000, ("pentagon", 1000): 3400,
                ("pentagon", 4000): 1200, ("pentagon", 14400): 1200, ("pentagon", 57600): 1000}
            self.timed_steps = self.timed_steps or {500: 40, 1000: 30, 4000: 20, 14400: 6, 57600: 3}


# --------------------------------------------------------------------------------------------
