"""Every XML reader refuses entity declarations: external entities (a local file, a network
address), parameter entities and nested internal entities ("billion laughs") are neither
resolved nor expanded; the error names the file and never shows what an entity points at."""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from nmsm.errors import InputError

SECRET = "nmsm-entity-secret-7f3a"


def _payloads(secret_file: Path) -> dict[str, tuple[str, str]]:
    """name -> (internal DTD subset, reference placed in the root's text)."""
    laughs = '<!ENTITY l0 "lol">' + "".join(
        f'<!ENTITY l{k} "{"".join(f"&l{k - 1};" for _ in range(10))}">' for k in range(1, 10))
    return {
        "file": (f'<!ENTITY xx SYSTEM "{secret_file.as_uri()}">', "&xx;"),
        "network": ('<!ENTITY xx SYSTEM "http://127.0.0.1:9/nmsm-entity">', "&xx;"),
        "parameter": (f'<!ENTITY % pp SYSTEM "{secret_file.as_uri()}"> %pp;', ""),
        "billion laughs": (laughs, "&l9;"),
    }


def _poison(source: Path, target: Path, subset: str, reference: str) -> Path:
    """``source`` copied to ``target`` with a ``<!DOCTYPE>`` declaring ``subset`` and
    ``reference`` as the root element's first text."""
    text = source.read_text(encoding="utf-8", errors="replace")
    text = re.sub(r"^\s*<\?xml[^>]*\?>\s*", "", text)
    root = re.search(r"<([A-Za-z_][\w.-]*)[^>]*?>", re.sub(r"<!--.*?-->", lambda m: " " * len(m.group()), text,
                                                           flags=re.S))
    assert root is not None
    end = root.end()
    text = text[:end] + reference + text[end:]
    target.write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<!DOCTYPE {root.group(1)} [{subset}]>\n{text}',
                      encoding="utf-8")
    return target


def _readers() -> dict[str, tuple[str, Callable[[Path], object]]]:
    from nmsm.io.osimx import read_osimx
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.model.external_loads import read_external_loads
    from nmsm.model.osim import load_model
    from nmsm.tools.jmp.ik_settings import read_ik_settings
    from nmsm.tools.pipeline.pipeline_file import read_pipeline

    return {
        "settings": ("jmp/uf_subject3_tutorial/CompletedSettingsFiles/JMPSettingsSimultaneous.xml",
                     read_settings_document),
        "osim": ("gcp/patient3_right_foot/footModel_1.osim", load_model),
        "osimx": ("gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPResultsV2/bodyModel_gcp.osimx", read_osimx),
        "external loads": ("preprocessing/uf_subject3_tutorial/PreCompleted/input_data/externalLoads.xml",
                           read_external_loads),
        "IK settings": ("preprocessing/uf_subject3_tutorial/input_data/IKSettings.xml", read_ik_settings),
        "pipeline": ("", read_pipeline),
    }


PIPELINE = """<?xml version="1.0"?>
<NMSMPipelineDocument Version="1.6.0"><PipelineTool><results_directory>out</results_directory>
</PipelineTool></NMSMPipelineDocument>
"""


@pytest.mark.parametrize("payload", ["file", "network", "parameter", "billion laughs"])
@pytest.mark.parametrize("reader", ["settings", "osim", "osimx", "external loads", "IK settings", "pipeline"])
def test_readers_refuse_entity_declarations(shared_data: Path, tmp_path: Path, reader: str, payload: str) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text(SECRET, encoding="utf-8")
    relative, read = _readers()[reader]
    if relative:
        source = shared_data / relative
    else:
        source = tmp_path / "pipeline_source.xml"
        source.write_text(PIPELINE, encoding="utf-8")
    folder = tmp_path / "in"
    folder.mkdir()
    subset, reference = _payloads(secret)[payload]
    poisoned = _poison(source, folder / ("poisoned" + source.suffix), subset, reference)
    with pytest.raises(InputError) as caught:
        read(poisoned)
    message = str(caught.value)
    assert str(poisoned) in message
    assert SECRET not in message
    if payload == "billion laughs":  # libxml2 stops at its amplification limit while reading the declarations
        assert "entit" in message
    else:
        assert "declares XML entities" in message and "<!DOCTYPE>" in message


