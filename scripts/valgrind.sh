#!/usr/bin/env bash
# Runs the SUNDIALS wrapper's tests (tests/integrate/cvode.rs and arkode.rs, i.e. the `cvode::` and `arkode::` tests of the
# `integrate` test binary) under valgrind's memcheck: fails on any invalid access, use of
# uninitialised memory or *definite* leak (e.g. a SUNDIALS object not freed, a custom linear
# solver's content leaked by a missing ops.free).
#
# "Possibly lost" and "still reachable" blocks are reported but not errors: the Rust test
# harness keeps its threads' state alive at exit. Extra arguments go to the test binary instead
# of the default filter `cvode::` (e.g. `cvode::stop_time_and_reinit`; a filter matching tests of
# other modules of the binary runs those too).
#
# `--test fmu` runs the FMU host tests instead (tests/fmu/: the FMU binary loaded with
# libloading and driven through its C interface, every test by default): the binary's
# instances, their CVODE objects and the error paths must free everything too. Their child
# processes (the jointrom CLI exporting the FMU, cargo) are not traced.
#
# Usage: scripts/valgrind.sh [--test fmu] [TEST_FILTER...]
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

if ! command -v valgrind >/dev/null; then
    echo "valgrind not found: apt-get install --no-install-recommends valgrind" >&2
    exit 2
fi

target=integrate
default_filter=(cvode:: arkode::)
if [[ "${1-}" == "--test" ]]; then
    if [[ "${2-}" != "fmu" ]]; then
        echo "--test takes fmu (the default is the integrate binary's cvode:: tests)" >&2
        exit 2
    fi
    target=fmu
    default_filter=()
    shift 2
    # The FMU binary the tests load, built (and found) beside the jointrom executable.
    cargo build --release -p jointrom-fmu --quiet
fi

# The test binary's path, from cargo's JSON messages (no jq needed).
binary=$(cargo test --release --test "$target" --no-run --message-format=json 2>/dev/null |
    grep '"executable":"' | grep "\"name\":\"$target\"" | tail -n 1 |
    sed -E 's/.*"executable":"([^"]+)".*/\1/')
if [[ -z "$binary" || ! -x "$binary" ]]; then
    echo "could not build or find the tests/$target/ binary" >&2
    exit 2
fi

args=("$@")
if [[ ${#args[@]} -eq 0 && ${#default_filter[@]} -gt 0 ]]; then
    args=("${default_filter[@]}")
fi

start=$(date +%s)
# One test thread: deterministic output, no harness threads alive at exit.
# RUST_BACKTRACE=0: the panic tests would otherwise symbolize backtraces (slow under valgrind).
RUST_BACKTRACE=0 valgrind \
    --leak-check=full \
    --errors-for-leak-kinds=definite \
    --show-leak-kinds=definite,possible \
    --error-exitcode=1 \
    "$binary" --test-threads=1 ${args[@]+"${args[@]}"} || {
    status=$?
    echo "valgrind: tests/$target/ ${args[*]-} FAILED (exit $status: memory errors, definite leaks or a failing test)" >&2
    exit "$status"
}
echo "valgrind: tests/$target/ ${args[*]-} clean (no memory errors, no definite leaks) in $(($(date +%s) - start)) s"
