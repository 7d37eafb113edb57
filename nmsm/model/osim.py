"""Loading ``.osim`` files: :func:`load_model` reads a model with lxml, no OpenSim in process.

Old file versions (< 40000: 20303, 30000, with joints inside bodies) are not parsed by
hand: they are upgraded once by OpenSim through the bridge (``resave_model``) into a cache
keyed by the file's content hash, ``$NMSM_CACHE_DIR`` or ``~/.cache/nmsm/models/``, and
the upgraded copy is read. Errors name the file the user gave.
"""

from __future__ import annotations

import codecs
import hashlib
import os
import tempfile
from pathlib import Path

from lxml import etree

from nmsm.errors import InputError, ModelError
from nmsm.io.xml_input import refuse_entities, xml_parser
from nmsm.model.components import Model
from nmsm.model.parse_model import parse_model_document

#: first file version nmsm reads directly (OpenSim 4.0 format)
CURRENT_FORMAT = 40000


def cache_dir() -> Path:
    """Folder of upgraded model copies (``$NMSM_CACHE_DIR/models`` or ``~/.cache/nmsm/models``)."""
    env = os.environ.get("NMSM_CACHE_DIR")
    base = Path(env) if env else Path.home() / ".cache" / "nmsm"
    return base / "models"


def read_xml(path: str | Path) -> etree._ElementTree:
    """The XML tree of ``path`` (comments and layout kept); ModelError if it is not XML."""
    try:
        tree = etree.parse(str(path), xml_parser(huge_tree=True, remove_blank_text=False))
    except OSError as exc:
        raise ModelError(f"cannot read the model file ({exc})", file=path) from None
    except etree.XMLSyntaxError as exc:
        raise ModelError(f"not a valid XML file ({exc})", file=path, expected="an OpenSim .osim file") from None
    try:
        refuse_entities(tree, path, "model file")
    except InputError as exc:
        raise ModelError(exc.detail, file=path, line=1, element="<!DOCTYPE>", expected=exc.expected) from None
    declared = tree.docinfo.encoding or "UTF-8"
    if not ascii_compatible(declared):
        raise ModelError(
            f"the model file is {declared}-encoded; OpenSim reads only model files in an ASCII-compatible "
            "encoding (UTF-8, or a one-byte encoding such as ISO-8859-1 or windows-1252), not "
            f"{declared}",
            file=path, line=1, element="<?xml encoding?>",
            expected='a UTF-8 .osim file: save it again as UTF-8 (e.g. Notepad: "Save as", encoding UTF-8) '
            'with <?xml version="1.0" encoding="UTF-8"?>')
    return tree


#: what ASCII text looks like in an encoding OpenSim can read (its XML parser reads bytes)
_ASCII_PROBE = bytes(range(0x20, 0x7F)) + b"\t\r\n"
#: encodings Python may not know by name that are never ASCII-compatible
_WIDE_NAMES = ("UTF-16", "UTF16", "UTF-32", "UTF32", "UCS-2", "UCS2", "UCS-4", "UCS4", "UNICODE")


def ascii_compatible(encoding: str) -> bool:
    """Whether ``encoding`` writes ASCII characters as the same single bytes (UTF-8, ISO-8859-x,
    windows-125x: OpenSim reads these; UTF-16/32, UCS-2/4 or EBCDIC it cannot)."""
    name = encoding.strip().upper()
    if name.startswith(_WIDE_NAMES):
        return False
    try:
        return _ASCII_PROBE.decode("ascii").encode(codecs.lookup(encoding).name) == _ASCII_PROBE
    except (LookupError, UnicodeError):
        return True  # unknown to Python but read by libxml2: judged by name only


def python_codec(tree: etree._ElementTree) -> str:
    """The Python codec name of a parsed file's declared encoding (UTF-8 if none)."""
    declared = tree.docinfo.encoding or "UTF-8"
    try:
        return codecs.lookup(declared).name
    except LookupError:
        return "utf-8"


def file_version(tree: etree._ElementTree, path: str | Path) -> int:
    root = tree.getroot()
    if root.tag != "OpenSimDocument":
        if root.tag == "Model":
            return 0
        raise ModelError(f"root element is <{root.tag}>", file=path, expected="<OpenSimDocument> holding a <Model>")
    try:
        return int(root.get("Version", "0"))
    except ValueError:
        raise ModelError(f"unreadable Version '{root.get('Version')}'", file=path, element="OpenSimDocument",
                         expected="an integer file version") from None


def upgraded_copy(path: str | Path) -> Path:
    """Path of the OpenSim-upgraded copy of an old ``.osim`` file (made once, cached by hash)."""
    path = Path(path)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:20]
    target = cache_dir() / f"{path.stem}-{digest}.osim"
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    from nmsm.errors import BridgeError
    from nmsm.opensim_bridge import get_bridge, opensim_available

    if not opensim_available():
        raise ModelError(
            "this model file uses an old format; nmsm upgrades such files once with OpenSim, which is not installed",
            file=path, expected="an OpenSim 4 model file, or `pip install opensim` to upgrade it automatically")
    fd, tmp = tempfile.mkstemp(suffix=".osim", dir=target.parent)
    os.close(fd)
    try:
        get_bridge().call("resave_model", path=str(path.resolve()), output=tmp)
        os.replace(tmp, target)
    except BridgeError as exc:
        raise ModelError(f"OpenSim could not upgrade this old-format model: {exc}", file=path) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


def load_model(path: str | Path) -> Model:
    """Read the OpenSim model at ``path`` (any OpenSim 3/4 file version)."""
    path = Path(path)
    if not path.is_file():
        raise ModelError("model file not found", file=path, expected="an existing .osim file")
    tree = read_xml(path)
    version = file_version(tree, path)
    if version and version < CURRENT_FORMAT:
        source = upgraded_copy(path)
        tree = read_xml(source)
        model = parse_model_document(tree.getroot(), f"{path} (upgraded copy {source})", version=version,
                                     source_file=source)
    else:
        model = parse_model_document(tree.getroot(), path, version=version, source_file=path)
    model.file = str(path)
    return model
