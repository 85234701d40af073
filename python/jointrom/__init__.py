"""jointrom from Python: reduced-order transient dynamics of jointed sheet structures with
contact and friction, over the same Rust library as the ``jointrom`` command line.

    import jointrom as jr
    model = jr.load("friction_bar")            # built-in name, case file, NASTRAN deck, matrix map
    rom = model.reduce(tolerance=1e-2)         # or basis="tvd", g=14
    run = rom.transient(end_time=0.2)          # numpy curves, stats, error estimate
    ref = model.transient(end_time=0.2)        # the full FE run

Units are mm, N, t, s throughout. Long work releases the GIL; Ctrl-C raises KeyboardInterrupt.
Errors are ``jointrom.Error`` subclasses carrying the command line's messages.
"""

from ._native import (
    Error,
    InputError,
    IoError,
    Model,
    Rom,
    RunResult,
    SolverError,
    __version__,
    load,
    load_rom,
)

__all__ = [
    "Error",
    "InputError",
    "IoError",
    "Model",
    "Rom",
    "RunResult",
    "SolverError",
    "__version__",
    "load",
    "load_rom",
]
