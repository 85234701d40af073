#!/usr/bin/env bash
# Cross-checks the NASTRAN reader against pyNastran (scripts/pynastran_check.py) in a virtual
# environment of its own (target/py-pynastran: pyNastran 1.4 needs numpy < 2, FMPy numpy >= 2),
# installing pyNastran from PyPI on first use. Skips with a message when python3 or its venv
# module is missing. Needs target/release/jointrom (cargo build --release).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if ! command -v python3 >/dev/null 2>&1; then
    echo "pynastran_check: no python3, skipped"
    exit 0
fi
venv=target/py-pynastran
if [[ ! -x "$venv/bin/python" ]]; then
    if ! python3 -m venv "$venv" >/dev/null 2>&1; then
        echo "pynastran_check: python3 cannot make a virtual environment (python3-venv), skipped"
        exit 0
    fi
fi
if ! "$venv/bin/python" -c "import pyNastran" >/dev/null 2>&1; then
    "$venv/bin/pip" install -q --disable-pip-version-check pyNastran
fi
[[ -x target/release/jointrom ]] || cargo build --release --bin jointrom -q
exec "$venv/bin/python" scripts/pynastran_check.py "$@"
