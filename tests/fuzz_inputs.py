"""Seeded mutators of real input files and command lines, and the judge of one outcome.

A mutated file is written into a folder that mirrors its original's folder and the folder
above it with symbolic links (so the paths it names resolve as the original's do; nothing
is ever written into the shared data), read by its reader, and judged:

``clean``     an :class:`~nmsm.errors.NmsmError` whose message names the mutated file
``accepted``  the reader returned
``crash``     anything else (another exception, or a project error not naming the file)

Command lines: each token of a valid command line is mutated, and ``nmsm``'s parser must
either accept the result or end with argparse's usage error (exit status 2).
"""

from __future__ import annotations

import random
import re
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import attrs

#: values put in place of a number or a word of an input file
ODD_VALUES = ("nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-320", "2147483648", "", " ", "abc", "1,5",
              "0x10", "true", "yes", "\u22121", "\u00e9", "a" * 300, "a" * 300 + ".osim", "x/" + "b" * 256 + "/y.sto",
              "../" * 20 + "x", "/", "&amp;", "<!-- c -->")
_TEXT = re.compile(rb">\s*([^<>\s][^<>]*?)\s*<")
#: bytes put into a file
ODD_BYTES = (b"\x00", b"\xff\xfe", b"\xe9", b"<", b">", b"&", b"]]>", b"\r", b"\t", b"\n\n", b"<!DOCTYPE r>", b"=")
_TOKEN = re.compile(rb"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|[A-Za-z_][\w.]*")


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One to three random edits of ``data``: a token or an element's text replaced by an
    odd value, a path given an overlong or odd name, bytes inserted, deleted, duplicated or
    truncated, two lines swapped."""
    for _ in range(rng.randint(1, 3)):
        data = rng.choice(_MUTATORS)(data, rng)
    return data


def _replace_token(data: bytes, rng: random.Random) -> bytes:
    tokens = list(_TOKEN.finditer(data))
    if not tokens:
        return data
    match = rng.choice(tokens)
    return data[:match.start()] + rng.choice(ODD_VALUES).encode() + data[match.end():]


def _replace_text(data: bytes, rng: random.Random) -> bytes:
    """The text of a random XML element (or a random line of a table) replaced by an odd value."""
    texts = list(_TEXT.finditer(data))
    if not texts:
        lines = data.split(b"\n")
        lines[rng.randrange(len(lines))] = rng.choice(ODD_VALUES).encode()
        return b"\n".join(lines)
    match = rng.choice(texts)
    return data[:match.start(1)] + rng.choice(ODD_VALUES).encode() + data[match.end(1):]


_PATH_TEXT = re.compile(rb">\s*([^<>\s]*(?:/|\\|\.(?:osimx?|xml|trc|mot|sto))[^<>\s]*)\s*<")


def _long_path(data: bytes, rng: random.Random) -> bytes:
    """A path written in the file (an element's text with a folder separator or a data file's
    extension) with one name made longer than file systems allow, or replaced by odd text."""
    paths = list(_PATH_TEXT.finditer(data))
    if not paths:
        return _replace_text(data, rng)
    match = rng.choice(paths)
    text = match.group(1)
    parts = re.split(rb"([/\\])", text)
    names = [k for k in range(0, len(parts), 2)]
    k = rng.choice(names)
    parts[k] = rng.choice((b"n" * 256, b"n" * 300 + parts[k], parts[k] + b"\x00", b"", b"..", b"~"))
    return data[:match.start(1)] + b"".join(parts) + data[match.end(1):]


def _insert(data: bytes, rng: random.Random) -> bytes:
    at = rng.randint(0, len(data))
    return data[:at] + rng.choice(ODD_BYTES) + data[at:]


def _delete(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    at = rng.randrange(len(data))
    return data[:at] + data[at + rng.randint(1, 64):]


def _duplicate(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    at = rng.randrange(len(data))
    piece = data[at:at + rng.randint(1, 200)]
    return data[:at] + piece + data[at:]


def _truncate(data: bytes, rng: random.Random) -> bytes:
    return data[:rng.randint(0, len(data))]


def _swap_lines(data: bytes, rng: random.Random) -> bytes:
    lines = data.split(b"\n")
    if len(lines) < 2:
        return data
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return b"\n".join(lines)


_MUTATORS: tuple[Callable[[bytes, random.Random], bytes], ...] = (
    _replace_token, _replace_token, _replace_text, _replace_text, _long_path, _insert, _delete, _duplicate,
    _truncate, _swap_lines)


@attrs.define
class Tally:
    """Outcomes of a fuzz run; ``crashes``: (description, exception text) of each crash."""

    inputs: int = 0
    clean: int = 0
    accepted: int = 0
    crashes: list[tuple[str, str]] = attrs.field(factory=list)

    def text(self) -> str:
        return (f"{self.inputs} inputs: {self.clean} clean errors, {self.accepted} accepted, "
                f"{len(self.crashes)} crashes")


def mirror(source: Path, root: Path) -> Path:
    """A folder under ``root`` standing for ``source``'s folder: the entries of that folder
    and of the folder above it are symbolic links to the originals. Returns the stand-in of
    ``source``'s folder (where the mutated file goes)."""
    parent, folder = source.parent.parent, source.parent
    top = root / "up"
    here = top / folder.name
    if here.exists():
        return here
    here.mkdir(parents=True)
    for entry in parent.iterdir():
        if entry.name != folder.name:
            (top / entry.name).symlink_to(entry)
    for entry in folder.iterdir():
        (here / entry.name).symlink_to(entry)
    return here


