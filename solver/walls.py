"""Rigid walls: lines given by a point and the unit normal pointing into the sample, each
fixed, moved at an imposed velocity, or pushed by an imposed stress.

A wall pushed by a stress sigma is a body of mass ``mass`` that translates along its normal
only; its driving force is sigma times its length (the box's extent along the wall) times the
slab thickness, pointing into the sample.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from grainview.contract.errors import ParameterError

FIXED, VELOCITY, STRESS = 0, 1, 2
BOX_NAMES = ("bottom", "right", "top", "left")


@dataclass
class Walls:
    point: np.ndarray  # (W, 2) m
    normal: np.ndarray  # (W, 2) inward unit normals
    names: tuple = ()
    mode: np.ndarray = None  # (W,) FIXED / VELOCITY / STRESS
    velocity: np.ndarray = None  # (W, 2) m s-1, imposed (VELOCITY) or current (STRESS)
    stress: np.ndarray = None  # (W,) Pa, for STRESS walls
    mass: np.ndarray = None  # (W,) kg, for STRESS walls
    length_axis: np.ndarray = field(default=None)  # (W,) 0: length along x (width), 1: along y (height)
    max_speed: np.ndarray = None  # (W,) m s-1, cap on the inward speed of STRESS walls

    def __post_init__(self):
        self.point = np.asarray(self.point, float).reshape(-1, 2).copy()
        self.normal = np.asarray(self.normal, float).reshape(-1, 2).copy()
        n = len(self.point)
        norm = np.linalg.norm(self.normal, axis=1)
        if np.any(np.abs(norm - 1) > 1e-12):
            raise ParameterError("wall normals must be unit vectors")
        self.names = tuple(self.names) or tuple(f"wall{k}" for k in range(n))
        self.mode = np.zeros(n, np.int64) if self.mode is None else np.asarray(self.mode, np.int64)
        self.velocity = np.zeros((n, 2)) if self.velocity is None else np.asarray(self.velocity, float)
        self.stress = np.zeros(n) if self.stress is None else np.asarray(self.stress, float)
        self.mass = np.ones(n) if self.mass is None else np.asarray(self.mass, float)
        self.max_speed = np.full(n, np.inf) if self.max_speed is None else np.asarray(self.max_speed, float)
        if self.length_axis is None:
            self.length_axis = np.where(np.abs(self.normal[:, 1]) > np.abs(self.normal[:, 0]), 0, 1)

    @classmethod
    def box(cls, width, height, origin=(0.0, 0.0)):
        """The four walls of a box [x0, x0 + width] x [y0, y0 + height]: bottom, right, top, left."""
        x0, y0 = origin
        point = [[x0, y0], [x0 + width, y0], [x0, y0 + height], [x0, y0]]
        normal = [[0, 1], [-1, 0], [0, -1], [1, 0]]
        return cls(point, normal, BOX_NAMES)

    @classmethod
    def floor(cls, y=0.0, sides=None):
        """A floor at height y, with vertical side walls at x = sides[0], sides[1] if given."""
        point, normal, names = [[0.0, y]], [[0.0, 1.0]], ["bottom"]
        if sides is not None:
            point += [[sides[1], y], [sides[0], y]]
            normal += [[-1.0, 0.0], [1.0, 0.0]]
            names += ["right", "left"]
        return cls(point, normal, tuple(names))

    def __len__(self):
        return len(self.point)

    def index(self, name):
        try:
            return self.names.index(name)
        except ValueError:
            raise ParameterError(f"no wall named {name!r}; walls are {self.names}") from None

    def drive_velocity(self, name, velocity):
        """Move wall ``name`` at the imposed velocity (m s-1, 2-vector)."""
        k = self.index(name)
        self.mode[k] = VELOCITY
        self.velocity[k] = velocity

    def drive_stress(self, name, stress, mass, max_speed=np.inf):
        """Push wall ``name`` into the sample with stress ``stress`` (Pa); ``mass`` in kg.

        ``max_speed`` (m s-1) caps the wall's inward speed: a loose sample is then closed
        without the wall slamming into it (the theta-scheme lets a contact approached at speed
        u overlap by about h (1 - theta) u, which is never pushed back out); it has no effect
        once the wall has settled."""
        if stress < 0 or not np.isfinite(stress):
            raise ParameterError(f"stress on wall {name!r} must be finite and >= 0 Pa, got {stress}")
        if mass <= 0 or not np.isfinite(mass):
            raise ParameterError(f"mass of wall {name!r} must be > 0 kg, got {mass}")
        k = self.index(name)
        self.mode[k] = STRESS
        self.stress[k] = stress
        self.mass[k] = mass
        self.max_speed[k] = max_speed

    def box_bounds(self):
        """(box_min, box_max) from the box walls; from the walls' points otherwise."""
        if set(BOX_NAMES) <= set(self.names):
            lo = np.array([self.point[self.index("left"), 0], self.point[self.index("bottom"), 1]])
            hi = np.array([self.point[self.index("right"), 0], self.point[self.index("top"), 1]])
            return lo, hi
        return self.point.min(0), self.point.max(0)
