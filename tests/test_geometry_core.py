"""Logic core (paper Eq. 1): residuals, the paper's numbers, kinematics, the accessible region."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from mlc.errors import MlcError
from mlc.geometry.core import accessible_din_range, design_space, solve_core


def test_paper_design_point():
    s = solve_core(0.5, 2.0)
    assert abs(s.dout - 0.56) < 0.005
    assert np.max(np.abs(s.residuals())) < 1e-10
    assert 0 < s.phi < np.pi / 2 and s.dout > 0
    assert s.x == pytest.approx(2.0 - np.cos(s.phi), abs=1e-14)


def test_kinematics_truth_table():
    """d stays at h unless both inputs are actuated: the core is an AND."""
    s = solve_core(0.5, 2.0)
    d = {st: s.points(1 + 0.5 * int(st[0]), 1 + 0.5 * int(st[1]))["d"][1] for st in ("00", "01", "10", "11")}
    assert d["00"] == pytest.approx(2.0, abs=1e-12)
    assert d["01"] == pytest.approx(2.0, abs=1e-10)
    assert d["10"] == pytest.approx(2.0, abs=1e-10)
    assert d["11"] == pytest.approx(2.0 + s.dout, abs=1e-10)


def test_points_keep_link_lengths():
    s = solve_core(0.5, 2.0)
    for la, lb in [(1.0, 1.2), (1.3, 1.5), (1.5, 1.5)]:
        p = s.points(la, lb)
        assert np.linalg.norm(p["c"] - p["a"]) == pytest.approx(la, abs=1e-12)
        assert np.linalg.norm(p["c"] - p["b"]) == pytest.approx(lb, abs=1e-12)
        assert np.linalg.norm(p["d"] - p["c"]) == pytest.approx(s.x, abs=1e-12)
        assert p["d"][0] == 0.0


@settings(max_examples=40, deadline=None)
@given(h=st.floats(1.2, 3.5), frac=st.floats(0.05, 0.95))
def test_accessible_space_property(h, frac):
    rng = accessible_din_range(h)
    assert rng is not None
    din = frac * rng[1]
    s = solve_core(din, h)
    assert np.max(np.abs(s.residuals())) < 1e-10
    assert 0 < s.phi < np.pi / 2 and s.dout > 0 and s.x > 0
    p = s.points(1 + din, 1.0)
    assert p["d"][1] == pytest.approx(h, abs=1e-8)      # the design condition holds


def test_outside_region_is_one_clear_error():
    with pytest.raises(MlcError) as e:
        solve_core(3.0, 2.0)
    msg = str(e.value)
    assert "accessible range" in msg and "din <=" in msg
    with pytest.raises(MlcError):
        solve_core(-0.1, 2.0)


def test_design_space_data():
    sp = design_space(hs=(1.5, 2.0), n=12)
    assert set(sp["curves"]) == {1.5, 2.0}
    for pts in sp["curves"].values():
        dins = [p[0] for p in pts]
        assert dins == sorted(dins) and len(pts) >= 10
    assert len(sp["boundary"]) > 5
    # along the boundary every point is (barely) accessible
    h, din, dout = sp["boundary"][3]
    assert solve_core(din, h).dout == pytest.approx(dout, rel=1e-9)


def test_cross3_is_numpys_cross_bit_for_bit():
    """The builders' 3-vector cross product equals np.cross exactly (the circuits' scenes
    depend on their last bits), on random vectors of mixed scales and signs, on axis
    vectors and on zeros; and frame_matrix is still a rotation with the asked columns."""
    from mlc.geometry.rotation import cross3, frame_matrix
    rng = np.random.default_rng(7)
    a = rng.normal(size=(20000, 3)) * 10.0 ** rng.integers(-8, 8, size=(20000, 1))
    b = rng.normal(size=(20000, 3)) * 10.0 ** rng.integers(-8, 8, size=(20000, 1))
    special = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0.0, 0, 0], [-0.0, 0, 1.0], [1e-300, 1e300, 1.0]])
    a = np.vstack([a, special, special])
    b = np.vstack([b, special[::-1], special])
    got = np.array([cross3(x, y) for x, y in zip(a, b)])
    want = np.cross(a, b)
    assert np.array_equal(got.view(np.int64), want.view(np.int64))
    R = frame_matrix([1.0, 2.0, 3.0], [0.0, 1.0, -1.0])
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-15) and np.linalg.det(R) > 0
    assert np.allclose(R[:, 0], np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0))
