#!/usr/bin/env bash
# Installs everything Lacerta needs on Debian 12 (bookworm) from Debian's packages.
# Run as root (or through sudo). Safe to run again: apt-get skips what is installed.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
# libdeal.ii-dev brings Trilinos, CGAL, gmsh, MPI and TBB; the rest are named explicitly
# because the build or the test suite uses them directly:
#  numdiff, perl     deal.II's DEAL_II_PICKUP_TESTS compares outputs with numdiff
#  openmpi-bin       the MPI tests run under mpirun
#  libvtk9-dev       the VTK mesh reader (.vtk, .vtu)
#  libcgal-dev       implicit-function organ meshes (GridGenerator::implicit_function)
#  libeigen3-dev     small dense algebra, eigenvalue checks in tests
#  libgtest-dev, libbenchmark-dev   unit tests and benchmarks
#  python3-matplotlib  study plots (error against run time)
#  python3-vtk9      the spring-against-FEM render of doc/accuracy.md
#                    (contrib/figures/render_paper_figures.sh)
#  clang-14, libclang-rt-14-dev   the sanitizer and fuzzing build (libFuzzer)
#  libbullet-dev     the optional Bullet peer of the cantilever study
#                    (-DLACERTA_BULLET_PEER=ON, contrib/peers/bullet/)
#  xvfb, xauth       a virtual X display: Debian's VTK renders (lacerta-view, the png
#                    postprocessor) only with an X server, and the tests run under
#                    xvfb-run
$SUDO apt-get install -y --no-install-recommends \
  build-essential cmake ninja-build git \
  libdeal.ii-dev \
  numdiff perl openmpi-bin libopenmpi-dev \
  libvtk9-dev libcgal-dev libeigen3-dev \
  libgtest-dev libbenchmark-dev \
  clang-format python3 python3-matplotlib python3-vtk9 \
  clang-14 libclang-rt-14-dev \
  libbullet-dev \
  xvfb xauth
