#!/usr/bin/env python3
"""The FMU of a reduced model under an independent FMI importer, FMPy (PyPI `fmpy`).

1. builds jointrom and the FMU binary (`cargo build --release`, a no-op when built);
2. exports the friction bar's TVD model (g = 12, r = 28) as ROM JSON and as an FMU;
3. `fmpy validate` on the FMU (schema, model structure, start values, units, binaries);
4. simulates it with `fmpy.simulate_fmu` over 0.02 s with a 1e-4 s communication step and
   compares `master_uy` with `jointrom transient CASE --model file:ROM.json --end-time 0.02`
   (relative L2, contract: <= 1e-3), and prints the figures.

Exits 0 when all of it passes, 1 on a failed check, 2 when FMPy cannot be imported.

Usage: python3 scripts/fmu_check.py [--keep DIR]   (DIR: keep the exported files there)
"""
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
END = 0.02
STEP = 1e-4
TOLERANCE = 1e-3
OUTPUTS = ["master_ux", "master_uy", "master_uz", "master_rx", "master_ry", "master_rz",
           "contact_force_norm", "friction_force_norm"]


def run(cmd, **kw):
    """Runs `cmd`, failing with its standard error if it fails; its standard output."""
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.exit(f"fmu_check: {' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
    return p.stdout


def rel_l2(a, b):
    n = min(len(a), len(b))
    num = sum((a[i] - b[i]) ** 2 for i in range(n)) ** 0.5
    den = sum(b[i] ** 2 for i in range(n)) ** 0.5
    return num / den


def check(work):
    try:
        import fmpy
        from fmpy import simulate_fmu
    except ImportError as e:
        print(f"fmu_check: FMPy not importable ({e}): pip install fmpy", file=sys.stderr)
        return 2
    run(["cargo", "build", "--release", "--quiet"])
    exe = os.path.join(ROOT, "target", "release", "jointrom")
    rom = os.path.join(work, "rom.json")
    fmu = os.path.join(work, "friction_bar.fmu")
    t0 = time.perf_counter()
    print(run([exe, "export", "friction_bar", "--basis", "tvd", "--g", "12",
               "--out", rom, "--fmu", fmu]).strip())
    export_s = time.perf_counter() - t0

    validate = subprocess.run([sys.executable, "-m", "fmpy", "validate", fmu],
                              capture_output=True, text=True)
    verdict = (validate.stdout + validate.stderr).strip()
    print(f"fmpy {fmpy.__version__} validate: {verdict}")
    failed = validate.returncode != 0 or "No problems found" not in verdict

    doc = json.loads(run([exe, "transient", "friction_bar", "--model", f"file:{rom}",
                          "--end-time", str(END), "--json"]))
    uy_ref = doc["curves"]["master_uy"]

    runs = []
    for _ in range(3):
        t0 = time.perf_counter()
        res = simulate_fmu(fmu, stop_time=END, output_interval=STEP, output=OUTPUTS)
        runs.append(time.perf_counter() - t0)
    uy = list(res["master_uy"])
    times = list(res["time"])
    error = rel_l2(uy, uy_ref)
    print(f"FMPy simulate_fmu: {len(times) - 1} steps of {STEP} s to {times[-1]:.4g} s, "
          f"{min(runs) * 1e3:.1f} ms per run (best of 3, including instantiation; "
          f"export {export_s:.2f} s; jointrom transient wall {doc['wall_s'] * 1e3:.1f} ms)")
    print(f"master_uy: FMU {uy[-1]:.6e} mm at {END} s, transient {uy_ref[-1]:.6e} mm; "
          f"relative L2 difference {error:.3e} (tolerance {TOLERANCE:g})")
    print("contact_force_norm at the end: FMU {:.6e} N, transient {:.6e} N".format(
        res["contact_force_norm"][-1], doc["curves"]["contact_force_norm"][-1]))
    if len(times) != len(uy_ref):
        print(f"fmu_check: {len(times)} FMU outputs, {len(uy_ref)} transient outputs",
              file=sys.stderr)
        failed = True
    if not error <= TOLERANCE:
        failed = True
    print("fmu_check: " + ("FAILED" if failed else "passed"))
    return 1 if failed else 0


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--keep":
        os.makedirs(sys.argv[2], exist_ok=True)
        return check(os.path.abspath(sys.argv[2]))
    if len(sys.argv) != 1:
        sys.exit(__doc__)
    with tempfile.TemporaryDirectory(prefix="jointrom_fmu_") as work:
        return check(work)


if __name__ == "__main__":
    sys.exit(main())
