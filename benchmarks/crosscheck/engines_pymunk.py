"""The cross-check's biaxial test in pymunk (Chipmunk2D; ``pip install pymunk``).

Run in the peers' virtual environment by ``python -m benchmarks.crosscheck``::

    python engines_pymunk.py SAMPLE.npz OUT_DIR --strain 0.25 --every 100 --iterations 200

The protocol and the raw snapshots are described in ``peer_common.py``. pymunk specifics:

* SI units throughout (Chipmunk has no length-dependent tolerance but ``collision_slop``,
  set to ``SLOP`` = 1e-5 m, 0.04 % of the smallest diameter); ``collision_bias`` is left at
  Chipmunk's default; no damping, no sleeping.
* Masses and moments of inertia are the sample's; polygons are hard (``Poly`` radius 0).
* Walls: bottom and left boxes on the static body; top a kinematic box moving at -velocity;
  right a box on a dynamic body of the sample's wall mass with infinite moment of inertia,
  held on a horizontal groove (``GrooveJoint``, a prismatic joint), pushed by ``body.force``
  set before every step (Chipmunk clears it after each step). Walls do not collide with each
  other (``ShapeFilter``).
* Friction: Chipmunk multiplies the coefficients of the two shapes, so grains get sqrt(mu)
  (sqrt(mu)^2 = mu) and walls 0; elasticity 0.
* Contacts: every arbiter of the step (``Body.each_arbiter``), one per pair; the normal is
  ``arbiter.normal`` (from the first shape to the second), the force on the second shape is
  ``-arbiter.total_impulse / dt`` (``total_impulse`` is the impulse on the first shape:
  checked on a box resting on a floor); the points are the midpoints of
  ``contact_point_set``'s ``point_a`` and ``point_b``, and their normal impulses are
  Chipmunk's accumulated ``jnAcc`` of each contact (read through pymunk's cffi structure,
  which pymunk does not expose otherwise), used only to place the resultant.
"""

from __future__ import annotations

import math
import sys

import numpy as np

import peer_common as pc

SLOP = 1e-5
"""Chipmunk's collision_slop, m: the overlap it lets stand."""
PARTICLE, WALL = 0b01, 0b10
WALL_HALF_THICKNESS = 0.125  # m


def _box(body, centre, half):
    """A frictionless wall box shape on ``body`` (centre and half sizes in the body's frame, m)
    that collides with particles only."""
    import pymunk

    (cx, cy), (hx, hy) = centre, half
    shape = pymunk.Poly(body, [(cx - hx, cy - hy), (cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy)],
                        radius=0.0)
    shape.friction, shape.elasticity = 0.0, 0.0
    shape.filter = pymunk.ShapeFilter(categories=WALL, mask=PARTICLE)
    return shape


