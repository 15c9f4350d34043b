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



# -- steps: work whose size is not known in advance (synthesis) ----------------------------

def test_steps_move_forward_with_a_budget_eta():
    from mlc.io import progress
    with Progress("synth", steps=("decomposing", "improving", "proving"), show=False) as p:
        assert p.line().startswith("synth  ")                      # before the first step: the timer
        progress.stage("decomposing")
        assert "synth: step 1/3, decomposing" in p.line() and "%" not in p.line()
        done = [0.02]
        progress.stage("improving", lambda: done[0])
        assert "step 2/3, improving" in p.line() and p.line().endswith("(2 % of its budget)")
        p.step_t0 -= 10.0                                           # 10 s into the step, half its budget
        done[0] = 0.5
        assert p.line().endswith("(50 % of its budget, at most about 10 s left)"), p.line()
        progress.stage("decomposing")                               # a nested call: never backwards
        progress.stage("no such step")
        assert "step 2/3, improving" in p.line()
        done[0] = 1.2
        assert p.line().endswith("(its budget spent, finishing)")
        done[0] = None                                              # a reader that fails: no ETA, no error
        assert "step 2/3, improving" in p.line() and "%" not in p.line()
        progress.stage("proving")
        assert "step 3/3, proving" in p.line() and "budget" not in p.line()
    assert progress._active is None                                  # closed: stage() is a no-op again
    progress.stage("improving")
    assert p.step == 2


def test_a_shorter_line_blanks_out_the_longer_one_before():
    s = io.StringIO()
    p = Progress("x", show=True, delay=0.0, stream=s)
    p.label = "a long label"
    p._draw()
    p.label = "x"
    p._draw()
    first, second = s.getvalue().split("\r")[1:]
    assert second.startswith("x  ") and len(second) == len(first)


def test_synthesis_names_its_steps_in_order():
    """compile's display (mlc.logic.synth.STEPS): decomposing, improving (with the work clock's
    fraction of the budget), proving; -O0 has no improving step."""
    from mlc.front.expr import parse
    from mlc.io import progress
    from mlc.logic.synth import STEPS, synthesize

    spec = parse("inputs a, b, c, d\nf = (a & b) | (c ^ d)\ng = a ^ b ^ c\n", "t.expr")
    for level, want in ((2, list(STEPS)), (0, ["decomposing", "proving"])):
        seen = []

        class Recording(Progress):
            def _move(self, name, fraction=None):
                before = self.step
                super()._move(name, fraction)
                if self.step != before:
                    seen.append((self.steps[self.step], None if fraction is None else fraction()))

        with Recording("s", steps=STEPS, show=False):
            synthesize(spec, level)
        assert [n for n, _ in seen] == want, seen
        assert all(0 <= f < 0.5 for n, f in seen if n == "improving"), seen   # read at the step's start
    assert progress._active is None
