"""Files as Windows users produce them: CRLF, byte-order marks, UTF-16, Windows-1252 (the
rules: docs/install.md, "Files from Windows"; paths in settings: test_windows_paths.py)."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from nmsm.cli import main
from nmsm.errors import BridgeError, InputError, ModelError
from nmsm.io.settings.document import parse_settings_xml
from nmsm.io.osimx import parse_osimx, read_osimx
from nmsm.io.storage import read_storage
from nmsm.io.trc import read_trc
from nmsm.model.osim import load_model
from nmsm.model.osim_writer import OsimWriter

BOM = b"\xef\xbb\xbf"


def _crlf(data: bytes) -> bytes:
    return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")


def _variants(data: bytes) -> dict[str, bytes]:
    return {
        "crlf": _crlf(data),
        "bom": BOM + data,
        "crlf+bom": BOM + _crlf(data),
        "utf-16": data.decode("utf-8").encode("utf-16"),  # Excel's "Unicode Text": UTF-16 LE with its mark
        "no final newline": data.rstrip(b"\n"),
        "trailing tabs": b"\n".join(line + b" \t" if line.strip() else line for line in data.split(b"\n")),
    }


@pytest.mark.parametrize("variant", list(_variants(b"")))
def test_marker_file_variants_read_as_the_original(arm: Path, variant: str) -> None:
    original = read_trc(arm / "simple_arm.trc")
    changed = arm / "changed.trc"
    changed.write_bytes(_variants((arm / "simple_arm.trc").read_bytes())[variant])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = read_trc(changed)
    assert table == original and table.units == original.units and table.data_rate == original.data_rate


@pytest.mark.parametrize("variant", list(_variants(b"")))
def test_storage_variants_read_as_the_original(arm: Path, variant: str) -> None:
    # a header whose first line is a key: a byte-order mark must not hide 'version'
    text = (arm / "arm1.sto").read_bytes()
    keyed = b"version=1\n" + text.split(b"\n", 1)[1]
    (arm / "keyed.sto").write_bytes(keyed)
    original = read_storage(arm / "keyed.sto")
    (arm / "changed.sto").write_bytes(_variants(keyed)[variant])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = read_storage(arm / "changed.sto")
    assert table == original and dict(table.metadata) == dict(original.metadata)
    assert not table.name.startswith("\ufeff")


def test_windows_1252_marker_file_is_read_with_a_warning(arm: Path) -> None:
    text = (arm / "simple_arm.trc").read_text(encoding="utf-8")
    text = text.replace("(X/Y/Z)\tsimple_arm.trc", "(X/Y/Z)\tsimple_arm 20°C.trc").replace("r_radius3", "r_Müller3")
    (arm / "ansi.trc").write_bytes(text.encode("cp1252"))
    with pytest.warns(UserWarning, match=r"ansi\.trc:1: not UTF-8 text .*read as Windows-1252"):
        table = read_trc(arm / "ansi.trc")
    assert "r_Müller3" in table.names and table.file_label == "simple_arm 20°C.trc"


def test_windows_1252_table_header_is_read_with_a_warning(tmp_path: Path) -> None:
    (tmp_path / "t.sto").write_bytes("emg\nversion=1\nrecorded at 20°C\nendheader\ntime\tm\n0\t1\n1\t2\n".encode("cp1252"))
    with pytest.warns(UserWarning, match=r"t\.sto:3: not UTF-8"):
        table = read_storage(tmp_path / "t.sto")
    assert table.comments == ("recorded at 20°C",) and np.array_equal(table.column("m"), [1, 2])


def test_whole_jmp_run_with_every_input_crlf_and_bom(arm: Path, tmp_path: Path) -> None:
    """``nmsm run`` on the toy arm: settings, models and markers from Windows give the same model."""
    windows = tmp_path / "windows"
    shutil.copytree(arm, windows)
    for path in windows.iterdir():
        if path.suffix in (".xml", ".osim", ".trc", ".sto", ".mot"):
            path.write_bytes(BOM + _crlf(path.read_bytes()))
    assert main(["run", str(arm / "ToySettingsFile.xml"), "-o", str(tmp_path / "plain")]) == 0
    assert main(["run", str(windows / "ToySettingsFile.xml"), "-o", str(tmp_path / "win")]) == 0
    plain, changed = (etree.tostring(etree.parse(str(tmp_path / folder / "translation_result_from_xml.osim")),
                                     method="c14n") for folder in ("plain", "win"))
    assert changed == plain  # the same model, every number
    assert b"0.0061" in plain  # the solved elbow translation


# ----- XML encodings ------------------------------------------------------------------------
def test_utf16_settings_file_with_its_declaration_is_read(arm: Path) -> None:
    text = (arm / "ToySettingsFile.xml").read_text(encoding="utf-8").replace('encoding="UTF-8"', 'encoding="UTF-16"')
    (arm / "utf16.xml").write_bytes(text.encode("utf-16"))
    assert parse_settings_xml(arm / "utf16.xml").find(".//input_model_file").text == "simple_arm_translated_away.osim"


def test_ansi_settings_file_names_the_line_and_the_encoding(arm: Path) -> None:
    text = (arm / "ToySettingsFile.xml").read_text(encoding="utf-8")
    text = text.replace("<input_model_file>simple_arm", "<input_model_file>Müller\\simple_arm")
    (arm / "ansi.xml").write_bytes(text.encode("cp1252"))  # Notepad's "ANSI", declared UTF-8
    with pytest.raises(InputError) as info:
        parse_settings_xml(arm / "ansi.xml")
    line = 1 + text[: text.index("Müller")].count("\n")
    assert info.value.line == line and "not in the file's encoding" in str(info.value)
    assert "save the file as UTF-8" in info.value.expected and 'encoding="windows-1252"' in info.value.expected


_OSIMX = "gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPResultsV1/bodyModel_gcp.osimx"


def test_ansi_osimx_file_names_the_line_and_the_encoding(shared_data: Path, tmp_path: Path) -> None:
    text = (shared_data / _OSIMX).read_text(encoding="utf-8")
    text = text.replace("<!--File name of associated .osim file-->", "<!--Modell von Müller, 20°C-->", 1)
    (tmp_path / "ansi.osimx").write_bytes(text.encode("cp1252"))  # Notepad's "ANSI", declared UTF-8
    with pytest.raises(InputError) as info:
        read_osimx(tmp_path / "ansi.osimx")
    line = 1 + text[: text.index("Müller")].count("\n")
    assert info.value.file == str(tmp_path / "ansi.osimx") and info.value.line == line
    assert "not in the file's encoding" in info.value.detail
    assert "save the file as UTF-8" in info.value.expected and 'encoding="windows-1252"' in info.value.expected
    with pytest.raises(InputError, match="not in the file's encoding"):
        parse_osimx(text.encode("cp1252"), source=tmp_path / "ansi.osimx")
    declared = text.replace('encoding="utf-8"', 'encoding="windows-1252"', 1)
    (tmp_path / "declared.osimx").write_bytes(declared.encode("cp1252"))  # the fix the message names
    assert read_osimx(tmp_path / "declared.osimx").contact_surfaces
    with pytest.raises(InputError, match="cannot read .osimx file") as info:
        read_osimx(tmp_path / "missing.osimx")
    assert info.value.expected == "a readable .osimx file"


@pytest.mark.parametrize("encoding", ["UTF-16", "UTF-16LE"])
def test_utf16_model_is_refused_before_anything_runs(arm: Path, encoding: str) -> None:
    text = (arm / "simple_arm.osim").read_text(encoding="utf-8")
    assert 'encoding="UTF-8"' in text
    (arm / "wide.osim").write_bytes(text.replace('encoding="UTF-8"', f'encoding="{encoding}"').encode(encoding))
    with pytest.raises(ModelError) as info:
        load_model(arm / "wide.osim")
    assert encoding in info.value.detail and "OpenSim reads only model files in an ASCII-compatible" in info.value.detail
    assert info.value.file == str(arm / "wide.osim") and info.value.line == 1
    assert "save it again as UTF-8" in info.value.expected


def _latin1_model(arm: Path) -> Path:
    """simple_arm.osim declared and saved as ISO-8859-1, with a non-ASCII comment and model name."""
    text = (arm / "simple_arm.osim").read_text(encoding="utf-8")
    text = text.replace('encoding="UTF-8"', 'encoding="ISO-8859-1"').replace('<Model name="arm26">',
                                                                            '<Model name="arm26">\n<!-- Müller, 20°C -->', 1)
    (arm / "latin1.osim").write_bytes(text.encode("latin-1", errors="xmlcharrefreplace"))
    return arm / "latin1.osim"


def test_latin1_model_loads_as_opensim_loads_it(arm: Path, bridge) -> None:
    path = _latin1_model(arm)
    assert bridge.call("model_info", path=str(path))["coordinates"] == ["r_elbow_flex"]  # OpenSim 4.6 reads it
    assert [c.name for c in load_model(path).coordinates] == ["r_elbow_flex"]
    wide = arm / "utf16.osim"  # and the reason for the rule: OpenSim cannot read UTF-16
    wide.write_bytes((arm / "simple_arm.osim").read_text(encoding="utf-8")
                     .replace('encoding="UTF-8"', 'encoding="UTF-16"').encode("utf-16"))
    with pytest.raises(BridgeError):
        bridge.call("model_info", path=str(wide))


def test_latin1_model_is_written_back_in_its_own_encoding(arm: Path) -> None:
    path = _latin1_model(arm)
    writer = OsimWriter(path)
    writer.set_marker_location("r_humerus1", [0.1, 0.2, 0.3])
    writer.write(arm / "out.osim")
    data = (arm / "out.osim").read_bytes()
    assert "<!-- Müller, 20°C -->".encode("latin-1") in data  # still ISO-8859-1, as declared
    assert b"0.1 0.2 0.3" in data and load_model(arm / "out.osim").coordinates[0].name == "r_elbow_flex"


def test_model_with_bom_and_crlf_loads(arm: Path) -> None:
    (arm / "win.osim").write_bytes(BOM + _crlf((arm / "simple_arm.osim").read_bytes()))
    names = [c.name for c in load_model(arm / "win.osim").coordinates]
    assert names == [c.name for c in load_model(arm / "simple_arm.osim").coordinates] == ["r_elbow_flex"]
