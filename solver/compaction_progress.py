"""The state of an isotropic compaction's loop besides the simulation
(:func:`solver.scenes.isotropic_compaction`), which a checkpoint saves and a resumed compaction
starts from (:mod:`solver.compaction_checkpoint`)."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np


@dataclass
class CompactionProgress:
    """The state of :func:`solver.scenes.isotropic_compaction`'s loop besides the simulation.

    Attributes
    ----------
    steps : int
        Compaction steps taken.
    target : ndarray
        The stress-driven walls' target stress, Pa (the pressure ramp rises to it).
    own_cap : ndarray
        The stress-driven walls' own cap of their inward speed, m s-1 (the inertia-number cap is
        applied below it).
    stresses, rates : deque of ndarray
        The last ``window`` steps' stresses on (Pa) and strain rates of (s-1) the driven walls,
        for the equilibrium test (:func:`solver.scenes.is_equilibrium`).
    largest_inertia : float
        The largest inertia number of a driven wall so far.
    """

    steps: int
    target: np.ndarray
    own_cap: np.ndarray
    stresses: deque = field(default_factory=deque)
    rates: deque = field(default_factory=deque)
    largest_inertia: float = 0.0

    @classmethod
    def start(cls, walls, driven, window) -> CompactionProgress:
        """The state before the first step: the driven walls' stresses and speed caps as set."""
        return cls(0, walls.stress[driven].copy(), walls.max_speed[driven].copy(), deque(maxlen=window),
                   deque(maxlen=window))

    def attrs(self) -> dict:
        """The state as ``checkpoint_*`` file attributes (the windows as flat arrays)."""
        width = len(self.target)
        return {"checkpoint_steps": int(self.steps), "checkpoint_window": int(self.stresses.maxlen),
                "checkpoint_target_stress_Pa": self.target.astype("f8"),
                "checkpoint_own_cap_m_s": self.own_cap.astype("f8"),
                "checkpoint_stresses_Pa": np.asarray(list(self.stresses), "f8").reshape(-1, width).ravel(),
                "checkpoint_rates_s": np.asarray(list(self.rates), "f8").reshape(-1, width).ravel(),
                "checkpoint_largest_inertia": float(self.largest_inertia)}

    @classmethod
    def from_attrs(cls, attrs) -> CompactionProgress:
        """The state :meth:`attrs` wrote."""
        target = np.atleast_1d(np.asarray(attrs["checkpoint_target_stress_Pa"], float))
        window = int(attrs["checkpoint_window"])

        def rows(name):
            flat = np.atleast_1d(np.asarray(attrs[name], float))
            return deque(list(flat.reshape(-1, len(target))), maxlen=window)

        return cls(int(attrs["checkpoint_steps"]), target,
                   np.atleast_1d(np.asarray(attrs["checkpoint_own_cap_m_s"], float)),
                   rows("checkpoint_stresses_Pa"), rows("checkpoint_rates_s"),
                   float(attrs["checkpoint_largest_inertia"]))