def judge(read: Callable[[Path], Any], path: Path, tally: Tally, label: str) -> None:
    """Read ``path`` and count the outcome (module docstring)."""
    from nmsm.errors import NmsmError

    tally.inputs += 1
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            read(path)
    except NmsmError as exc:
        if path.name in str(exc):
            tally.clean += 1
        else:
            tally.crashes.append((label, f"{type(exc).__name__} not naming {path.name}: {exc}"[:400]))
    except RecursionError as exc:
        tally.crashes.append((label, f"RecursionError: {exc}"[:400]))
    except Exception as exc:  # noqa: BLE001 - every other exception is a crash to report
        tally.crashes.append((label, f"{type(exc).__name__}: {exc}"[:400]))
    else:
        tally.accepted += 1


def fuzz_file(source: Path, read: Callable[[Path], Any], root: Path, count: int, seed: int, tally: Tally) -> None:
    """``count`` mutations of ``source`` (seeded), each judged (:func:`judge`)."""
    rng = random.Random(f"{seed}:{source.name}")
    original = source.read_bytes()
    folder = mirror(source, root)
    target = folder / source.name
    for k in range(count):
        if target.is_symlink() or target.exists():
            target.unlink()
        target.write_bytes(mutate(original, rng))
        judge(read, target, tally, f"{source.name} #{k} (seed {seed})")


def mutate_argv(argv: Sequence[str], rng: random.Random) -> list[str]:
    """``argv`` with one or two tokens replaced, removed or repeated, or an odd token added."""
    out = list(argv)
    for _ in range(rng.randint(1, 2)):
        choice = rng.randrange(4)
        if choice == 0 and out:
            out[rng.randrange(len(out))] = rng.choice(ODD_VALUES)
        elif choice == 1 and out:
            del out[rng.randrange(len(out))]
        elif choice == 2 and out:
            at = rng.randrange(len(out))
            out.insert(at, out[at])
        else:
            out.insert(rng.randint(0, len(out)), rng.choice(("--progress", "--traceback", "-o", "--", "-h",
                                                             "--lowpass", "--start", "--end", "nan", "-1")))
    return out


def judge_argv(argv: list[str], tally: Tally) -> None:
    """Parse ``argv`` with ``nmsm``'s parser: accepted, or argparse's usage error (exit 2;
    ``-h`` exits 0)."""
    import contextlib
    import io

    from nmsm.cli import _misplaced_global_option, build_parser

    tally.inputs += 1
    parser = build_parser()
    try:
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            message = _misplaced_global_option(parser, argv)
            if message:
                parser.error(message)
            parser.parse_args(argv)
    except SystemExit as exc:
        if exc.code in (0, 2):
            tally.clean += 1
        else:
            tally.crashes.append((" ".join(argv), f"exit status {exc.code}"))
    except Exception as exc:  # noqa: BLE001 - every other exception is a crash to report
        tally.crashes.append((" ".join(argv)[:200], f"{type(exc).__name__}: {exc}"[:400]))
    else:
        tally.accepted += 1
