"""mlc.io.progress: the bar's line, and moving within one long item (Progress.within)."""
import io

from mlc.io.progress import Progress


def test_within_moves_the_bar_inside_an_item_and_caps_it():
    s = io.StringIO()
    bar = Progress("job", total=4, show=True, delay=0.0, stream=s)
    f = bar.within(2, 10.0)
    assert f is not None
    f(5.0)
    assert bar.done == 2.5 and "2/4" in bar.line()          # whole items counted
    assert bar.line().split("[")[1].count("#") == int(24 * 2.5 / 4)
    f(100.0)                                                # past the estimate: capped
    assert bar.done == 2.95
    bar.update(3)
    assert bar.done == 3 and "3/4" in bar.line()
    assert "\r" in s.getvalue()                             # it drew


def test_within_is_none_when_hidden_or_without_an_estimate():
    assert Progress("job", total=4, show=False).within(0, 10.0) is None
    assert Progress("job", total=4, show=True, stream=io.StringIO()).within(0, 0.0) is None
