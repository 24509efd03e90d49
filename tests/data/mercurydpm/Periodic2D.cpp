// Small 2D MercuryDPM runs in periodic cells for grainview's reader tests
// (tests/data/mercurydpm/make_fixtures.py builds and runs it; build_mercurydpm.sh compiles it):
//
//   Periodic2D periodic [seed]  -> Periodic2D.data .fstat .restart: 100 polydisperse frictional
//       disks on a perturbed 10 x 10 grid, squeezed (solid fraction about 0.88, overlapping) in a
//       cell periodic in x and y (two PeriodicBoundary), no gravity: they push apart and settle into
//       a jammed packing whose contacts cross the cell's edges.
//   Periodic2D lees [seed]      -> LeesEdwards2D.*: the same packing in a LeesEdwardsBoundary (periodic
//       in x, and in y with the images across the top and bottom shifted in x by shift(t) = v t,
//       v = 1): simple shear driven through the boundary; the shift passes half the cell's width.
//   Periodic2D channel [seed]   -> Channel2D.*: 40 disks under gravity between a floor and a lid
//       (InfiniteWalls), periodic in x only (one PeriodicBoundary).
//   Periodic2D tilted [seed]    -> Tilted2D.*: the periodic packing in a fixed tilted cell: the
//       PeriodicBoundary across y shifts its images by 2 in x too (setPlanewiseShift); it is added
//       before the one across x, which then wraps in x what it moved. Up to t = 2 only (2 snapshots).
//
// MercuryDPM's own nondimensional units: radii 0.4 to 0.6, density 1, collision time 0.05, time step
// 0.001; a snapshot every 2 time units (saveCount 2000) up to t = 6 (4 snapshots; the first, at t = 0,
// holds the forces of MercuryDPM's initial computation on the squeezed grid).
#include <Mercury2D.h>
#include <Species/LinearViscoelasticSlidingFrictionSpecies.h>
#include <Walls/InfiniteWall.h>
#include <Boundaries/PeriodicBoundary.h>
#include <Boundaries/LeesEdwardsBoundary.h>
#include <cstdlib>
#include <string>

class Periodic2D : public Mercury2D
{
public:
    unsigned long seed = 1;
    std::string mode = "periodic";
    int nx = 10, ny = 10;
    Mdouble spacing = 0.95;
    Mdouble velocity = 1.0;  // the Lees-Edwards shift's rate

    void setupInitialConditions() override
    {
        random.setRandomSeed(seed);
        const Mdouble l = getXMax() - getXMin(), h = getYMax() - getYMin();
        if (mode == "lees")
        {
            LeesEdwardsBoundary le;
            const Mdouble v = velocity;
            le.set([v](Mdouble t) { return v * t; }, [v](Mdouble t UNUSED) { return v; }, getXMin(), getXMax(),
                   getYMin(), getYMax());
            boundaryHandler.copyAndAddObject(le);
        }
        else
        {
            PeriodicBoundary b;
            if (mode == "tilted")
            {
                b.set(Vec3D(0.0, 1.0, 0.0), getYMin(), getYMax());
                b.setPlanewiseShift(Vec3D(2.0, 0.0, 0.0));
                boundaryHandler.copyAndAddObject(b);
            }
            b.set(Vec3D(1.0, 0.0, 0.0), getXMin(), getXMax());
            boundaryHandler.copyAndAddObject(b);
            if (mode == "periodic")
            {
                b.set(Vec3D(0.0, 1.0, 0.0), getYMin(), getYMax());
                boundaryHandler.copyAndAddObject(b);
            }
            else if (mode == "channel")  // walls across y
            {
                InfiniteWall w;
                w.setSpecies(speciesHandler.getObject(0));
                w.set(Vec3D(0.0, -1.0, 0.0), Vec3D(0.0, getYMin(), 0.0));  // floor
                wallHandler.copyAndAddObject(w);
                w.set(Vec3D(0.0, 1.0, 0.0), Vec3D(0.0, getYMax(), 0.0));   // lid
                wallHandler.copyAndAddObject(w);
            }
        }
        SphericalParticle p;
        p.setSpecies(speciesHandler.getObject(0));
        const Mdouble sx = l / nx, sy = (mode == "channel") ? 1.25 : h / ny;
        for (int row = 0; row < ny; ++row)
            for (int col = 0; col < nx; ++col)
            {
                p.setRadius(random.getRandomNumber(0.4, 0.6));
                p.setPosition(Vec3D(getXMin() + sx * (col + 0.5) + random.getRandomNumber(-0.05, 0.05),
                                    getYMin() + sy * (row + 0.5) + random.getRandomNumber(-0.05, 0.05), 0.0));
                p.setVelocity(Vec3D(random.getRandomNumber(-0.1, 0.1), random.getRandomNumber(-0.1, 0.1), 0.0));
                particleHandler.copyAndAddObject(p);
            }
    }
};

int main(int argc, char* argv[])
{
    Periodic2D problem;
    if (argc > 1) problem.mode = argv[1];
    if (argc > 2) problem.seed = std::strtoul(argv[2], nullptr, 10);
    if (problem.mode != "periodic" && problem.mode != "lees" && problem.mode != "channel" && problem.mode != "tilted")
    {
        std::cerr << "usage: Periodic2D periodic|lees|channel|tilted [seed]\n";
        return 2;
    }
    problem.setName(problem.mode == "periodic" ? "Periodic2D" : problem.mode == "lees" ? "LeesEdwards2D" :
                    problem.mode == "channel" ? "Channel2D" : "Tilted2D");
    problem.setDimension(2);  // a 2D system of disks: mass = density pi r^2, inertia = m r^2 / 2
    if (problem.mode == "channel")
    {
        problem.nx = 8;
        problem.ny = 5;
        problem.setGravity(Vec3D(0.0, -1.0, 0.0));
        problem.setMin(Vec3D(0.0, 0.0, -0.5));
        problem.setMax(Vec3D(8.4, 8.0, 0.5));
    }
    else
    {
        problem.setGravity(Vec3D(0.0, 0.0, 0.0));
        problem.setMin(Vec3D(0.0, 0.0, -0.5));
        problem.setMax(Vec3D(problem.nx * problem.spacing, problem.ny * problem.spacing, 0.5));
    }
    problem.setTimeMax(problem.mode == "tilted" ? 2.0 : 6.0);

    LinearViscoelasticSlidingFrictionSpecies species;
    species.setDensity(1.0);
    const Mdouble tc = 0.05, restitution = 0.5;
    const Mdouble mass = species.getDensity() * constants::pi * 0.4 * 0.4;  // the lightest disk
    species.setCollisionTimeAndRestitutionCoefficient(tc, restitution, mass);
    species.setSlidingStiffness(2.0 / 7.0 * species.getStiffness());
    species.setSlidingDissipation(2.0 / 7.0 * species.getDissipation());
    species.setSlidingFrictionCoefficient(0.5);
    problem.speciesHandler.copyAndAddObject(species);

    problem.setTimeStep(tc / 50.0);
    problem.setSaveCount(2000);  // a snapshot every 2 time units: t = 0, 2, 4, 6
    problem.dataFile.setFileType(FileType::ONE_FILE);
    problem.fStatFile.setFileType(FileType::ONE_FILE);
    problem.restartFile.setFileType(FileType::ONE_FILE);
    problem.eneFile.setFileType(FileType::NO_FILE);
    problem.setXBallsAdditionalArguments("");
    problem.solve();
    return 0;
}
