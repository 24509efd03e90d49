"""The cross-check's biaxial test in Box2D 2.3 (``pip install box2d``, ``import Box2D``).

Run in the peers' virtual environment by ``python -m benchmarks.crosscheck``::

    python engines_box2d.py SAMPLE.npz OUT_DIR --strain 0.25 --every 100 \
        --velocity-iterations 100 --position-iterations 40

The protocol and the raw snapshots are described in ``peer_common.py``. Box2D specifics:

* Units: lengths in units of 2.5 cm (``UNIT``; Box2D's slop and skin assume metre-sized
  bodies), measured from the centre of the initial box (Box2D stores positions in float32);
  masses in kg and time in s, so velocities are in UNIT/s, forces in kg UNIT/s2 (= N / UNIT)
  and impulses in kg UNIT/s (= N s / UNIT). Every quantity is converted back to SI on output.
* Masses and moments of inertia are set explicitly to the sample's (``b2MassData``), so they
  are those of the project's solver whatever Box2D would compute from the shapes.
* Box2D rounds every polygon (and edge) by a skin of ``b2_polygonRadius`` (0.01 UNIT =
  0.25 mm), which it cannot turn off. The polygons' cores are therefore shrunk so that their
  edges (core + skin) lie where the sample's edges are (inradius r cos(pi/n) - skin); only
  the corners are rounded, by 0.25 mm. Disks have no skin. The walls' boxes are likewise set
  back by the skin.
* Walls: bottom and left static boxes; top a kinematic box moving at -velocity; right a
  dynamic box of the sample's wall mass with fixed rotation on a prismatic joint (axis x) to
  the ground, pushed by ``ApplyForceToCenter`` every step. Walls do not collide with each
  other (collision filter).
* Friction: Box2D mixes coefficients by their geometric mean, so grains get mu and walls 0
  (sqrt(mu * 0) = 0); restitution 0. No sleeping, no continuous collision (speeds are far
  below a skin per step), warm starting on (Box2D's default).
* Contacts: every touching contact with ``manifold.pointCount`` >= 1; the normal is
  ``worldManifold.normal`` (from fixture A to fixture B), the force on B is the sum over the
  points of (normalImpulse n + tangentImpulse (n_y, -n_x)) / dt, Box2D's own tangent.
"""

from __future__ import annotations

import sys

import numpy as np

import peer_common as pc

UNIT = 0.025
"""Box2D length unit in m (2.5 cm, the smallest grain diameter)."""
PARTICLE, WALL = 0x0001, 0x0002
WALL_HALF_THICKNESS = 5.0  # UNIT


