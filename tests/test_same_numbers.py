"""The comparison of committed outputs as numbers (``tests/same_numbers.py``): what passes as the same result
printed on another CPU, and what is still caught."""
from __future__ import annotations

from same_numbers import csv_differences, differences, numbers_agree
from doc_blocks import listing_missing


def test_a_decimal_may_print_one_unit_away_in_its_last_digit_and_no_more():
    assert numbers_agree("1.307", "1.308") and numbers_agree("4.4e-06", "4.5e-06") and numbers_agree("−0.3921", "-0.3922")
    assert not numbers_agree("1.307", "1.309") and not numbers_agree("4.4e-06", "4.6e-06")
    assert numbers_agree("0.3696", "0.37")  # printed shorter: the less precise one's digit counts


def test_integers_and_words_must_be_the_same():
    assert not numbers_agree("16", "17") and numbers_agree("16", "16")
    assert differences("16 fold, 2 grazing", "17 fold, 2 grazing")
    assert differences("held-out error 0.3696", "training error 0.3696")
    assert differences("a 1.0", "a 1.0 b") and differences("a\nb", "a")
    assert not differences("Held-out error 0.3696 → 0.01053 (35.1× lower)", "Held-out error 0.3697 → 0.01052 (35.2× lower)")
    assert numbers_agree("10.24", "10.3", rel=0.01) and not numbers_agree("10.24", "10.5", rel=0.01)


def test_csv_cells_compare_within_their_tolerance_and_headers_exactly():
    committed = "t,x\n0.0,1.0000000000001\n0.5,-2.5\n"
    assert not csv_differences("t,x\n0.0,1.0\n0.5,-2.5\n", committed, rel=1e-9)
    assert csv_differences("t,x\n0.0,1.001\n0.5,-2.5\n", committed, rel=1e-9)
    assert csv_differences("t,v\n0.0,1.0\n0.5,-2.5\n", committed, rel=1e-9)
    assert csv_differences("t,x\n0.0,1.0\n", committed, rel=1e-9)


def test_a_listing_line_matches_the_output_with_its_numbers_one_unit_away_in_order():
    output = "planetary: 5 modes\n   0.81996  elastic x2  0  0  1  0  -1\n   1.52658  elastic  1  -0.06437\n"
    assert listing_missing("0.81996 elastic x2 0 0 1 0 -1\n1.52659 elastic 1 -0.06438", output) == []
    assert listing_missing("1.52658 elastic 1 -0.06437\n0.81996 elastic x2 0 0 1 0 -1", output) == [
        "0.81996 elastic x2 0 0 1 0 -1"]
    assert listing_missing("0.81996 elastic x2 0 0 0 1 -1", output) == ["0.81996 elastic x2 0 0 0 1 -1"]
