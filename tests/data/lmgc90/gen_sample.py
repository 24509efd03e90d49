"""Write the DATBOX of an LMGC90 2D run (pylmgc90.pre), for the LMGC90 reader's fixtures.

Two scenes, chosen with ``--scene``:

* ``sample`` (default): 36 regular pentagons (POLYG) and 12 disks (DISKx) on a square lattice
  in a box of four JONCx walls, under gravity; contact law IQS_CLB, friction 0.4 everywhere.
  Radii are drawn from [0.4, 0.6] m with ``--seed`` (default 7).
* ``periodic``: 30 regular pentagons and 10 disks (radii from [0.4, 0.6] m, ``--seed``) on a
  lattice between a floor and a lid (two JONCx spanning the cell), thrown sideways at up to
  1 m/s under gravity; command.py makes the run periodic in x with period :data:`PERIOD`
  (``chipy.SetPeriodicCondition(xperiod=PERIOD)``: LMGC90 keeps x in [0, PERIOD]).
* ``handmade``: bodies whose forces are known by hand, far enough apart not to touch one
  another: a disk resting on a floor (DKJCx) with a second disk on top of it (DKDKx); a
  square (POLYG, 4 vertices) resting on a floor with a second square on top of it, face to
  face (PLJCx and two PLPLx points each); a square resting on a floor tilted by 0.2 rad
  (friction 0.4 > tan 0.2, so it sticks); a disk resting on a square (DKPLx).

Run in an empty folder, then ``command.py`` there (same ``--scene``):

    python gen_sample.py --scene sample && python command.py --scene sample

Every body's material density is 1000 kg/m2 per unit thickness (LMGC90's 2D masses are
density x area); gravity is (0, -9.81) m/s2.
"""

import argparse
import math
from pathlib import Path

import numpy as np
from pylmgc90 import pre

PERIOD = 10.0
"""The x period of the ``periodic`` scene (m): 8 columns of pitch 1.25."""
FRICTION = 0.4
DENSITY = 1000.0
GRAVITY = [0.0, -9.81, 0.0]


def containers():
    mats, mods, svs, tacts = pre.materials(), pre.models(), pre.see_tables(), pre.tact_behavs()
    grain = pre.material(name="PLEXx", materialType="RIGID", density=DENSITY)
    wall = pre.material(name="TDURx", materialType="RIGID", density=DENSITY)
    mats.addMaterial(grain, wall)
    mod = pre.model(name="rigid", physics="MECAx", element="Rxx2D", dimension=2)
    mods.addModel(mod)
    law = pre.tact_behav(name="iqsc0", law="IQS_CLB", fric=FRICTION)
    tacts += law
    pairs = [("DISKx", "BLEUx", "DISKx", "BLEUx"), ("DISKx", "BLEUx", "JONCx", "WALLx"),
             ("POLYG", "BLEUx", "POLYG", "BLEUx"), ("POLYG", "BLEUx", "JONCx", "WALLx"),
             ("DISKx", "BLEUx", "POLYG", "BLEUx")]
    for cd, cdcolor, an, ancolor in pairs:
        svs += pre.see_table(CorpsCandidat="RBDY2", candidat=cd, colorCandidat=cdcolor, behav=law,
                             CorpsAntagoniste="RBDY2", antagoniste=an, colorAntagoniste=ancolor, alert=0.05)
    return mats, mods, svs, tacts, grain, wall, mod


def jonc(bodies, mod, wall, half_length, half_thickness, centre, angle=0.0):
    body = pre.rigidJonc(axe1=half_length, axe2=half_thickness, center=list(centre), model=mod, material=wall,
                         color="WALLx")
    if angle:
        body.rotate(psi=angle, center=body.nodes[1].coor)
    body.imposeDrivenDof(component=[1, 2, 3], dofty="vlocy")
    bodies += body
    return body


def sample(bodies, mod, grain, wall, seed):
    rng = np.random.default_rng(seed)
    columns, rows, pitch = 8, 6, 1.25
    width, height = columns * pitch, rows * pitch + 2.0
    k = 0
    for row in range(rows):
        for column in range(columns):
            radius = rng.uniform(0.4, 0.6)
            centre = [pitch * (column + 0.5), pitch * (row + 0.5)]
            if k % 4 == 3:  # one disk in four
                bodies += pre.rigidDisk(r=radius, center=centre, model=mod, material=grain, color="BLEUx")
            else:
                bodies += pre.rigidPolygon(model=mod, material=grain, center=centre, theta=rng.uniform(0, 2 * math.pi),
                                           color="BLEUx", generation_type="regular", nb_vertices=5, radius=radius)
            k += 1
    t = 0.2  # walls' half thickness
    jonc(bodies, mod, wall, 0.5 * width + t, t, (0.5 * width, -t))  # bottom
    jonc(bodies, mod, wall, 0.5 * width + t, t, (0.5 * width, height + t))  # top
    jonc(bodies, mod, wall, 0.5 * height + t, t, (-t, 0.5 * height), angle=-0.5 * math.pi)  # left
    jonc(bodies, mod, wall, 0.5 * height + t, t, (width + t, 0.5 * height), angle=0.5 * math.pi)  # right