def test_the_parser_substitutes_no_entity(tmp_path: Path) -> None:
    """The parser itself leaves entity references alone (also where no check follows)."""
    from lxml import etree

    from nmsm.io.xml_input import xml_parser

    secret = tmp_path / "secret.txt"
    secret.write_text(SECRET, encoding="utf-8")
    for subset, reference in _payloads(secret).values():
        data = f'<!DOCTYPE r [{subset}]><r>{reference}</r>'.encode()
        for huge in (False, True):
            try:
                root = etree.fromstring(data, xml_parser(huge_tree=huge))
            except etree.XMLSyntaxError as exc:
                assert "amplification" in str(exc)
                continue
            assert SECRET not in etree.tostring(root, encoding="unicode")
            assert len(etree.tostring(root)) < 100


def test_an_external_dtd_is_not_fetched(shared_data: Path, tmp_path: Path) -> None:
    """A ``<!DOCTYPE ... SYSTEM "file">`` declaring no entity in the file: the DTD is never
    loaded, and the file is refused."""
    from nmsm.io.settings.reader import read_settings_document

    dtd = tmp_path / "x.dtd"
    dtd.write_text(f'<!ENTITY xx "{SECRET}">', encoding="utf-8")
    source = shared_data / "jmp/uf_subject3_tutorial/CompletedSettingsFiles/JMPSettingsSimultaneous.xml"
    settings = tmp_path / "s.xml"
    shutil.copy(source, settings)
    text = re.sub(r"^\s*<\?xml[^>]*\?>\s*", "", settings.read_text(encoding="utf-8"))
    settings.write_text(f'<!DOCTYPE NMSMPipelineDocument SYSTEM "{dtd.as_uri()}">\n'
                        + text.replace("<JointModelPersonalizationTool>", "<JointModelPersonalizationTool>&xx;", 1),
                        encoding="utf-8")
    with pytest.raises(InputError) as caught:
        read_settings_document(settings)
    assert SECRET not in str(caught.value) and str(settings) in str(caught.value)
    assert "external DTD" in str(caught.value)


def test_every_parser_of_nmsm_is_the_safe_one() -> None:
    """No module parses XML with lxml's default parser or builds its own ``XMLParser``
    (nmsm.io.xml_input.xml_parser is the one lxml parser). The standard library's parser
    (the full-body example's builders) is expat, which reads no external entity and stops at
    its amplification limit (checked below)."""
    import nmsm

    root = Path(nmsm.__file__).parent
    offenders = []
    for path in sorted(root.rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            code = line.split("#")[0]
            calls = re.findall(r"etree\.(?:parse|fromstring|XML|iterparse)\((.*)", code)
            if any("xml_parser(" not in call for call in calls) or (
                    "XMLParser(" in code and path.name != "xml_input.py"):
                offenders.append(f"{path.relative_to(root)}:{number}: {line.strip()}")
    assert not offenders, "\n".join(offenders)


def test_the_standard_library_parser_refuses_entities_too(tmp_path: Path) -> None:
    import xml.etree.ElementTree as ET  # noqa: N817 - as the full-body example's builders import it

    secret = tmp_path / "secret.txt"
    secret.write_text(SECRET, encoding="utf-8")
    for name, (subset, reference) in _payloads(secret).items():
        if name == "parameter":
            continue  # expat skips external parameter entities: nothing is read
        with pytest.raises(ET.ParseError):
            ET.fromstring(f"<!DOCTYPE r [{subset}]><r>{reference}</r>")
