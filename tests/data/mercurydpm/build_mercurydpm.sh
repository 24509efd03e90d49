#!/bin/bash
# Build MercuryDPM's Kernel library (libMercuryBase.a) and the drivers of this folder (Settle2D, Periodic2D).
#
#   tests/data/mercurydpm/build_mercurydpm.sh SOURCE BUILD
#
# SOURCE: a MercuryDPM source tree (github.com/MercuryDPM/MercuryDPM, or a fork of it; the
# committed fixtures were made from the fork kuwt/MercuryDPM_fork at fb0ebf1, 2024-07-26, "add
# collision measure"). BUILD: the build folder (created). Needs cmake, g++ and gfortran (the
# kernel's small linear-algebra library is Fortran). Only the kernel is built (about 6 minutes
# on one core at -O1), then the drivers are compiled and linked by hand; the executables are
# BUILD/Settle2D and BUILD/Periodic2D. tests/data/mercurydpm/make_fixtures.py runs them. A BUILD
# that already holds the kernel is reused (make does nothing), so the drivers alone are rebuilt.
set -euo pipefail
SOURCE=$(cd "$1" && pwd)
BUILD=$2
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$BUILD"
BUILD=$(cd "$BUILD" && pwd)
cd "$BUILD"
cmake "$SOURCE" -DMercuryDPM_KERNEL_ONLY=ON -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE=-O1 \
      -DCMAKE_Fortran_FLAGS_RELEASE=-O1 > cmake.log
nice -n 15 make -j1 MercuryBase > make.log
# the driver is compiled with the kernel's own definitions, includes and flags (CMake's flags.make)
FLAGS=Kernel/CMakeFiles/MercuryBase.dir/flags.make
field() { sed -n "s/^$1 = //p" "$FLAGS"; }
for driver in Settle2D Periodic2D; do
    nice -n 15 g++ $(field CXX_DEFINES) $(field CXX_INCLUDES) $(field CXX_FLAGS) "$HERE/$driver.cpp" -o $driver \
        Kernel/libMercuryBase.a Kernel/Math/libLinearAlgebra.a -lgfortran -lpthread
    echo "$BUILD/$driver"
done
