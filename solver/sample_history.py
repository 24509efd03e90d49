"""The history of a sample: how it was made and what its compaction found, as one record that a
:class:`solver.stepper.Simulation` holds (``sim.history``) and that files carry as global
attributes.

The scenes write it (:func:`solver.scenes.compaction_sample`: the confining stress;
:func:`solver.scenes.isotropic_compaction`: the compaction's outcome;
:func:`solver.preparation.prepare_sample`: the preparation), the writers put
:meth:`SampleHistory.attrs` into the file, and :func:`solver.restart.load_sample` reads it
back (:meth:`SampleHistory.from_attrs`). The attributes are those files have always carried:
``sigma0_Pa``, ``preparation_*`` (:meth:`solver.preparation.Preparation.attrs`, with
``preparation_name``) and ``compaction_*``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

HISTORY_PREFIXES = ("preparation_", "compaction_")
"""Prefixes of the file attributes that hold a sample's history, besides ``sigma0_Pa``."""


@dataclass
class SampleHistory:
    """How a sample was made and what its compaction found.

    Attributes
    ----------
    sigma0 : float
        The confining stress the sample was compacted under, Pa (NaN: not said).
    preparation : solver.preparation.Preparation or None
        The preparation that made the sample (None: not made by
        :func:`solver.preparation.prepare_sample`).
    settled : bool or None
        Whether the isotropic compaction reached its equilibrium test (None: not compacted).
    compaction_steps : int or None
        Steps the compaction took.
    compaction_stress : ndarray or None
        Mean stress on each stress-driven wall over the compaction's last window, Pa.
    compaction_inertia_number : float or None
        The largest inertia number of the closing walls over the compaction.
    compaction_unconverged : solver.stepper.Unconverged or None
        The compaction's steps whose NLGS stopped before its tolerances.
    recorded : dict
        The history's attributes as a file recorded them (a sample read back from a file,
        whose preparation is known by its attributes only); {} otherwise.
    """

    sigma0: float = np.nan
    preparation: object = None
    settled: bool | None = None
    compaction_steps: int | None = None
    compaction_stress: np.ndarray | None = None
    compaction_inertia_number: float | None = None
    compaction_unconverged: object = None
    recorded: dict = field(default_factory=dict)

    def attrs(self) -> dict:
        """The history as file attributes: the :class:`Preparation` (``preparation_*``, with
        ``preparation_name``), ``sigma0_Pa`` and the compaction's outcome (``compaction_*``);
        the recorded ones for a sample read from a file; {} for a sample that no preparation
        made."""
        if self.preparation is None:
            return dict(self.recorded)
        prep = self.preparation
        out = {**prep.attrs(), "sigma0_Pa": prep.sigma0,
               "compaction_steps": self.compaction_steps, "compaction_settled": int(bool(self.settled)),
               "compaction_inertia_number": self.compaction_inertia_number}
        if self.compaction_unconverged is not None:  # steps whose NLGS stopped before its tolerances
            out.update(compaction_unconverged_steps=self.compaction_unconverged.steps,
                       compaction_unconverged_local_law_residual=self.compaction_unconverged.local_law_residual)
        return out

    @classmethod
    def from_attrs(cls, attrs) -> SampleHistory:
        """The history a file's global attributes ``attrs`` record (:meth:`attrs`): the
        confining stress (NaN when absent) and the ``preparation_*`` and ``compaction_*``
        attributes as they are."""
        return cls(sigma0=float(attrs.get("sigma0_Pa", np.nan)),
                   recorded={k: v for k, v in attrs.items() if k.startswith(HISTORY_PREFIXES)})