class Box2DBiaxial:
    """A Box2D world holding the sample between its four walls (see the module docstring)."""

    def __init__(self, sample, velocity, velocity_iterations, position_iterations):
        import Box2D as b2

        self.b2 = b2
        self.sample = sample
        self.dt = sample["time_step"]
        self.iterations = (int(velocity_iterations), int(position_iterations))
        self.n = len(sample["radius"])
        walls = sample["wall_position"]
        self.x_left, self.y_bottom = walls[pc.LEFT, 0], walls[pc.BOTTOM, 1]
        self.origin = np.array([(walls[pc.LEFT, 0] + walls[pc.RIGHT, 0]) / 2,
                                (walls[pc.BOTTOM, 1] + walls[pc.TOP, 1]) / 2])
        self.skin = float(b2.b2_polygonRadius)
        world = b2.b2World(gravity=(0.0, 0.0), doSleep=False)
        world.continuousPhysics = False
        world.warmStarting = True
        self.world = world
        self.bodies = [self._particle(p) for p in range(self.n)]
        self._walls(walls, sample["wall_velocity"], velocity)

    # -- units ---------------------------------------------------------------------------------
    def to_b2(self, x):
        return tuple(float(c) for c in (np.asarray(x) - self.origin) / UNIT)

    def from_b2(self, v):
        return np.array([v[0], v[1]]) * UNIT + self.origin

    # -- construction ----------------------------------------------------------------------------
    def _particle(self, p):
        b2, s = self.b2, self.sample
        radius, n = float(s["radius"][p]) / UNIT, int(s["n_vertices"][p])
        body = self.world.CreateDynamicBody(position=self.to_b2(s["position"][p]), angle=float(s["angle"][p]),
                                            linearVelocity=tuple(float(v) / UNIT for v in s["velocity"][p]),
                                            angularVelocity=float(s["angular_velocity"][p]), allowSleep=False)
        common = dict(density=0.0, friction=float(s["friction"]), restitution=0.0,
                      categoryBits=PARTICLE, maskBits=0xFFFF)
        if n == 0:
            body.CreateCircleFixture(radius=radius, **common)
        else:
            # core + skin = the sample's edges: shrink about the centre so that every edge line moves in by
            # the skin (exact for polygons whose edges all touch the inscribed circle, as regular ones do)
            shrink = 1.0 - self.skin / (float(s["inradius"][p]) / UNIT)
            core = pc.local_vertices(s, p) / UNIT * shrink
            body.CreatePolygonFixture(vertices=[tuple(v) for v in core], **common)
        body.massData = b2.b2MassData(mass=float(s["mass"][p]), I=float(s["inertia"][p]) / UNIT**2, center=(0, 0))
        body.userData = p
        return body

    def _box(self, body, half, centre):
        """A wall box fixture (half sizes and centre in the body's frame, UNIT)."""
        shape = self.b2.b2PolygonShape(box=(half[0], half[1], centre, 0.0))
        body.CreateFixture(shape=shape, density=0.0, friction=0.0, restitution=0.0,
                           categoryBits=WALL, maskBits=PARTICLE)

    def _walls(self, walls, wall_velocity, velocity):
        b2, t, s, n = self.b2, WALL_HALF_THICKNESS, self.skin, self.n
        width = (walls[pc.RIGHT, 0] - walls[pc.LEFT, 0]) / UNIT
        height = (walls[pc.TOP, 1] - walls[pc.BOTTOM, 1]) / UNIT
        span = 3.0 * max(width, height)  # half length of every wall: covers any box of the test
        bottom = self.world.CreateStaticBody(position=(0.0, self.to_b2(walls[pc.BOTTOM])[1]))
        self._box(bottom, (span, t), (0.0, -s - t))
        left = self.world.CreateStaticBody(position=(self.to_b2(walls[pc.LEFT])[0], 0.0))
        self._box(left, (t, span), (-s - t, 0.0))
        top = self.world.CreateKinematicBody(position=(0.0, self.to_b2(walls[pc.TOP])[1]),
                                             linearVelocity=(0.0, -velocity / UNIT))
        self._box(top, (span, t), (0.0, s + t))
        right = self.world.CreateDynamicBody(position=(self.to_b2(walls[pc.RIGHT])[0], 0.0), fixedRotation=True,
                                             linearVelocity=(float(wall_velocity[pc.RIGHT, 0]) / UNIT, 0.0),
                                             allowSleep=False)
        self._box(right, (t, span), (s + t, 0.0))
        right.massData = b2.b2MassData(mass=float(self.sample["right_wall_mass"]), I=1.0, center=(0, 0))
        self.world.CreatePrismaticJoint(bodyA=bottom, bodyB=right, anchor=right.worldCenter, axis=(1.0, 0.0))
        for body, w in ((bottom, pc.BOTTOM), (right, pc.RIGHT), (top, pc.TOP), (left, pc.LEFT)):
            body.userData = n + w
        self.top, self.right = top, right
        self.velocity = velocity

    # -- the protocol ------------------------------------------------------------------------------
    def height(self):
        """Current sample height (m): top wall line minus bottom wall line."""
        return self.from_b2(self.top.position)[1] - self.y_bottom

    def step(self, right_force):
        """One step with the right wall pushed inward by ``right_force`` (N)."""
        self.right.ApplyForceToCenter((-right_force / UNIT, 0.0), True)
        self.world.Step(self.dt, *self.iterations)

    def snapshot(self):
        """The raw snapshot (``peer_common`` module docstring), in SI units."""
        bodies = self.bodies
        position = np.array([self.from_b2(b.position) for b in bodies])
        velocity = np.array([tuple(b.linearVelocity) for b in bodies]) * UNIT
        walls = np.array([[self.x_left, self.y_bottom], [self.from_b2(self.right.position)[0], self.y_bottom],
                          [self.x_left, self.from_b2(self.top.position)[1]], [self.x_left, self.y_bottom]])
        wall_velocity = np.zeros((4, 2))
        wall_velocity[pc.RIGHT, 0] = self.right.linearVelocity[0] * UNIT
        wall_velocity[pc.TOP, 1] = -self.velocity
        rows = []
        to_force = UNIT / self.dt  # impulse (kg UNIT/s) -> force (N)
        for contact in self.world.contacts:
            manifold = contact.manifold
            count = manifold.pointCount
            if not contact.touching or count == 0:
                continue
            world_manifold = contact.worldManifold
            normal = np.array(tuple(world_manifold.normal))
            tangent = np.array([normal[1], -normal[0]])  # Box2D: b2Cross(normal, 1)
            jn = np.array([manifold.points[k].normalImpulse for k in range(count)])
            jt = np.array([manifold.points[k].tangentImpulse for k in range(count)])
            force = (jn.sum() * normal + jt.sum() * tangent) * to_force
            points = [self.from_b2(world_manifold.points[k]) for k in range(count)]
            rows.append((contact.fixtureA.body.userData, contact.fixtureB.body.userData, normal, force,
                         points, jn * to_force))
        return dict(position=position, angle=np.array([b.angle for b in bodies]), velocity=velocity,
                    angular_velocity=np.array([b.angularVelocity for b in bodies]), wall_position=walls,
                    wall_velocity=wall_velocity, **pc.pairs_to_arrays(rows))


def main():
    args = pc.parse_args("box2d", __doc__.split("\n\n")[0], [
        ("--velocity-iterations", 100, "Box2D velocity iterations per step"),
        ("--position-iterations", 40, "Box2D position iterations per step")])
    import Box2D

    sample = pc.load_sample(args.sample)
    engine = Box2DBiaxial(sample, args.velocity, args.velocity_iterations, args.position_iterations)
    settings = dict(engine="box2d", version=Box2D.__version__, unit_m=UNIT, skin_m=engine.skin * UNIT,
                    velocity_iterations=args.velocity_iterations, position_iterations=args.position_iterations,
                    python=sys.version.split()[0])
    pc.run(engine, args, settings)


if __name__ == "__main__":
    main()
