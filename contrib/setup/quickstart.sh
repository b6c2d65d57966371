#!/usr/bin/env bash
# The README's quick start on a fresh Debian 12 machine:
#   bash contrib/setup/quickstart.sh run    installs, builds, runs prm/square_pull.prm
#   bash contrib/setup/quickstart.sh test   installs, builds, runs the whole CTest suite,
#                                           then again built by clang with the
#                                           sanitizers, with the fuzz targets
set -euo pipefail

mode="${1:-run}"
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${LACERTA_BUILD_DIR:-$top/build}"

bash "$top/contrib/setup/install-dependencies.sh"

cmake -S "$top" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" --parallel "$(nproc)"

case "$mode" in
  run)
    cd "$top"
    "$build/lacerta" prm/square_pull.prm
    echo "Results: $top/output/square_pull (open solution.pvd in ParaView)"
    ;;
  test)
    # Allow mpirun as root (CI runs as root) for the MPI tests.
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    ctest --test-dir "$build" --parallel "$(nproc)" --output-on-failure --timeout 900
    # The same suite again (but for the long scenes), built by clang with
    # AddressSanitizer and UndefinedBehaviorSanitizer (LACERTA_SANITIZE) and libFuzzer's
    # coverage (LACERTA_FUZZ), with the fuzz.* tests: the first report stops the test
    # that made it. Leak checking is off (MPI and TBB keep their pools to the exit), and
    # so is the check of new/free pairs, which libfreeimage (a dependency of deal.II's
    # OpenCASCADE) breaks in its own exit handler.
    asan="${LACERTA_ASAN_BUILD_DIR:-$top/build-asan}"
    export ASAN_OPTIONS=halt_on_error=1:detect_leaks=0:alloc_dealloc_mismatch=0
    export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
    cmake -S "$top" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_CXX_COMPILER=clang++-14 -DLACERTA_SANITIZE=ON -DLACERTA_FUZZ=ON
    cmake --build "$asan" --parallel "$(nproc)" --target lacerta lacerta-view lacerta-unit-tests \
      lacerta-bench lacerta-fuzz-gmsh_reader lacerta-fuzz-vtk_readers \
      lacerta-fuzz-parameter_file lacerta-fuzz-cutter
    # Without the scenes labelled `long` (tests/CMakeLists.txt): the Release suite has
    # run them.
    ctest --test-dir "$asan" --parallel "$(nproc)" --output-on-failure --timeout 900 \
      --label-exclude long
    ;;
  *)
    echo "usage: $0 run|test" >&2
    exit 2
    ;;
esac
