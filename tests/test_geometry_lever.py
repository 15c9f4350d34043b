"""Scissor levers (Eq. 2 in its corrected half-length form)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from mlc.errors import MlcError
from mlc.geometry.lever import solve_lever
from mlc.gates.library import lever_local_points


@pytest.mark.parametrize("args", [
    (1, 1, -0.5, 0.5, 1.5, "open"), (1, 1, 0.5, 0.5, 1.5, "crossed"),
    (2.0, 1, 0.5573, -0.5, 2, "open"), (2.0, 0.5, 0.5573, 0.5, 2, "crossed")])
def test_residuals_and_endpoints(args):
    s = solve_lever(*args)
    assert np.max(np.abs(s.residuals())) < 1e-10
    lin, lout, dlin, dlout = args[:4]
    assert s.output_length(lin) == pytest.approx(lout, abs=1e-10)
    assert s.output_length(lin + dlin) == pytest.approx(lout + dlout, abs=1e-10)


def test_geometry_matches_equations():
    """The placed points realise the lengths Eq. 2 promises (the factor-2 misprint)."""
    s = solve_lever(1, 1, -0.5, 0.5, 1.5, "open")
    for act, lin, lout in ((False, 1.0, 1.0), (True, 0.5, 1.5)):
        p = lever_local_points(s, act)
        assert np.linalg.norm(p["A_up"] - p["A_dn"]) == pytest.approx(lin, abs=1e-12)
        assert np.linalg.norm(p["B_up"] - p["B_dn"]) == pytest.approx(lout, abs=1e-12)
    p0, p1 = lever_local_points(s, False), lever_local_points(s, True)
    # rigid bodies: body "up" of an open lever carries A_up and B_up; their distance is fixed
    assert np.linalg.norm(p0["A_up"] - p0["B_up"]) == pytest.approx(np.linalg.norm(p1["A_up"] - p1["B_up"]))
    assert p0["B_up"][0] - p0["A_up"][0] == pytest.approx(1.5)


def test_transfer_is_monotonic():
    for typ, dl in (("open", -0.5), ("crossed", 0.5)):
        s = solve_lever(1, 1, dl, 0.5, 1.5, typ)
        xs = np.linspace(1, 1 + dl, 30)
        ys = np.array([s.output_length(x) for x in xs])
        assert np.all(np.diff(ys) > 0)


def test_wrong_type_and_infeasible():
    with pytest.raises(MlcError, match="use --type open"):
        solve_lever(1, 1, -0.5, 0.5, 1.5, "crossed")
    with pytest.raises(MlcError, match="no open-hinge lever"):
        solve_lever(1, 1, -0.5, 0.5, 0.2, "open")
    with pytest.raises(MlcError, match="--lin"):
        solve_lever(-1, 1, -0.5, 0.5, 1.5)


@settings(max_examples=40, deadline=None)
@given(lin=st.floats(0.5, 2.5), lout=st.floats(0.5, 2.0), fin=st.floats(0.1, 0.4),
       fout=st.floats(0.1, 0.4), sin=st.sampled_from([-1, 1]), sout=st.sampled_from([-1, 1]),
       l=st.floats(1.2, 3.0))
def test_property_solutions_satisfy_kinematics(lin, lout, fin, fout, sin, sout, l):
    try:
        s = solve_lever(lin, lout, sin * fin * lin, sout * fout * lout, l)
    except MlcError:
        return     # infeasible specs are allowed to be rejected, never mis-solved
    assert np.max(np.abs(s.residuals())) < 1e-9
    assert s.output_length(lin + s.dlin) == pytest.approx(lout + s.dlout, abs=1e-9)
    for a in (s.theta1, s.theta2, s.theta1 + s.dtheta, s.theta2 + s.sign * s.dtheta):
        assert 0 < a < np.pi / 2


def test_too_long_lever_gets_the_right_hint():
    """A lever so long that its angles fall below the scan's T_MIN is refused with a hint
    to shorten it (not to lengthen it); one just inside the bound is solved exactly."""
    with pytest.raises(MlcError, match=r"too long.*at most 5000 sigma"):
        solve_lever(1, 1, 0.5, 0.5, 1e300)
    s = solve_lever(1, 1, 0.5, 0.5, 4000.0)
    assert s.output_length(1.0) == pytest.approx(1.0, abs=1e-9)
    assert s.output_length(1.5) == pytest.approx(1.5, abs=1e-9)
    with pytest.raises(MlcError, match="longer lever"):            # too short: the other hint
        solve_lever(1, 1, 0.5, 0.5, 0.3)
