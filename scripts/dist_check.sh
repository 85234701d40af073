#!/usr/bin/env bash
# CI check of the distributed path (docs/distributed.md): installs the opt-in MPI
# stack if it is missing (apt-get install -y slepc-dev openmpi-bin), builds the PETSc/SLEPc
# program (scripts/dist.sh build) and runs the equality tests of tests/distributed/ under
# mpirun -n 1 and -n 2: the friction bar (ν = 10 and 30) and its 10⁵-DOF refinement against the
# native path. About 2–3 minutes on the 2-core machine after the release build.
#
# Prints "SKIPPED: ..." and succeeds only when the stack is missing and apt-get cannot install it
# (no apt-get, or not root); any other failure fails.
set -u
cd "$(dirname "$0")/.."
have_stack() {
    pkg-config --exists slepc && command -v mpicc > /dev/null && command -v mpirun > /dev/null
}
if ! have_stack; then
    if ! command -v apt-get > /dev/null; then
        echo "SKIPPED: distributed path check: slepc-dev/openmpi-bin missing and apt-get unavailable"
        exit 0
    fi
    if [ "$(id -u)" != 0 ]; then
        echo "SKIPPED: distributed path check: slepc-dev/openmpi-bin missing and not root (run: apt-get install -y slepc-dev openmpi-bin)"
        exit 0
    fi
    echo "dist_check: installing slepc-dev openmpi-bin"
    export DEBIAN_FRONTEND=noninteractive
    if ! apt-get install -y -q slepc-dev openmpi-bin > /dev/null; then
        apt-get update -q > /dev/null && apt-get install -y -q slepc-dev openmpi-bin > /dev/null || {
            echo "dist_check: FAILED: apt-get install -y slepc-dev openmpi-bin" >&2
            exit 1
        }
    fi
    have_stack || { echo "dist_check: FAILED: SLEPc still not found after the install" >&2; exit 1; }
fi
scripts/dist.sh build || exit 1
export JOINTROM_SLEPC="$PWD/target/distributed/jointrom_slepc"
cargo test --release --test distributed -- --include-ignored --test-threads=1 --nocapture || {
    echo "dist_check: FAILED: tests/distributed" >&2
    exit 1
}
echo "dist_check: distributed path equals the native path (friction bar, 10⁵-DOF refinement; 1 and 2 ranks)"
