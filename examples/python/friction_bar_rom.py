"""A 1 % reduced model of the friction bar against the full FE model, from Python.

    pip install ./python matplotlib       # once, from the repository's root
    python examples/python/friction_bar_rom.py [--out friction_bar_rom.png]

Builds the smallest reduced model whose estimated relative L2 error of the contact force norm
is at most 1 %, runs it and the full model over the case's 0.2 s, prints the errors measured
against the full run beside the estimate and the speed-up, and plots ‖f_c‖, ‖f_R‖ and u_y of
both (skipped, with a note, where matplotlib is not installed).
"""

import argparse
import time

import numpy as np

import jointrom as jr


def relative_l2(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="friction_bar")
    ap.add_argument("--tolerance", type=float, default=1e-2)
    ap.add_argument("--out", default="friction_bar_rom.png")
    args = ap.parse_args()

    model = jr.load(args.case)
    print(f"{model.name}: {model.dofs} DOF, {model.pairs} joint pairs")

    t0 = time.perf_counter()
    rom = model.reduce(tolerance=args.tolerance)
    run = rom.transient()
    rom_s = time.perf_counter() - t0
    print(f"reduced model: r = {rom.dimension}, built and run in {rom_s:.2f} s")

    shown = []

    def progress(t, end):
        # About every tenth of the run.
        if int(10 * t / end) > len(shown):
            shown.append(t)
            print(f"  full model: t = {t:.3f} of {end} s", flush=True)

    t0 = time.perf_counter()
    full = model.transient(progress=progress)
    full_s = time.perf_counter() - t0
    print(
        f"full model: {model.dofs} DOF, run in {full_s:.2f} s; integration {full.wall_s:.2f} s "
        f"against the reduced model's {run.wall_s:.3f} s ({full.wall_s / run.wall_s:.0f}×)"
    )

    est = run.error_estimate
    print("relative L2 error against the full run (the reduced model's own estimate):")
    for name, key in [
        ("contact_force_norm", "contact_force"),
        ("friction_force_norm", "friction_force"),
        ("master_uy", "master_uy"),
    ]:
        err = relative_l2(getattr(run, name), getattr(full, name))
        print(f"  {name:20s} {100 * err:7.3f} %   (estimate {100 * est[key]:.3f} %)")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot (pip install matplotlib)")
        return
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 8))
    labels = [("contact_force_norm", "‖f_c‖ (N)"), ("friction_force_norm", "‖f_R‖ (N)"), ("master_uy", "u_y (mm)")]
    for ax, (name, label) in zip(axes, labels):
        ax.plot(full.t, getattr(full, name), "k-", lw=2, label=f"full FE ({model.dofs} DOF)")
        ax.plot(run.t, getattr(run, name), "C1--", lw=1.5, label=f"reduced (r = {rom.dimension})")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend()
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(f"{model.name}: {100 * args.tolerance:g} % reduced model vs the full model")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"plot → {args.out}")


if __name__ == "__main__":
    main()
