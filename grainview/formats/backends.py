"""The readers as xarray backends: ``xr.open_dataset(path, engine="lammps", ...)``.

Registered through the ``xarray.backends`` entry point (pyproject.toml), so xarray finds them
once grainview is installed. A backend opens a run only when asked by name (``engine=``):
other codes' text dumps carry no signature that would let xarray guess them safely.
"""

from __future__ import annotations

from xarray.backends import BackendEntrypoint

__all__ = ["LammpsBackend", "Box2dBackend", "PymunkBackend", "Lmgc90Backend", "MercuryDpmBackend", "PegsBackend"]


class LammpsBackend(BackendEntrypoint):
    """LAMMPS 2D granular runs (:func:`grainview.formats.lammps.open_lammps`).

    ``xr.open_dataset("dump.particles", engine="lammps", contacts="dump.contacts",
    walls="dump.walls", log="log.lammps")``: the particles' ``dump custom`` is the path;
    ``contacts`` (required), ``walls``, ``log``, ``time_step``, ``columns`` and ``inertia`` are
    passed on to :func:`~grainview.formats.lammps.open_lammps`.
    """

    description = "LAMMPS 2D granular dumps (particles, pairs, walls) as a grainview dataset"
    url = "https://github.com/lammps/lammps"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "contacts", "walls", "log", "time_step",
                               "columns", "inertia")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, contacts=None, walls=None, log=None,
                     time_step=None, columns=None, inertia="auto"):
        from ..contract.errors import ParameterError
        from .lammps import open_lammps

        if contacts is None:
            raise ParameterError("engine='lammps' needs contacts=<the pairs' dump local> besides the particles' dump")
        ds = open_lammps(filename_or_obj, contacts, walls, log=log, time_step=time_step, columns=columns,
                         inertia=inertia)
        return ds.drop_vars(list(drop_variables or []), errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False


class _PeerBackend(BackendEntrypoint):
    """A run of the cross-check's peer engines (:func:`grainview.formats.peers.open_peer`):
    ``xr.open_dataset(raw_folder, engine=..., sample="sample.npz")``."""

    engine = ""
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "sample")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, sample=None):
        from ..contract.errors import ParameterError
        from .peers import open_peer

        if sample is None:
            raise ParameterError(f"engine={self.engine!r} needs sample=<the cross-check sample's .npz>")
        ds = open_peer(filename_or_obj, sample, self.engine)
        return ds.drop_vars(list(drop_variables or []), errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False


class Box2dBackend(_PeerBackend):
    """Box2D runs of the cross-check: a folder of raw snapshots and meta.json."""

    engine = "box2d"
    description = "Box2D runs of grainview's cross-check (raw snapshots) as a grainview dataset"


class PymunkBackend(_PeerBackend):
    """pymunk runs of the cross-check: a folder of raw snapshots and meta.json."""

    engine = "pymunk"
    description = "pymunk runs of grainview's cross-check (raw snapshots) as a grainview dataset"


class Lmgc90Backend(BackendEntrypoint):
    """LMGC90 2D rigid runs (:func:`grainview.formats.lmgc90.open_lmgc90`).

    ``xr.open_dataset("run_folder", engine="lmgc90")``: the path is the run's folder, holding
    ``DATBOX/`` (BODIES.DAT, BULK_BEHAV.DAT) and ``OUTBOX/`` (DOF.OUT.n, Vloc_Rloc.OUT.n); a run
    periodic in x gives its period, ``x_period=L`` (m).
    """

    description = "LMGC90 2D rigid runs (DATBOX and OUTBOX text files) as a grainview dataset"
    url = "https://git-xen.lmgc.univ-montp2.fr/lmgc90/lmgc90_user"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "x_period")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, x_period=None):
        from .lmgc90 import open_lmgc90

        return open_lmgc90(filename_or_obj, x_period=x_period).drop_vars(list(drop_variables or []),
                                                                         errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False


class MercuryDpmBackend(BackendEntrypoint):
    """MercuryDPM 2D runs (:func:`grainview.formats.mercurydpm.open_mercurydpm`).

    ``xr.open_dataset("run.data", engine="mercurydpm", units="si")``: the path is the run's
    ``.data`` file; ``fstat`` and ``restart`` default to the files beside it with the same stem;
    ``units`` (required: ``"si"`` or ``{"length": m, "mass": kg, "time": s}``) is passed on.
    """

    description = "MercuryDPM 2D runs (.data, .fstat, .restart) as a grainview dataset"
    url = "https://www.mercurydpm.org"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "fstat", "restart", "units")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, fstat=None, restart=None, units=None):
        from .mercurydpm import open_mercurydpm

        ds = open_mercurydpm(filename_or_obj, fstat, restart, units=units)
        return ds.drop_vars(list(drop_variables or []), errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False


class PegsBackend(BackendEntrypoint):
    """Photoelastic experiments solved by PeGS2 (:func:`grainview.formats.pegs.open_pegs`).

    ``xr.open_dataset("Adjacency_list.txt", engine="pegs", positions="particle_positions.txt",
    metres_per_pixel=4.375e-5, force_unit_n=1)``: the path is the adjacency list; ``positions``,
    ``metres_per_pixel`` and ``force_unit_n`` are required, ``frame_interval_s``,
    ``thickness_m`` and ``density_kg_m3`` optional.
    """

    description = "PeGS2 photoelastic adjacency lists and particle positions as a grainview dataset"
    url = "https://github.com/jekollmer/PEGS"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "positions", "metres_per_pixel", "force_unit_n",
                               "frame_interval_s", "thickness_m", "density_kg_m3")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, positions=None, metres_per_pixel=None,
                     force_unit_n=None, frame_interval_s=1.0, thickness_m=1.0, density_kg_m3=1000.0):
        from ..contract.errors import ParameterError
        from .pegs import open_pegs

        if positions is None:
            raise ParameterError("engine='pegs' needs positions=<particle_positions.txt or the *_centers.txt files> "
                                 "besides the adjacency list")
        ds = open_pegs(filename_or_obj, positions, metres_per_pixel=metres_per_pixel, force_unit_n=force_unit_n,
                       frame_interval_s=frame_interval_s, thickness_m=thickness_m, density_kg_m3=density_kg_m3)
        return ds.drop_vars(list(drop_variables or []), errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False
