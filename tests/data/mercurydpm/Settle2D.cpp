// A small 2D MercuryDPM run for grainview's reader tests (tests/data/mercurydpm/make_fixtures.py
// builds and runs it): 32 polydisperse frictional disks dropped under gravity into a box of four
// InfiniteWalls (floor, two sides, a lid they never reach), settling to rest. MercuryDPM's own
// nondimensional units: radii 0.4 to 0.6, density 1, gravity 1, collision time 0.05.
// Usage: Settle2D [seed]  (writes Settle2D.data, Settle2D.fstat, Settle2D.restart in the current folder)
#include <Mercury2D.h>
#include <Species/LinearViscoelasticSlidingFrictionSpecies.h>
#include <Walls/InfiniteWall.h>
#include <cstdlib>

class Settle2D : public Mercury2D
{
public:
    unsigned long seed = 1;

    void setupInitialConditions() override
    {
        random.setRandomSeed(seed);
        InfiniteWall w;
        w.setSpecies(speciesHandler.getObject(0));
        w.set(Vec3D(0.0, -1.0, 0.0), Vec3D(0.0, getYMin(), 0.0));  // floor
        wallHandler.copyAndAddObject(w);
        w.set(Vec3D(1.0, 0.0, 0.0), Vec3D(getXMax(), 0.0, 0.0));   // right
        wallHandler.copyAndAddObject(w);
        w.set(Vec3D(0.0, 1.0, 0.0), Vec3D(0.0, getYMax(), 0.0));   // lid
        wallHandler.copyAndAddObject(w);
        w.set(Vec3D(-1.0, 0.0, 0.0), Vec3D(getXMin(), 0.0, 0.0));  // left
        wallHandler.copyAndAddObject(w);

        SphericalParticle p;
        p.setSpecies(speciesHandler.getObject(0));
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 8; ++col)
            {
                p.setRadius(random.getRandomNumber(0.4, 0.6));
                p.setPosition(Vec3D(0.65 + 1.3 * col + random.getRandomNumber(-0.02, 0.02), 0.7 + 1.3 * row, 0.0));
                p.setVelocity(Vec3D(random.getRandomNumber(-0.1, 0.1), 0.0, 0.0));
                particleHandler.copyAndAddObject(p);
            }
    }
};

int main(int argc, char* argv[])
{
    Settle2D problem;
    if (argc > 1) problem.seed = std::strtoul(argv[1], nullptr, 10);
    problem.setName("Settle2D");
    problem.setDimension(2);  // a 2D system of disks: mass = density pi r^2, inertia = m r^2 / 2
    problem.setGravity(Vec3D(0.0, -1.0, 0.0));
    problem.setMin(Vec3D(0.0, 0.0, -0.5));
    problem.setMax(Vec3D(10.4, 10.0, 0.5));
    problem.setTimeMax(40.0);

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
    problem.setSaveCount(5000);  // a snapshot every 5 time units: 9 snapshots
    problem.dataFile.setFileType(FileType::ONE_FILE);
    problem.fStatFile.setFileType(FileType::ONE_FILE);
    problem.restartFile.setFileType(FileType::ONE_FILE);
    problem.eneFile.setFileType(FileType::NO_FILE);
    problem.setXBallsAdditionalArguments("");
    problem.solve();
    return 0;
}
