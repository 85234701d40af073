"""Shared fixtures: the jointrom CLI binary the Python results are compared with, and models."""

import json
import os
import subprocess
from pathlib import Path

import pytest

import jointrom as jr

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Runs `jointrom ARGS` ($JOINTROM_BIN or target/release/jointrom); returns the process."""
    exe = Path(os.environ.get("JOINTROM_BIN", REPO / "target" / "release" / "jointrom"))
    if not exe.is_file():
        pytest.fail(f"the CLI binary {exe} is missing: `cargo build --release` (or set JOINTROM_BIN)")

    def run(*args, check=True):
        p = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"jointrom {' '.join(map(str, args))}: {p.stderr}")
        return p

    def run_json(*args):
        doc = json.loads(run(*args, "--json").stdout)
        # The wall times of the CLI's model build and of the whole command are the process's,
        # not the result's.
        doc.pop("model_s", None)
        doc.pop("total_s", None)
        return doc

    run.json = run_json
    return run


@pytest.fixture(scope="session")
def bar():
    return jr.load("friction_bar")


@pytest.fixture(scope="session")
def bar_tvd(bar):
    return bar.reduce(basis="tvd", g=14)
