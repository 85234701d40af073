"""Bad input raises Python exceptions with the CLI's messages, never crashes the interpreter."""

import json
import shutil

import numpy as np
import pytest

import jointrom as jr


def cli_error(cli, *args):
    p = cli(*args, check=False)
    assert p.returncode != 0
    return p.stderr.strip().removeprefix("jointrom: error: ")


def test_wrong_types(bar):
    with pytest.raises(TypeError):
        jr.load(["friction_bar"])
    with pytest.raises(TypeError):
        jr.load_rom(["rom.json"])
    with pytest.raises(TypeError):
        bar.modes("ten")
    with pytest.raises(TypeError):
        bar.static(load="up")
    with pytest.raises(TypeError):
        bar.reduce(tolerance="tight")


def test_unknown_case_has_the_cli_message(cli):
    with pytest.raises(jr.Error) as e:
        jr.load("no_such_case")
    assert str(e.value) == cli_error(cli, "info", "no_such_case")
    assert isinstance(e.value, jr.IoError)


def test_negative_tolerance(cli, bar):
    with pytest.raises(jr.InputError) as e:
        bar.reduce(tolerance=-0.1)
    assert str(e.value) == cli_error(cli, "transient", "friction_bar", "--tolerance", "-0.1")


def test_bad_options_name_the_flag(cli, bar_tvd):
    with pytest.raises(jr.InputError) as e:
        bar_tvd.transient(end_time=-1.0)
    assert str(e.value) == cli_error(cli, "transient", "friction_bar", "--end-time=-1")
    with pytest.raises(jr.InputError, match="--rtol must be finite and positive"):
        bar_tvd.transient(rtol=float("nan"))
    with pytest.raises(jr.InputError, match="--max-order must be 1..=5"):
        bar_tvd.transient(max_order=9)
    with pytest.raises(jr.InputError, match="functional"):
        bar_tvd.transient(iteration="picard")
    with pytest.raises(jr.InputError, match="output points"):
        bar_tvd.transient(end_time=1.0, output_step=1e-12)
    with pytest.raises(jr.InputError, match="--interface"):
        jr.load("friction_bar").modes(3, interface="sideways")
    with pytest.raises(jr.InputError, match="--g"):
        jr.load("friction_bar").reduce(tolerance=1e-2, g=3)
    with pytest.raises(jr.InputError):
        jr.load("friction_bar").reduce(basis="nonsense")


def test_vector_shapes(bar):
    with pytest.raises(jr.InputError, match=r"shape \(2, 3\)"):
        bar.static(load=np.zeros((2, 3)))
    with pytest.raises(jr.InputError, match="6 components"):
        bar.static(load=[1.0, 2.0])
    up = bar.static(load=[0, 1, 0, 0, 0, 0], linear=True)
    assert up["master_displacement"][1] > 0


def test_rom_of_another_model(cli, bar_tvd, tmp_path):
    path = tmp_path / "rom.json"
    bar_tvd.save(path)
    other = jr.load("multilayer_sheet")
    with pytest.raises(jr.InputError) as e:
        jr.load_rom(path, model=other)
    assert str(e.value) == cli_error(
        cli, "transient", "multilayer_sheet", "--model", f"file:{path}", "--end-time", "0.01"
    )


def test_malformed_rom_file(cli, bar_tvd, tmp_path):
    path = tmp_path / "rom.json"
    bar_tvd.save(path)
    doc = json.loads(path.read_text())
    doc["dimension"] = "thirty"
    path.write_text(json.dumps(doc))
    with pytest.raises(jr.InputError) as e:
        jr.load_rom(path)
    assert str(e.value) == cli_error(
        cli, "transient", "friction_bar", "--model", f"file:{path}", "--end-time", "0.01"
    )
    assert "dimension" in str(e.value)


def test_model_used_after_its_file_changed(tmp_path):
    from conftest import REPO

    case = tmp_path / "bar.json"
    shutil.copy(REPO / "cases" / "friction_bar.json", case)
    model = jr.load(case)
    assert model.modes(2).shape == (2,)
    case.write_text(case.read_text() + "\n")
    with pytest.raises(jr.InputError, match="changed since the model was loaded"):
        model.modes(2)
    with pytest.raises(jr.InputError, match="changed since the model was loaded"):
        model.reduce(basis="tvd", g=4)


def test_fmu_without_binary(bar_tvd, tmp_path, monkeypatch):
    monkeypatch.delenv("JOINTROM_FMU_BINARY", raising=False)
    with pytest.raises(jr.InputError, match="JOINTROM_FMU_BINARY"):
        bar_tvd.export_fmu(tmp_path / "m.fmu")
    assert not (tmp_path / "m.fmu").exists()


def test_fmu_export(bar_tvd, tmp_path):
    from conftest import REPO
    import zipfile

    binary = REPO / "target" / "release" / "libjointrom_fmu.so"
    if not binary.is_file():
        pytest.fail(f"{binary} is missing: `cargo build --release`")
    out = tmp_path / "bar.fmu"
    bar_tvd.export_fmu(out, binary=binary)
    names = zipfile.ZipFile(out).namelist()
    assert "modelDescription.xml" in names and "resources/rom.json" in names
