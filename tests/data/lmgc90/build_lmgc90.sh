#!/usr/bin/env bash
# Build LMGC90 (2D rigid bodies + its Python interface pylmgc90) from its public source, for the
# LMGC90 reader's fixtures (make_fixtures.py) and the test that regenerates a run.
#
# Source: https://github.com/petrasvestartas/lmgc90_installation, commit
# 60614b1503c6dcd79bbde9fd18882921fe9e4ae6 (a copy of LMGC90's source tree; CMakeLists.txt says
# version 3.0.0, release candidate 1 of 2025). Tested on Debian 12 with gfortran 12.2, SWIG 4.1,
# CMake 3.25 and CPython 3.11 with numpy 2: about 7 minutes on two cores.
#
#   tests/data/lmgc90/build_lmgc90.sh            # sources in $LMGC90_SRC, build in $LMGC90_BUILD
#   PYTHONPATH=$LMGC90_BUILD python -c "from pylmgc90 import chipy"
#
# Options: HDF5 off (the text files DOF.OUT / Vloc_Rloc.OUT are what the reader reads), no
# sparse solver (MUMPS: only deformable bodies need it), no MatLib (deformable material laws),
# no documentation, no tests, no rTree/ANN bindings; nothing is installed (the build folder holds
# the pylmgc90 package).
set -euo pipefail

SRC=${LMGC90_SRC:-/work/lmgc90-src}
BUILD=${LMGC90_BUILD:-/work/lmgc90-build}
COMMIT=60614b1503c6dcd79bbde9fd18882921fe9e4ae6
PYTHON=${PYTHON:-$(command -v python3)}

if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
        gfortran g++ cmake make swig liblapack-dev libopenblas-dev python3-dev git
fi
"$PYTHON" -c "import numpy" # numpy's headers are needed by the SWIG interface

if [ ! -e "$SRC/CMakeLists.txt" ]; then
    git clone https://github.com/petrasvestartas/lmgc90_installation "$SRC"
    git -C "$SRC" checkout "$COMMIT"
fi

mkdir -p "$BUILD"
cd "$BUILD"
nice -n 19 cmake "$SRC" \
    -DCMAKE_BUILD_TYPE=Release \
    -DPython_EXECUTABLE="$PYTHON" \
    -DWITH_HDF5=OFF \
    -DSPARSE_LIBRARY=none \
    -DMATLIB_VERSION=none \
    -DNO_INSTALL=ON \
    -DNO_TEST=ON \
    -DNO_DOXYGEN=ON \
    -DWITH_DOCSTRING=OFF \
    -DBUILD_rTree_BINDING=OFF \
    -DBUILD_ANN_BINDING=OFF
nice -n 19 make -j2
PYTHONPATH="$BUILD" "$PYTHON" -c "from pylmgc90 import chipy, pre; print('pylmgc90 built in $BUILD')"
