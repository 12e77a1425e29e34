"""Numbers typed by a user are decimals: Python-only spellings such as ``0.6_9`` (read as
0.69 by ``float``) are refused by ``plan`` and ``schedule``, on the command line and in CSV."""

import math

import pytest
from hypothesis import given, strategies as st

from flipkit.cli import main
from flipkit.decimal_text import decimal


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_every_float_spelled_by_python_reads_back(x):
    assert decimal(repr(x)) == x and decimal(f"{x:e}") == float(f"{x:e}")


@pytest.mark.parametrize("word", ["0.6_9", "1_000", "٠.٦٩", "0x10", "", "1e", ".", "1.2.3",
                                  "--1", "1e5_0"])
def test_python_only_spellings_are_refused(word):
    with pytest.raises(ValueError, match="not a decimal number"):
        decimal(word)


def test_the_words_for_non_finite_numbers_are_left_to_the_callers():
    assert math.isnan(decimal("nan")) and decimal("-inf") == -math.inf
    assert decimal(" 0.69 ") == 0.69 and decimal("+.5e-1") == 0.05


def _refused(capsys, argv, words):
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert all(w in err for w in words), err


def test_a_typo_in_burger_is_refused(tmp_path, capsys):
    out = tmp_path / "p.json"
    _refused(capsys, ["plan", "flip", "--burger", "0.6_9", "-0.16", "0.072", "--json", out],
             ["--burger", "not a decimal number", "0.6_9"])
    assert not out.exists()


def test_a_typo_in_a_csv_is_refused(tmp_path, capsys):
    burgers = tmp_path / "b.csv"
    burgers.write_text("x,y,z\n0.6_9,-0.16,0.072\n")
    _refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", tmp_path / "o"],
             ["line 2", "not a decimal number"])
    cook = tmp_path / "c.csv"
    cook.write_text("burger,t_drop,x,y\nb1,0,0.6_9,-0.16\n")
    _refused(capsys, ["schedule", cook, "--json", tmp_path / "t.json"],
             ["line 2", "decimal numbers", "0.6_9"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.csv", "c.csv"]
