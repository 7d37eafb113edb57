"""Numbers and global options on the ``nmsm`` command line (nmsm/cli_types.py, nmsm/cli.py):
a value out of range is argparse's usage error (exit 2) naming the option and the accepted
range; ``--progress``/``--traceback`` after the sub-command say where they go."""

from __future__ import annotations

import argparse

import pytest

from nmsm.cli import main
from nmsm.cli_types import fraction, non_negative_float, percent, positive_float, positive_int

SURROGATE = ["surrogate", "--model", "m.osim", "--data-dir", "d", "--coordinates", "q", "-o", "s.json"]
BAD_NUMBERS = {
    "id --lowpass -6": (["id", "m.osim", "q.sto", "-o", "x.sto", "--lowpass", "-6"], "--lowpass", "-6 is out of range",
                        "a finite number > 0"),
    "id --lowpass 0": (["id", "m.osim", "q.sto", "-o", "x.sto", "--lowpass", "0"], "--lowpass", "0 is out of range",
                       "a finite number > 0"),
    "id --lowpass nan": (["id", "m.osim", "q.sto", "-o", "x.sto", "--lowpass", "nan"], "--lowpass",
                         "'nan' is not a finite number", "a finite number > 0"),
    "id --start inf": (["id", "m.osim", "q.sto", "-o", "x.sto", "--start", "inf"], "--start",
                       "'inf' is not a finite number", "a finite number"),
    "muscle-analysis --lowpass -6": (["muscle-analysis", "m.osim", "q.sto", "--lowpass", "-6"], "--lowpass",
                                     "-6 is out of range", "a finite number > 0"),
    "ik --accuracy -1": (["ik", "m.osim", "t.trc", "--accuracy", "-1"], "--accuracy", "-1 is out of range",
                         "a finite number > 0"),
    "surrogate --holdout -0.2": ([*SURROGATE, "--holdout", "-0.2"], "--holdout", "-0.2 is out of range",
                                 "a finite number in [0, 1)"),
    "surrogate --holdout 1": ([*SURROGATE, "--holdout", "1"], "--holdout", "1 is out of range",
                              "a finite number in [0, 1)"),
    "surrogate --holdout 1.5": ([*SURROGATE, "--holdout", "1.5"], "--holdout", "1.5 is out of range",
                                "a finite number in [0, 1)"),
    "surrogate --angular-padding -10": ([*SURROGATE, "--angular-padding", "-10"], "--angular-padding",
                                        "-10 is out of range", "a finite number >= 0"),
    "surrogate --epsilon -1": ([*SURROGATE, "--epsilon", "-1"], "--epsilon", "-1 is out of range",
                               "a finite number >= 0"),
    "surrogate --samples-per-frame 0": ([*SURROGATE, "--samples-per-frame", "0"], "--samples-per-frame",
                                        "0 is out of range", "a whole number >= 1"),
    "vaf --threshold 150": (["vaf", "a.sto", "--threshold", "150"], "--threshold", "150 is out of range",
                            "a finite number in (0, 100]"),
    "vaf --threshold -5": (["vaf", "a.sto", "--threshold", "90", "-5"], "--threshold", "-5 is out of range",
                           "a finite number in (0, 100]"),
    "vaf --max-synergies 0": (["vaf", "a.sto", "--max-synergies", "0"], "--max-synergies", "0 is out of range",
                              "a whole number >= 1"),
    "vaf --max-synergies -2": (["vaf", "a.sto", "--max-synergies", "-2"], "--max-synergies", "-2 is out of range",
                               "a whole number >= 1"),
    "vaf --max-synergies 2.5": (["vaf", "a.sto", "--max-synergies", "2.5"], "--max-synergies",
                                "'2.5' is not a whole number", "a whole number >= 1"),
    "--progress -1": (["--progress", "-1", "plugins"], "--progress", "-1 is out of range", "a finite number >= 0"),
    "--progress nan": (["--progress", "nan", "plugins"], "--progress", "'nan' is not a finite number",
                       "a finite number >= 0"),
}


@pytest.mark.parametrize("case", list(BAD_NUMBERS))
def test_a_number_out_of_range_is_a_usage_error(case: str, capsys) -> None:
    argv, option, problem, expected = BAD_NUMBERS[case]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert f"error: argument {option}: {problem} (expected {expected})" in err, err
    assert err.startswith("usage: nmsm")


def test_the_converters_accept_their_range() -> None:
    assert positive_float("1e-5") == 1e-5 and non_negative_float("0") == 0.0
    assert fraction("0") == 0.0 and fraction("0.99") == 0.99
    assert percent("100") == 100.0 and positive_int("3") == 3
    for convert, text in ((positive_float, "-inf"), (fraction, "1"), (percent, "0"), (positive_int, "0")):
        with pytest.raises(argparse.ArgumentTypeError):
            convert(text)


@pytest.mark.parametrize(("argv", "message"), [
    (["id", "--progress", "5", "m.osim", "q.sto", "-o", "x.sto"],
     "--progress goes before the sub-command: nmsm --progress 5 id ... "
     "(--progress and --traceback are options of nmsm itself)"),
    (["vaf", "a.sto", "--progress=0"], "--progress goes before the sub-command: nmsm --progress 0 vaf ..."),
    (["ik", "m.osim", "--traceback"], "--traceback goes before the sub-command: nmsm --traceback ik ..."),
    (["--progress", "2", "markers", "m.osim", "q.sto", "--progress", "5", "-o", "x.trc"],
     "--progress goes before the sub-command: nmsm --progress 5 markers ..."),
])
def test_a_global_option_after_the_sub_command_says_where_it_goes(argv: list[str], message: str, capsys) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert f"nmsm: error: {message}" in err and "unrecognized arguments" not in err, err


def test_global_options_before_the_sub_command_still_work(tmp_path, capsys) -> None:
    assert main(["--progress", "0", "--traceback", "plugins"]) == 0
    assert main(["--progress", "5", "id", str(tmp_path / "none.osim"), str(tmp_path / "none.sto"),
                 "-o", str(tmp_path / "x.sto")]) == 1
    assert "model file not found" in capsys.readouterr().err
