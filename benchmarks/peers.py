"""Peer engines on the same pile: pymunk (Chipmunk2D) and Box2D 2.3.

Run in the peers' own environment (``benchmarks/requirements-peers.txt``; they are not project
dependencies)::

    python -m benchmarks.peers PILE.npz OUT.npz --engine pymunk --steps 200 --iterations 50

The pile (``PILE.npz``: position (N, 2), angle, radius (circumscribed, m), n_vertices,
first_vertex and local_vertices (the shape table's body-frame vertices),
density, box (x0, y0, x1, y1), gravity, dt, friction) is settled once and saved by
``benchmarks/solver_bench/peer_engines.py``; every engine is timed on the same reloaded pile, as
``../shared/PEERS.md`` recommends. The engine steps ``--steps`` times with a fixed iteration
budget and writes the final positions and angles (the caller measures the overlaps with this
project's narrow phase, one metric for all engines), the wall time per step, and the force on
the floor in each of ``--measured`` further steps, not timed (to compare with the weight: in a
pile at rest every step's floor force is the weight).

Fairness notes (PEERS.md): pymunk combines friction by product, Box2D by geometric mean: both
get per-shape coefficients that give mu = 0.4 between grains and 0 with walls. Box2D runs in
units of 2.5 cm (its tolerances assume metre-sized bodies), lengths and gravity scaled.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np


def local_vertices(pile, p):
    """(n, 2) m, the vertices of particle ``p`` in its own frame, as the project's shape table
    (``solver.shapes.Shapes``) wrote them into the pile."""
    first = pile["first_vertex"]
    return pile["local_vertices"][first[p]:first[p + 1]]


def run_pymunk(pile, steps, iterations, measured):
    import pymunk

    space = pymunk.Space()
    space.gravity = tuple(pile["gravity"])
    space.iterations = int(iterations)
    space.collision_slop = 1e-5  # metres: far below the 1e-3 d overlap budget
    x0, y0, x1, y1 = pile["box"]
    static = space.static_body
    walls = [pymunk.Segment(static, (x0 - 1, y0), (x1 + 1, y0), 0.0),  # floor
             pymunk.Segment(static, (x0, y0 - 1), (x0, y1 + 10), 0.0),
             pymunk.Segment(static, (x1, y0 - 1), (x1, y1 + 10), 0.0)]
    for w in walls:
        w.friction, w.elasticity = 0.0, 0.0
    floor = walls[0]
    space.add(*walls)
    mu_shape = math.sqrt(float(pile["friction"]))
    bodies = []
    for p in range(len(pile["radius"])):
        r, n = float(pile["radius"][p]), int(pile["n_vertices"][p])
        if n == 0:
            area = math.pi * r * r
            mass = float(pile["density"]) * area
            body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0, r))
            shape = pymunk.Circle(body, r)
        else:
            verts = [tuple(v) for v in local_vertices(pile, p)]
            area = pymunk.area_for_poly(verts)
            mass = float(pile["density"]) * area
            body = pymunk.Body(mass, pymunk.moment_for_poly(mass, verts))
            shape = pymunk.Poly(body, verts, radius=0.0)
        body.position = tuple(pile["position"][p])
        body.angle = float(pile["angle"][p])
        shape.friction, shape.elasticity = mu_shape, 0.0
        space.add(body, shape)
        bodies.append(body)
    dt = float(pile["dt"])
    floor_force = []

    def floor_impulse():
        """Sum of the normal impulses of the arbiters that involve the floor (N s)."""
        acc = [0.0]

        def on_arbiter(arbiter):
            if floor in arbiter.shapes:
                acc[0] += abs(arbiter.total_impulse[1])
        for body in bodies:
            body.each_arbiter(on_arbiter)
        return acc[0]

    start = time.perf_counter()
    for k in range(steps):
        space.step(dt)
    elapsed = time.perf_counter() - start
    for k in range(measured):  # force measurement, not timed
        space.step(dt)
        floor_force.append(floor_impulse() / dt)
    pos = np.array([b.position for b in bodies])
    ang = np.array([b.angle for b in bodies])
    return pos, ang, elapsed / steps, np.array(floor_force)


def run_box2d(pile, steps, iterations, measured):
    import Box2D as b2

    unit = 0.025  # length unit of the simulation, m
    g = np.asarray(pile["gravity"]) / unit
    world = b2.b2World(gravity=(float(g[0]), float(g[1])), doSleep=False)
    x0, y0, x1, y1 = np.asarray(pile["box"]) / unit
    ground = world.CreateStaticBody()
    floor_fixture = ground.CreateEdgeFixture(vertices=[(x0 - 40, y0), (x1 + 40, y0)], friction=0.0)
    floor_fixture.userData = "floor"  # SWIG proxies are not identical objects: tag the fixture
    ground.CreateEdgeFixture(vertices=[(x0, y0 - 40), (x0, y1 + 400)], friction=0.0)
    ground.CreateEdgeFixture(vertices=[(x1, y0 - 40), (x1, y1 + 400)], friction=0.0)
    mu_shape = float(pile["friction"])  # geometric mean of equal coefficients
    bodies = []
    # density in Box2D units: mass must match (mass = rho_2d * area, area scaled by unit^2)
    for p in range(len(pile["radius"])):
        r, n = float(pile["radius"][p]) / unit, int(pile["n_vertices"][p])
        pos = np.asarray(pile["position"][p]) / unit
        body = world.CreateDynamicBody(position=(float(pos[0]), float(pos[1])), angle=float(pile["angle"][p]),
                                       bullet=False)
        if n == 0:
            body.CreateCircleFixture(radius=r, density=1.0, friction=mu_shape, restitution=0.0)
        else:
            body.CreatePolygonFixture(vertices=[tuple(v) for v in local_vertices(pile, p) / unit], density=1.0,
                                      friction=mu_shape, restitution=0.0)
        bodies.append(body)

    class FloorListener(b2.b2ContactListener):
        def __init__(self):
            super().__init__()
            self.impulse = 0.0

        def PostSolve(self, contact, impulse):
            if "floor" in (contact.fixtureA.userData, contact.fixtureB.userData):
                self.impulse += sum(impulse.normalImpulses[: contact.manifold.pointCount])

    dt = float(pile["dt"])
    start = time.perf_counter()
    for k in range(steps):
        world.Step(dt, int(iterations), int(iterations))
    elapsed = time.perf_counter() - start
    listener = FloorListener()
    world.contactListener = listener
    # impulses are in (density-1 mass units) x unit/s: convert to the weight ratio directly
    weight_b2 = sum(b.mass for b in bodies) * abs(g[1])
    floor_ratio = []
    for k in range(measured):
        listener.impulse = 0.0
        world.Step(dt, int(iterations), int(iterations))
        floor_ratio.append(listener.impulse / dt / weight_b2)
    pos = np.array([b.position for b in bodies]) * unit
    ang = np.array([b.angle for b in bodies])
    return pos, ang, elapsed / steps, np.array(floor_ratio)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pile")
    parser.add_argument("out")
    parser.add_argument("--engine", choices=["pymunk", "box2d"], required=True)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--iterations", type=int, default=50)
    parser.add_argument("--measured", type=int, default=100, help="untimed steps whose floor force is recorded")
    args = parser.parse_args()
    if args.steps < 1 or args.iterations < 1 or args.measured < 1:
        parser.error(f"--steps {args.steps}, --iterations {args.iterations}, --measured {args.measured}: expected "
                     "whole numbers >= 1")
    pile = dict(np.load(args.pile))
    if args.engine == "pymunk":
        pos, ang, per_step, floor = run_pymunk(pile, args.steps, args.iterations, args.measured)
        mass = float(pile["density"]) * _areas(pile).sum()
        floor_ratio = floor / (mass * abs(pile["gravity"][1]))
    else:
        pos, ang, per_step, floor_ratio = run_box2d(pile, args.steps, args.iterations, args.measured)
    np.savez(args.out, position=pos, angle=ang, time_per_step=per_step, floor_over_weight=floor_ratio)


def _areas(pile):
    r, n = pile["radius"], pile["n_vertices"]
    safe = np.where(n >= 3, n, 3)
    return np.where(n >= 3, 0.5 * safe * r**2 * np.sin(2 * np.pi / safe), np.pi * r**2)


if __name__ == "__main__":
    main()