class PymunkBiaxial:
    """A pymunk space holding the sample between its four walls (see the module docstring)."""

    def __init__(self, sample, velocity, iterations):
        import pymunk
        from pymunk._chipmunk import ffi

        self.ffi = ffi
        self.sample = sample
        self.dt = sample["time_step"]
        self.n = len(sample["radius"])
        self.velocity = velocity
        space = pymunk.Space()
        space.gravity = (0.0, 0.0)
        space.iterations = int(iterations)
        space.collision_slop = SLOP
        space.damping = 1.0
        self.space = space
        self.ids = {}  # shape -> contract body id
        mu = math.sqrt(float(sample["friction"]))
        self.bodies = []
        for p in range(self.n):
            body = pymunk.Body(float(sample["mass"][p]), float(sample["inertia"][p]))
            body.position = tuple(sample["position"][p])
            body.angle = float(sample["angle"][p])
            body.velocity = tuple(sample["velocity"][p])
            body.angular_velocity = float(sample["angular_velocity"][p])
            r, n = float(sample["radius"][p]), int(sample["n_vertices"][p])
            if n == 0:
                shape = pymunk.Circle(body, r)
            else:
                shape = pymunk.Poly(body, [tuple(v) for v in pc.local_vertices(sample, p)], radius=0.0)
            shape.friction, shape.elasticity = mu, 0.0
            space.add(body, shape)
            self.ids[shape] = p
            self.bodies.append(body)
        self._walls(sample["wall_position"], sample["wall_velocity"])

    def _walls(self, walls, wall_velocity):
        import pymunk

        t = WALL_HALF_THICKNESS
        self.x_left, self.y_bottom = walls[pc.LEFT, 0], walls[pc.BOTTOM, 1]
        centre = np.array([(walls[pc.LEFT, 0] + walls[pc.RIGHT, 0]) / 2, (walls[pc.BOTTOM, 1] + walls[pc.TOP, 1]) / 2])
        span = 3.0 * max(walls[pc.RIGHT, 0] - walls[pc.LEFT, 0], walls[pc.TOP, 1] - walls[pc.BOTTOM, 1])
        static = self.space.static_body
        bottom = _box(static, (centre[0], self.y_bottom - t), (span, t))
        left = _box(static, (self.x_left - t, centre[1]), (t, span))
        top_body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        top_body.position = (centre[0], walls[pc.TOP, 1])
        top_body.velocity = (0.0, -self.velocity)
        top = _box(top_body, (0.0, t), (span, t))
        right_body = pymunk.Body(float(self.sample["right_wall_mass"]), math.inf)
        right_body.position = (walls[pc.RIGHT, 0], centre[1])
        right_body.velocity = (float(wall_velocity[pc.RIGHT, 0]), 0.0)
        right = _box(right_body, (t, 0.0), (t, span))
        groove = pymunk.GrooveJoint(static, right_body, (centre[0] - span, centre[1]), (centre[0] + span, centre[1]),
                                    (0.0, 0.0))
        self.space.add(bottom, left, top_body, top, right_body, right, groove)
        for shape, w in ((bottom, pc.BOTTOM), (right, pc.RIGHT), (top, pc.TOP), (left, pc.LEFT)):
            self.ids[shape] = self.n + w
        self.top, self.right = top_body, right_body

    # -- the protocol ------------------------------------------------------------------------------
    def height(self):
        """Current sample height (m): top wall line minus bottom wall line."""
        return self.top.position.y - self.y_bottom

    def step(self, right_force):
        """One step with the right wall pushed inward by ``right_force`` (N)."""
        self.right.force = (-right_force, 0.0)
        self.space.step(self.dt)

    def snapshot(self):
        """The raw snapshot (``peer_common`` module docstring), in SI units."""
        rows, seen = [], set()
        ffi, dt = self.ffi, self.dt

        def collect(arbiter):
            shape_a, shape_b = arbiter.shapes
            a, b = self.ids[shape_a], self.ids[shape_b]
            if (min(a, b), max(a, b)) in seen:
                return
            seen.add((min(a, b), max(a, b)))
            contacts = arbiter.contact_point_set.points
            if not contacts:
                return
            raw = ffi.cast("struct cpArbiter *", arbiter._arbiter)
            jn = np.array([raw.contacts[k].jnAcc for k in range(len(contacts))]) / dt
            points = [0.5 * (np.array(c.point_a) + np.array(c.point_b)) for c in contacts]
            force = -np.array(arbiter.total_impulse) / dt
            rows.append((a, b, np.array(arbiter.normal), force, points, jn))

        for body in self.bodies:
            body.each_arbiter(collect)
        walls = np.array([[self.x_left, self.y_bottom], [self.right.position.x, self.y_bottom],
                          [self.x_left, self.top.position.y], [self.x_left, self.y_bottom]])
        wall_velocity = np.zeros((4, 2))
        wall_velocity[pc.RIGHT] = tuple(self.right.velocity)
        wall_velocity[pc.TOP] = tuple(self.top.velocity)
        bodies = self.bodies
        return dict(position=np.array([tuple(b.position) for b in bodies]), angle=np.array([b.angle for b in bodies]),
                    velocity=np.array([tuple(b.velocity) for b in bodies]),
                    angular_velocity=np.array([b.angular_velocity for b in bodies]), wall_position=walls,
                    wall_velocity=wall_velocity, **pc.pairs_to_arrays(rows))


def main():
    args = pc.parse_args("pymunk", __doc__.split("\n\n")[0],
                         [("--iterations", 200, "Chipmunk solver iterations per step")])
    import pymunk

    engine = PymunkBiaxial(pc.load_sample(args.sample), args.velocity, args.iterations)
    settings = dict(engine="pymunk", version=pymunk.version, chipmunk=pymunk.chipmunk_version,
                    iterations=args.iterations, collision_slop_m=SLOP,
                    collision_bias=engine.space.collision_bias, python=sys.version.split()[0])
    pc.run(engine, args, settings)


if __name__ == "__main__":
    main()
