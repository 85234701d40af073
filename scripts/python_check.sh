#!/usr/bin/env bash
# The Python package (python/, docs/guide/python.md): a fresh virtual environment
# (/tmp/jr-venv), `pip install ./python pytest numpy` (maturin builds the extension into the
# workspace's target/), scipy if it installs, then the pytest suite python/tests/ against
# target/release/jointrom (cargo build --release). Skips with a message only when pip cannot
# reach PyPI; any other failure fails.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
venv=${JOINTROM_VENV:-/tmp/jr-venv}
start=$SECONDS
if ! command -v python3 >/dev/null 2>&1; then
    echo "python_check: no python3, skipped"
    exit 0
fi
rm -rf "$venv"
python3 -m venv "$venv"
pip=("$venv/bin/pip" --disable-pip-version-check)
probe=$(mktemp -d)
if ! "${pip[@]}" download -q --no-deps -d "$probe" maturin >/dev/null 2>&1; then
    rm -rf "$probe"
    echo "python_check: SKIPPED: pip cannot reach PyPI (maturin, numpy, pytest are needed)"
    exit 0
fi
rm -rf "$probe"
[[ -x target/release/jointrom && -f target/release/libjointrom_fmu.so ]] || cargo build --release -q
"${pip[@]}" install -q pytest numpy
"${pip[@]}" install -q ./python
"${pip[@]}" install -q scipy || echo "python_check: scipy did not install: K and M come as tuples"
echo "python_check: venv and build $((SECONDS - start)) s"
# From the repository's root, so `jointrom` is the installed package, not python/jointrom/.
"$venv/bin/pytest" -q python/tests
echo "python_check: $((SECONDS - start)) s in all"