def periodic(bodies, mod, grain, wall, seed):
    rng = np.random.default_rng(seed)
    columns, rows, pitch = 8, 5, PERIOD / 8
    height = rows * pitch + 1.0
    k = 0
    for row in range(rows):
        for column in range(columns):
            radius = rng.uniform(0.4, 0.6)
            centre = [pitch * (column + 0.5), pitch * (row + 0.5)]
            if k % 4 == 3:  # one disk in four
                body = pre.rigidDisk(r=radius, center=centre, model=mod, material=grain, color="BLEUx")
            else:
                body = pre.rigidPolygon(model=mod, material=grain, center=centre, theta=rng.uniform(0, 2 * math.pi),
                                        color="BLEUx", generation_type="regular", nb_vertices=5, radius=radius)
            body.imposeInitValue(component=1, value=rng.uniform(-1.0, 1.0))
            bodies += body
            k += 1
    t = 0.2  # walls' half thickness; they span the cell and a wall's thickness beyond it
    jonc(bodies, mod, wall, 0.5 * PERIOD + t, t, (0.5 * PERIOD, -t))  # floor
    jonc(bodies, mod, wall, 0.5 * PERIOD + t, t, (0.5 * PERIOD, height + t))  # lid


def handmade(bodies, mod, grain, wall):
    t = 0.1
    # a disk on a floor, a second disk on top of it
    jonc(bodies, mod, wall, 2.0, t, (0.0, -t))
    bodies += pre.rigidDisk(r=0.5, center=[0.0, 0.5], model=mod, material=grain, color="BLEUx")
    bodies += pre.rigidDisk(r=0.3, center=[0.0, 1.3], model=mod, material=grain, color="BLEUx")
    # a square on a floor, a second square on top of it, face to face
    jonc(bodies, mod, wall, 2.0, t, (6.0, -t))
    side = 0.8
    for y in (0.5 * side, 1.5 * side):
        bodies += pre.rigidPolygon(model=mod, material=grain, center=[6.0, y], theta=0.25 * math.pi, color="BLEUx",
                                   generation_type="regular", nb_vertices=4, radius=side / math.sqrt(2))
    # a square on a floor tilted by 0.2 rad: it sticks (tan 0.2 < 0.4)
    alpha = 0.2
    jonc(bodies, mod, wall, 2.0, t, (12.0, -t), angle=alpha)
    normal = np.array([-math.sin(alpha), math.cos(alpha)])
    centre = np.array([12.0, -t]) + (t + 0.5 * side) * normal
    bodies += pre.rigidPolygon(model=mod, material=grain, center=list(centre), theta=0.25 * math.pi + alpha,
                               color="BLEUx", generation_type="regular", nb_vertices=4, radius=side / math.sqrt(2))
    # a disk resting on a square resting on a floor
    jonc(bodies, mod, wall, 2.0, t, (18.0, -t))
    bodies += pre.rigidPolygon(model=mod, material=grain, center=[18.0, 0.5 * side], theta=0.25 * math.pi,
                               color="BLEUx", generation_type="regular", nb_vertices=4, radius=side / math.sqrt(2))
    bodies += pre.rigidDisk(r=0.25, center=[18.0, side + 0.25], model=mod, material=grain, color="BLEUx")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=("sample", "handmade", "periodic"), default="sample")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    mats, mods, svs, tacts, grain, wall, mod = containers()
    bodies = pre.avatars()
    if args.scene == "sample":
        sample(bodies, mod, grain, wall, args.seed)
    elif args.scene == "periodic":
        periodic(bodies, mod, grain, wall, args.seed)
    else:
        handmade(bodies, mod, grain, wall)
    Path("DATBOX").mkdir(exist_ok=True)
    pre.writeDatbox(2, mats, mods, bodies, tacts, svs, datbox_path="DATBOX", gravy=GRAVITY)


if __name__ == "__main__":
    main()
