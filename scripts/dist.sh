#!/usr/bin/env bash
# The distributed path's PETSc/SLEPc program (docs/distributed.md). Opt-in: the
# default `cargo build` needs none of this.
#
#     scripts/dist.sh install    # apt-get install -y slepc-dev openmpi-bin (as root)
#     scripts/dist.sh build      # mpicc distributed/jointrom_slepc.c → target/distributed/jointrom_slepc
#     scripts/dist.sh table      # the comparison table: friction bar (ν = 10, 30) and the
#                                # 10⁵-DOF refinement, native vs 1 and 2 MPI ranks
#
# Run from the repository root.
set -eu
out=target/distributed/jointrom_slepc
case "${1:-build}" in
install)
    DEBIAN_FRONTEND=noninteractive apt-get install -y slepc-dev openmpi-bin
    ;;
build)
    if ! pkg-config --exists slepc || ! command -v mpicc > /dev/null; then
        echo "scripts/dist.sh build: SLEPc or mpicc not found; install them with" \
             "\`scripts/dist.sh install\` (apt-get install -y slepc-dev openmpi-bin)" >&2
        exit 1
    fi
    mkdir -p "$(dirname "$out")"
    # shellcheck disable=SC2046 # pkg-config's flags are meant to split
    mpicc -O2 -Wall -Wextra -Werror -o "$out" distributed/jointrom_slepc.c \
        $(pkg-config --cflags --libs slepc)
    echo "built $out (SLEPc $(pkg-config --modversion slepc), PETSc $(pkg-config --modversion petsc))"
    ;;
table)
    bin=target/release/jointrom
    "$bin" distributed friction_bar --nu 10
    "$bin" distributed friction_bar --nu 30
    "$bin" distributed cases/scale/friction_bar_x13.json --nu 10
    ;;
*)
    echo "usage: scripts/dist.sh install | build | table" >&2
    exit 2
    ;;
esac
