"""The periodic cell of a simulation: its lattice vectors, how it moves, wrapping.

The cell is the contract's (docs/schema.md, "The periodic cell"): the parallelogram
``origin + s a + t b``, 0 <= s, t < 1, with ``a = (l, 0)`` and ``b = (tilt, h)`` (LAMMPS's
restricted triclinic form). Every particle stands for its images ``x + m a + n b``.

Positions are kept **wrapped**: after every step each centre that left the cell is moved back by
whole lattice vectors, ``x -= m a + n b``, and its velocity by the same vectors' rates,
``v -= m da/dt + n db/dt`` (Lees–Edwards: the image across the top boundary moves with the
cell). Wrapped positions are what a file holds, so the state a snapshot writes is the state the
run goes on from, bit for bit (an unwrapped position plus a tracked image count would be written
as a wrapped one, a rounding away from the run's own). A pair's image is found again at every
detection from the positions (:mod:`solver.periodic_detection`), so a wrap needs no bookkeeping.

When db/dt changes (the stress control's dh/dt, or gamma_dot h as h changes), the particles'
velocities take the change of the affine flow, ``v += d(db/dt) (t - 1/2)`` with t the centre's
fractional height (:meth:`PeriodicCell.follow_rate`): without it an image's velocity would jump
by d(db/dt) while its particle's would not, and the run would depend on where the boundary cuts
the sample (the representative of each particle); the 1/2 keeps the mean velocity.

The cell moves at ``da/dt = 0`` (``l`` fixed) and ``db/dt = (gamma_dot h, dh/dt)``: a simple
shear at the imposed rate ``shear_rate`` (the tilt's rate is gamma_dot h) and a height that is
either fixed or held at a normal stress (solved with the contacts: :mod:`solver.cell_coupling`). The tilt is
flipped by ``l`` once it passes ``l/2`` (the same lattice, LAMMPS's flip): the cell then never
gets thinner than ``h / sqrt(1 + (l / 2h)^2)`` across, and detection's cell lists keep working.

Everything here is elementwise numpy on a few numbers or (N, 2) arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grainview.contract.errors import ParameterError

__all__ = ["PeriodicCell"]


@dataclass
class PeriodicCell:
    """A biperiodic cell (m, s-1, Pa, kg).

    origin : (2,) m, the cell's corner (the file's ``box_min``); length ``l`` and height ``h``
    (m); tilt (m), the x-offset of the top edge; ``shear_rate`` gamma_dot (s-1): the tilt grows
    at gamma_dot h; ``height_rate`` dh/dt (m s-1), the cell's current rate of height; ``stress``
    the target normal stress sigma_yy (Pa, compression positive) or None for a fixed height;
    ``mass`` (kg) the inertia of the height under stress control; ``max_speed`` (m s-1) a cap on
    |dh/dt|; ``thickness`` (m) the slab's, for the stress's volume l h thickness.
    """

    origin: np.ndarray
    length: float
    height: float
    tilt: float = 0.0
    shear_rate: float = 0.0
    height_rate: float = 0.0
    stress: float | None = None
    mass: float = 1.0
    max_speed: float = np.inf
    thickness: float = 1.0

    def __post_init__(self):
        self.origin = np.asarray(self.origin, float).reshape(2).copy()
        for name in ("length", "height"):
            value = float(getattr(self, name))
            if not (np.isfinite(value) and value > 0):
                raise ParameterError(f"cell {name}={value!r}: expected a finite length > 0 m")
            setattr(self, name, value)
        for name in ("tilt", "shear_rate", "height_rate"):
            value = float(getattr(self, name))
            if not np.isfinite(value):
                raise ParameterError(f"cell {name}={value!r}: expected a finite number")
            setattr(self, name, value)
        if self.stress is not None and not (np.isfinite(self.stress) and self.stress >= 0):
            raise ParameterError(f"cell stress={self.stress!r}: expected a finite normal stress >= 0 Pa or None")
        if not (np.isfinite(self.mass) and self.mass > 0):
            raise ParameterError(f"cell mass={self.mass!r}: expected a finite mass > 0 kg")
        if not self.max_speed > 0:
            raise ParameterError(f"cell max_speed={self.max_speed!r}: expected a speed > 0 m/s")

    # -- geometry --------------------------------------------------------------------------
    @property
    def periodic(self) -> np.ndarray:
        """The contract's flags (a, b): both periodic."""
        return np.array([1, 1], np.int8)

    def vectors(self) -> np.ndarray:
        """The lattice vectors as the contract's ``cell`` (2, 2): rows a = (l, 0), b = (tilt, h)."""
        return np.array([[self.length, 0.0], [self.tilt, self.height]])

    def box(self):
        """(box_min, box_max): the cell's corner and the corner plus (l, h)."""
        return self.origin.copy(), self.origin + np.array([self.length, self.height])

    def area(self) -> float:
        """l h (m2)."""
        return self.length * self.height

    def width_across(self) -> float:
        """The cell's smallest width between opposite sides (m): h, or l h / |b| across a."""
        return min(self.height, self.length * self.height / float(np.hypot(self.tilt, self.height)))

    def b_rate(self) -> np.ndarray:
        """db/dt = (gamma_dot h, dh/dt) (m s-1): the velocity of an image one cell up."""
        return np.array([self.shear_rate * self.height, self.height_rate])

    def image_shifts(self, image) -> np.ndarray:
        """(P, 2) m: the vectors m a + n b of the image numbers ``image`` (P, 2) (m, n)."""
        image = np.asarray(image)
        m, n = image[:, 0].astype(float), image[:, 1].astype(float)
        return np.stack([m * self.length + n * self.tilt, n * self.height], -1)

    def image_velocities(self, image) -> np.ndarray:
        """(P, 2) m s-1: the velocity of the image (m, n) of a body relative to the body, n db/dt."""
        n = np.asarray(image)[:, 1].astype(float)
        rate = self.b_rate()
        return np.stack([n * rate[0], n * rate[1]], -1)

    def check_reach(self, reach):
        """Refuse a cell whose width across is not more than twice ``reach`` (m, the largest
        distance at which detection looks for a pair: every pair then has one image within it)."""
        if not self.width_across() > 2.0 * reach:
            raise ParameterError(f"the periodic cell is {self.width_across():.4g} m across, not more than twice the "
                                 f"detection reach {reach:.4g} m (two diameters and the alert distance): a pair could "
                                 "touch through two images; expected a larger cell")

    # -- wrapping ----------------------------------------------------------------------------
    def wrap(self, position, velocity):
        """Move the centres that left the cell back by whole lattice vectors, their velocities
        by the vectors' rates (module doc), in place; returns the number of moves. A centre a
        rounding puts on the far side (s or t = 1) is moved again, so that every centre ends with
        0 <= s, t < 1 and wrapping wrapped centres changes nothing (a resumed run's first wrap)."""
        count = 0
        for _ in range(3):
            t = (position[:, 1] - self.origin[1]) / self.height
            n = np.floor(t)
            s = (position[:, 0] - self.origin[0] - t * self.tilt) / self.length
            m = np.floor(s)
            moved = (m != 0) | (n != 0)
            if not moved.any():
                break
            k = np.flatnonzero(moved)
            rate = self.b_rate()
            position[k, 0] -= m[k] * self.length + n[k] * self.tilt
            position[k, 1] -= n[k] * self.height
            velocity[k, 0] -= n[k] * rate[0]
            velocity[k, 1] -= n[k] * rate[1]
            count += int(k.size)
        return count

    def follow_rate(self, position, velocity, change):
        """When db/dt changes by ``change`` (m s-1), add ``change (t - 1/2)`` to each velocity,
        t = (y - y0) / h the centre's height in the cell (in place): the affine flow follows the
        cell's new rate, and the velocity of an image one cell up stays the velocity of its
        particle plus db/dt, whichever image stands for the particle (module doc)."""
        if change[0] == 0.0 and change[1] == 0.0:
            return
        t = (position[:, 1] - self.origin[1]) / self.height - 0.5
        n = len(position)
        velocity[:n, 0] += t * change[0]
        velocity[:n, 1] += t * change[1]

    # -- motion ------------------------------------------------------------------------------
    def advance(self, time_step):
        """Move the cell over one step at its current rates: tilt += h_step gamma_dot h,
        h += h_step dh/dt; the tilt flipped by l when it passes l/2. Returns whether it flipped."""
        rate = self.b_rate()
        self.tilt += time_step * rate[0]
        self.height += time_step * rate[1]
        if not self.height > 0:
            raise ParameterError(f"the periodic cell's height fell to {self.height:.4g} m: its stress control "
                                 "collapsed it (expected a larger cell mass or a smaller time step)")
        if abs(self.tilt) > 0.5 * self.length:
            self.tilt -= self.length * np.sign(self.tilt)
            return True
        return False

    def set_height_rate(self, rate):
        """dh/dt = ``rate`` (m s-1, the one solved with the contacts under stress control,
        :mod:`solver.cell_coupling`), capped at ``max_speed``."""
        self.height_rate = float(min(max(float(rate), -self.max_speed), self.max_speed))
