"""A transient through Python equals `jointrom transient ... --json` bit for bit."""

import numpy as np

import jointrom as jr

CURVES = [
    "t",
    "contact_force_norm",
    "friction_force_norm",
    "master_uy",
    "kinetic",
    "strain",
    "pair",
    "external_work",
    "dissipated",
]


def assert_same_run(run, doc):
    for name in CURVES:
        got = getattr(run, name)
        want = np.array(doc["curves"][name], dtype=float)
        assert got.dtype == np.float64 and got.ndim == 1
        assert got.shape == want.shape, name
        # Bit for bit: the JSON's numbers round-trip exactly.
        assert np.array_equal(got.view(np.uint64), want.view(np.uint64)), name
    assert run.stats == doc["stats"]
    assert run.error_estimate == doc["error_estimate"]
    assert run.options == doc["options"]
    assert run.basis_size == doc["basis_size"]
    assert run.g == doc["g"]


def test_reduced_run_equals_cli(cli, bar_tvd):
    doc = cli.json("transient", "friction_bar", "--model", "tvd", "--g", "14", "--end-time", "0.03")
    run = bar_tvd.transient(end_time=0.03)
    assert run.model == "tvd" and run.case == "friction_bar"
    assert_same_run(run, doc)


def test_reduced_run_without_friction_equals_cli(cli, bar):
    doc = cli.json(
        "transient", "friction_bar", "--model", "jim", "--g", "6", "--end-time", "0.02",
        "--friction", "off", "--rtol", "1e-7",
    )
    run = bar.reduce(basis="jim", g=6).transient(end_time=0.02, friction=False, rtol=1e-7)
    assert_same_run(run, doc)


def test_full_run_equals_cli(cli, bar):
    doc = cli.json("transient", "friction_bar", "--model", "full", "--end-time", "0.01")
    run = bar.transient(end_time=0.01)
    assert run.error_estimate is None
    assert_same_run(run, doc)


def test_saved_rom_runs_as_the_cli_runs_its_file(cli, bar, bar_tvd, tmp_path):
    path = tmp_path / "rom.json"
    bar_tvd.save(path)
    rom = jr.load_rom(path, model=bar)
    assert np.array_equal(rom.k, bar_tvd.k) and np.array_equal(rom.m, bar_tvd.m)
    assert rom.phi is None
    doc = cli.json("transient", "friction_bar", "--model", f"file:{path}", "--end-time", "0.02")
    run = rom.transient(end_time=0.02)
    assert run.model == f"file:{path}"
    assert_same_run(run, doc)
    # Without the model, the file alone runs the same.
    assert_same_run(jr.load_rom(str(path)).transient(end_time=0.02), doc)


def test_info_modes_static_equal_cli(cli, bar):
    assert bar.info == cli.json("info", "friction_bar")
    modes = cli.json("modes", "friction_bar", "--count", "6", "--interface", "free")
    assert np.array_equal(bar.modes(6, interface="free"), modes["frequencies_hz"])
    st = cli.json("static", "friction_bar", "--scale", "-1")
    mine = bar.static(scale=-1.0)
    assert mine["contact_force_norm"] == st["contact_force_norm"]
    assert mine["pairs_in_contact"] == st["pairs_in_contact"]
    assert np.array_equal(mine["pair_forces"], np.array(st["pair_forces"]))
    assert np.array_equal(mine["master_displacement"], st["master_displacement"])
    lin = cli.json("static", "friction_bar", "--linear")
    assert np.array_equal(bar.static(linear=True)["master_displacement"], lin["master_displacement"])


def dense(a, n):
    """A scipy.sparse matrix, or the (data, indices, indptr, shape) tuple without scipy."""
    if isinstance(a, tuple):
        data, indices, indptr, shape = a
        assert shape == (n, n)
        out = np.zeros(shape)
        for j in range(n):
            out[indices[indptr[j] : indptr[j + 1]], j] = data[indptr[j] : indptr[j + 1]]
        return out
    return a.toarray()


def test_matrices(bar, bar_tvd):
    n = bar.dofs
    k = dense(bar.stiffness(), n)
    m = dense(bar.mass(), n)
    assert np.array_equal(k, k.T) and np.array_equal(m, m.T)
    assert k.shape == (n, n) and m.shape == (n, n)
    phi = bar_tvd.phi
    # The reduced matrices are the projections Φᵀ K Φ, Φᵀ M Φ.
    kr = phi.T @ (k @ phi)
    mr = phi.T @ (m @ phi)
    assert np.allclose(kr, bar_tvd.k, rtol=1e-9, atol=1e-9 * np.abs(bar_tvd.k).max())
    assert np.allclose(mr, bar_tvd.m, rtol=1e-9, atol=1e-9 * np.abs(bar_tvd.m).max())
    assert bar_tvd.b_phi.shape == (3 * bar.pairs, bar_tvd.dimension)
