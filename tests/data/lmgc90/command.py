"""Run the LMGC90 computation of a DATBOX written by ``gen_sample.py`` (pylmgc90.chipy).

Moreau-Jean time stepping (theta = 0.5), nonlinear Gauss-Seidel ('Stored_Delassus_Loops',
quadratic norm); DOF.OUT.n and Vloc_Rloc.OUT.n are written into OUTBOX at the steps listed
below, two of them consecutive (so that a test can take the velocity change over the last step).

* ``sample``: time step 1e-2 s, 500 steps (at rest from about step 400 on); files at steps
  100, 200 (still flowing), 499, 500.
* ``handmade``: time step 1e-3 s, 20 steps; files at steps 19, 20.
* ``periodic``: periodic in x with gen_sample.PERIOD (``chipy.SetPeriodicCondition``, after the
  DATBOX is read); time step 1e-2 s, 600 steps; files at steps 300, 400, 599, 600.

Run it in the folder holding DATBOX: ``python command.py --scene sample``.
"""

import argparse

from pylmgc90 import chipy

SCENES = {"sample": dict(dt=1e-2, steps=500, write=(100, 200, 499, 500), tol=1e-5),
          "handmade": dict(dt=1e-3, steps=20, write=(19, 20), tol=1e-8),
          "periodic": dict(dt=1e-2, steps=600, write=(300, 400, 599, 600), tol=1e-5, period=10.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=tuple(SCENES), default="sample")
    scene = SCENES[parser.parse_args().scene]

    chipy.checkDirectories()
    chipy.utilities_DisableLogMes()
    chipy.SetDimension(2)
    chipy.TimeEvolution_SetTimeStep(scene["dt"])
    chipy.Integrator_InitTheta(0.5)
    chipy.ReadDatbox(deformable=False)
    if "period" in scene:
        chipy.SetPeriodicCondition(xperiod=scene["period"])
    chipy.ComputeMass()
    for k in range(1, scene["steps"] + 1):
        chipy.IncrementStep()
        chipy.ComputeFext()
        chipy.ComputeBulk()
        chipy.ComputeFreeVelocity()
        chipy.SelectProxTactors()
        chipy.RecupRloc()
        chipy.ExSolver("Stored_Delassus_Loops         ", "Quad ", scene["tol"], 1.0, 50, 1000)
        chipy.StockRloc()
        chipy.ComputeDof()
        chipy.UpdateStep()
        if k in scene["write"]:
            chipy.WriteOut(1)
    chipy.Finalize()


if __name__ == "__main__":
    main()
