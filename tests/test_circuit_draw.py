"""mlc.circuit.draw: labels that would be drawn on one spot are written once."""
from mlc.circuit.draw import MERGE_FRACTION, MERGE_SHOWN, merge_labels


def test_labels_on_one_spot_are_joined_in_order_and_others_kept():
    span = 40.0
    near = 0.5 * MERGE_FRACTION * span
    labels = [(0.0, 38.0, "g1 CNIMPLY"), (near, 38.0, "g2 NIMPLY"), (0.0, 38.0 - near, "g3 AND"),
              (12.0, 0.0, "u1_up")]
    out = merge_labels(labels, span, "\n")
    assert out == [(0.0, 38.0, "g1 CNIMPLY\ng2 NIMPLY\ng3 AND"), (12.0, 0.0, "u1_up")]


def test_labels_just_beyond_the_tolerance_stay_apart_and_repeats_are_written_once():
    span = 10.0
    far = 1.01 * MERGE_FRACTION * span
    assert len(merge_labels([(0.0, 0.0, "a"), (far, 0.0, "b")], span)) == 2
    assert merge_labels([(1.0, 2.0, "y"), (1.0, 2.0, "y"), (1.0, 2.0, "b")], span) == [(1.0, 2.0, "y, b")]


def test_a_crowded_spot_names_a_few_and_counts_the_rest():
    labels = [(0.0, 0.0, f"g{k}") for k in range(MERGE_SHOWN + 3)]
    (x, y, text), = merge_labels(labels, 10.0, "\n")
    lines = text.split("\n")
    assert len(lines) == MERGE_SHOWN and lines[:-1] == [f"g{k}" for k in range(MERGE_SHOWN - 1)]
    assert lines[-1] == "+4 more"
    assert merge_labels(labels[:MERGE_SHOWN], 10.0, "\n")[0][2].split("\n") == [f"g{k}" for k in range(MERGE_SHOWN)]
