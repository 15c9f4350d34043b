"""The circuit back end (mlc.circuit): a compiled netlist becomes one mechanism whose
static equilibrium computes the specification on every row, without interpenetrating
slabs or strained gates; deliberately miswired circuits are caught."""
import copy

import numpy as np
import pytest

from mlc.circuit.build import build_circuit
from mlc.front.load import load
from mlc.pipeline import compile_spec
from mlc.scene.io import dump_scene, parse_scene
from mlc.verify.circuit import format_report, verify_static
from mlc.verify.overlap import clearance
from mlc.verify.static import CONTINUATION_STEPS


@pytest.fixture(scope="module")
def tetris():
    spec = load("examples/tetris.tt", None)
    c = compile_spec(spec)
    return spec, c, build_circuit(c.netlist, spec)


def test_scene_is_posed_consistently_and_round_trips(tetris):
    spec, c, circ = tetris
    sc = circ.scene
    assert sc.inputs == spec.inputs and sc.outputs == spec.outputs
    # every joint closed at build time (the all-zero row), no muscle strained
    A = sc.arrays()
    p = np.array([b.world(s) for b in sc.bodies for s in b.sites])
    d = np.linalg.norm(p[A.bond_i] - p[A.bond_j], axis=1)
    # (joint stops are flat-bottom bonds: free within rest +- tol, and none engaged at build)
    assert np.max(np.maximum(0.0, np.abs(d - A.bond_rest) - A.bond_tol)) < 1e-6
    assert any(b.name.startswith("w_") and b.tolerance > 0 for b in sc.bonds)      # the chains have stops
    dm = np.linalg.norm(p[A.muscle_i] - p[A.muscle_j], axis=1)
    assert np.max(np.abs(dm - A.muscle_rest)) < 1e-6
    # one muscle per circuit input
    assert sorted(m.input for m in sc.muscles) == sorted(spec.inputs)
    back = parse_scene(dump_scene(sc), "circuit.yaml")
    assert len(back.bodies) == len(sc.bodies) and back.truth_table == sc.truth_table


def test_truth_table_is_the_specification(tetris):
    spec, c, circ = tetris
    tt = circ.scene.truth_table
    # examples/tetris.tt, row "01" (y=0, b=1): u2_up = u3_dn = 1, the rest 0
    assert tt["01"] == "00100100"
    assert tt["10"] == "00001001" and tt["11"] == "00001010" and tt["00"] == "00000000"


def test_every_row_verifies_statically_and_reports_clearance(tetris):
    rep = verify_static(tetris[2].scene)
    print(format_report(rep))
    assert rep.ok, format_report(rep)
    assert len(rep.rows) == 4
    for row in rep.rows:
        assert row["joint_stretch"] < 1e-3           # no gate strained by its wiring
        assert row["muscle_strain"] < 1e-3 and row["iterations"] >= CONTINUATION_STEPS   # each step minimised
        assert isinstance(row["clearance"], float) and row["clearance_ok"] == (row["clearance"] > -1e-6)
        # the lanes keep every pair of slabs of different bodies apart in every row (exact box test)
        assert row["clearance"] > 0, (row["state"], row["clearance_pair"])
    strict = verify_static(tetris[2].scene, rows=["11"], require_clearance=True)
    assert strict.ok and strict.rows[0]["clearance_ok"]
    assert tetris[2].scene.meta["connector"]["tight_chains"] == []


def test_rows_in_processes_give_the_same_report_number_for_number(tetris):
    """--jobs: each row in a forked process of its own; every row starts from the scene's
    pose, so the report must not depend on how many run at once (only the seconds may)."""
    import multiprocessing
    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork here: rows run one at a time whatever --jobs says")
    seen = []
    one = verify_static(tetris[2].scene)
    two = verify_static(tetris[2].scene, jobs=3, progress=lambda done, total: seen.append((done, total)))
    for rep in (one, two):
        for row in rep.rows:
            row.pop("seconds")
    assert [r["state"] for r in two.rows] == tetris[2].scene.states()     # in the truth table's order
    assert two.rows == one.rows and two.entries == one.entries
    assert seen == [(k, 4) for k in range(1, 5)]


def test_routing_with_jobs_takes_solves_started_ahead_and_builds_the_same_scene(tetris, monkeypatch):
    """--jobs for the build: the next chains' first solves start in another process; the
    router takes one only for bit-identical arguments, so the scene is the same text; a
    started solve whose arguments differ from what the router asks (a wrong guess of its
    plane) is never taken, and the scene is still the same."""
    import multiprocessing

    from mlc.circuit import route
    from mlc.circuit.build import CircuitOptions
    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork here: nothing is started ahead")
    spec, c, circ = tetris
    want = dump_scene(circ.scene)
    monkeypatch.setattr(route, "_CACHE", {})
    started, taken = route.PREFETCH
    two = build_circuit(c.netlist, spec, CircuitOptions(jobs=2))
    assert route.PREFETCH[1] - taken > 0 and route.PREFETCH[0] - started >= route.PREFETCH[1] - taken
    assert dump_scene(two.scene) == want
    monkeypatch.setattr(route, "_CACHE", {})           # two other processes (forked as solves queue up)
    assert dump_scene(build_circuit(c.netlist, spec, CircuitOptions(jobs=3)).scene) == want

    submit = route.Prefetch.submit

    def off_by_a_hair(self, owner, *args, **kw):            # a wrong guess: other waypoints
        kw["waypoints"] = [(x + 1e-9, y, z) for x, y, z in kw["waypoints"]]
        return submit(self, owner, *args, **kw)
    monkeypatch.setattr(route.Prefetch, "submit", off_by_a_hair)
    monkeypatch.setattr(route, "_CACHE", {})
    started, taken = route.PREFETCH
    wrong = build_circuit(c.netlist, spec, CircuitOptions(jobs=2))
    assert route.PREFETCH[0] > started and route.PREFETCH[1] == taken
    assert dump_scene(wrong.scene) == want


def test_an_error_in_a_row_process_reaches_the_caller_whole(tetris, monkeypatch):
    from mlc.errors import MlcError
    from mlc.verify import circuit

    def boom(scene, state, **kw):
        raise MlcError(f"row {state} refused", "--rows", "pick another")
    monkeypatch.setattr(circuit, "_static_row", boom)
    with pytest.raises(MlcError) as e:
        verify_static(tetris[2].scene, jobs=2)
    assert e.value.where == "--rows" and e.value.fix == "pick another" and "refused" in e.value.message


def test_static_check_reports_the_thermal_spread(tetris):
    """Each probe's harmonic thermal spread at kT (mlc.verify.dynamic.probe_thermal_sd, checked
    against the integrator in test_verify_dynamic): a row is thermal_ok when every margin is
    at least 3 spreads; failing that is a warning, not a wrong bit."""
    from mlc.verify.circuit import THERMAL_SDS

    rep = verify_static(tetris[2].scene, rows=["01"], clearance=False)
    sds = [e["thermal_sd"] for e in rep.entries]
    assert all(0 <= v < 0.25 for v in sds) and max(sds) > 0
    assert min(sds) == 0.0                    # the constant outputs: both probe ends on one body
    hot = verify_static(tetris[2].scene, rows=["01"], clearance=False, kT=1e-2)
    for a, b in zip(rep.entries, hot.entries):  # the harmonic spread grows as sqrt(kT)
        assert b["thermal_sd"] == pytest.approx(a["thermal_sd"] * 1000 ** 0.5, rel=1e-6)
    for r in (rep, hot):
        want = all(e["margin"] >= THERMAL_SDS * e["thermal_sd"] for e in r.entries)
        assert r.ok and r.rows[0]["thermal_ok"] == want
        assert ("WARNING: thermal spread" in format_report(r)) == (not want)
    assert not hot.rows[0]["thermal_ok"] and "past the threshold" in format_report(hot)
    assert "recompile with `mlc compile --joint-k " in format_report(hot)
    assert "thermal_sd" not in verify_static(tetris[2].scene, rows=["01"], clearance=False, kT=None).entries[0]


def test_a_swapped_gate_is_caught(tetris):
    spec, c, _ = tetris
    nl = copy.deepcopy(c.netlist)
    g = next(g for g in nl.gates if g.type == "AND")
    g.type = "NAND"                                  # a lever of the wrong type: the output inverts
    bad = build_circuit(nl, spec)
    rep = verify_static(bad.scene)
    assert not rep.ok
    wrong = {(e["state"], e["output"]) for e in rep.failures()}
    assert ("11", "u4_up") in wrong
    assert "WRONG: row" in format_report(rep)


def test_a_missing_half_unit_is_caught():
    spec = load(None, "f = !a; g = a & b")
    c = compile_spec(spec)
    circ = build_circuit(c.netlist, spec)
    assert verify_static(circ.scene).ok
    nl = copy.deepcopy(c.netlist)
    o = next(o for o in nl.outputs if o.half_unit)
    o.half_unit = False
    rep = verify_static(build_circuit(nl, spec).scene)
    assert not rep.ok
    assert {e["output"] for e in rep.failures()} == {o.name}


def test_constant_and_input_outputs_are_built():
    spec = load(None, "z = a & !a; o = 1; w = a; nw = !b; x = a & b")
    c = compile_spec(spec)
    circ = build_circuit(c.netlist, spec)
    assert set(circ.scene.outputs) == {"z", "o", "w", "nw", "x"}
    rep = verify_static(circ.scene)
    assert rep.ok, format_report(rep)


def test_clearance_is_checked_in_each_row(tetris):
    """The overlap test sees an interpenetration that we put in on purpose."""
    sc = copy.deepcopy(tetris[2].scene)
    a = next(b for b in sc.bodies if b.name.endswith("core_cd"))
    b = next(x for x in sc.bodies if x.name.startswith(a.name.split("_")[0]) and x.name.endswith("a_lo"))
    b.position = a.position.copy()                 # a lever slab moved into the core
    assert clearance(sc).min_clearance < 0


def test_joint_k_stiffens_connector_bonds_and_narrows_the_thermal_spread():
    """CircuitOptions.joint_k multiplies every connector bond's k (hinges, joints, stops) and
    leaves the muscles and the gates at the design k0.  A width carried through a chain of
    junctions in series has compliance ~ n/k, so its harmonic spread shrinks as 1/sqrt(k)
    where the chains dominate: 100x stiffer joints must narrow the output's spread by more
    than 2x and at most 10x (10x: all compliance in the chains; in this small circuit the
    gates keep about a tenth of the variance, so the ratio is near 2.9)."""
    from mlc.circuit.build import CircuitOptions
    from mlc.verify.dynamic import probe_thermal_sd

    c = compile_spec(load(None, "y = (a & b) | c"))
    soft = build_circuit(c.netlist, c.spec, CircuitOptions(joint_k=1.0)).scene     # the paper's joints
    stiff = build_circuit(c.netlist, c.spec).scene                                  # the default: 100 k0
    assert CircuitOptions().joint_k == 100.0
    assert [b.name for b in soft.bonds] == [b.name for b in stiff.bonds]
    for a, b in zip(soft.bonds, stiff.bonds):
        assert b.k == pytest.approx(a.k * (1.0 if a.name.startswith("g") else 100.0)), a.name
    assert [m.k for m in stiff.muscles] == [m.k for m in soft.muscles]
    assert stiff.meta["connector"]["joint_k"] == pytest.approx(100.0)
    s1, s100 = probe_thermal_sd(soft, 1e-5)["y"], probe_thermal_sd(stiff, 1e-5)["y"]
    assert 2.0 < s1 / s100 <= 10.0 + 1e-9, (s1, s100)
    rep = verify_static(stiff, clearance=False)
    assert rep.ok and all(r["thermal_ok"] for r in rep.rows)
    # the suggested joint_k: (3 sd / margin)^2 doubled, times the present k, up to a power of 10
    from mlc.verify.circuit import suggest_joint_k
    assert suggest_joint_k(0.252, 0.25, {}) == 100.0          # the full adder's co at k0: 2 x 9.1 -> 100
    assert suggest_joint_k(0.139, 0.25, {}) == 10.0           # Tetris's g1 output: 2 x 2.8 -> 10
    assert suggest_joint_k(0.05, 0.25, {"joint_k": 100.0}) == 100.0
    assert suggest_joint_k(0.3, 0.25, {"joint_k": 100.0}) == 1e4


def test_slab_points_run_along_every_slab_of_the_gates(tetris):
    """What the router keeps chains from (build._slab_points): points along the middle of
    each slab, no farther apart than GATE_POINT_STEP, each inside its slab."""
    from mlc.circuit.build import GATE_POINT_STEP, _slab_points
    from mlc.geometry.rotation import quat_to_matrix
    scene = tetris[2].scene
    gid = next(iter(scene.meta["gates"]))
    bodies = [b for b in scene.bodies if b.name.startswith(f"{gid}_")]
    pts = _slab_points(bodies)
    n = 0
    for b in bodies:
        R = b.rotation()
        for box in b.boxes:
            A = R @ quat_to_matrix(np.asarray(box.orientation, float))
            c = b.position + R @ np.asarray(box.center, float)
            local = (pts - c) @ A                       # box frame
            inside = np.all(np.abs(local) <= 0.5 * np.asarray(box.size) + 1e-9, axis=1)
            k = int(np.argmax(box.size))
            along = np.sort(local[inside, k])
            assert along[0] <= -0.5 * box.size[k] + 1e-9 and along[-1] >= 0.5 * box.size[k] - 1e-9
            assert np.diff(along).max() <= GATE_POINT_STEP + 1e-9
            n += 1
    assert n > 5 and len(pts) >= n * 2


@pytest.mark.parametrize("tree", [False, True])
def test_five_way_branch_pages_clear_each_other(tree, monkeypatch):
    """The input posts of a branch's pages meet at the tap's joint; from 5 pages on (45
    degrees apart) they stop farther from it, and the built circuit has no overlap
    (it had, by 0.0117 sigma, between adjacent pages' posts).  That is the k-way branch
    (``BRANCH_TREE = False``); the default tree of 2-way branches (session 52) hangs
    2 (k - 1) = 8 pages, 3 deep, and is clear too."""
    from mlc.circuit import build as B
    monkeypatch.setattr(B, "BRANCH_TREE", tree)
    spec = load(None, "f1 = a & b; f2 = a & c; f3 = a | d; f4 = ~a & e; f5 = a | e")
    c = compile_spec(spec)
    sc = build_circuit(c.netlist, spec).scene
    assert sum(b.name.startswith("w_a_p") and b.name.endswith("_AB") for b in sc.bodies) == (8 if tree else 5)
    rep = clearance(sc)
    print("smallest clearance", rep.min_clearance, rep.pair)
    assert rep.min_clearance > 0.0, rep.pair


def _no_contact_rip_up(routed, lanes, space, space_clear, geo, margin=None, cache=None):
    """build._rip_up_contacts that only measures."""
    from mlc.circuit import build as B
    return [], B._state_contacts(routed, geo, cache=cache, margin=margin)


def test_rip_up_reroutes_a_chain_and_the_one_it_presses_into(monkeypatch):
    """Routed with wires g4 and g5 first, the full adder's chain w_g5_0 comes 1.30 sigma
    from w_g4_1, routed before it, which could not make room (layer centres; 1.8 keeps
    them apart by the sphere bound).  With the rip-up's threshold at 1.4 sigma (1.2 by
    default, which leaves this pair alone), w_g4_1 is routed again around it, then w_g5_0,
    and the two new routes are kept only if they are farther apart."""
    from mlc.circuit import build as B
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    opt = B.CircuitOptions()
    # this rip-up alone: the contact rip-up (_rip_up_contacts) takes this pair apart too
    monkeypatch.setattr(B, "_rip_up_contacts", _no_contact_rip_up)
    monkeypatch.setattr(B, "RIP_GAP", 0.0)              # no rip-up
    plain = B._build_circuit(c.netlist, spec, opt, first_wires=("g4", "g5")).assemble()
    monkeypatch.setattr(B, "RIP_GAP", 1.4)
    ripped = B._build_circuit(c.netlist, spec, opt, first_wires=("g4", "g5")).assemble()
    assert plain.closest < B.RIP_GAP and "rerouted" not in plain.scene.meta["connector"]
    assert ripped.scene.meta["connector"]["rerouted"], "no chain was routed again"
    assert ripped.closest > plain.closest, (plain.closest, ripped.closest)
    ripped.scene.check()
    # the untouched chains are the same, body for body
    moved = {t for pair in ripped.scene.meta["connector"]["rerouted"] for t in pair}
    keep = lambda sc: {b.name: tuple(b.position) for b in sc.bodies if not any(b.name.startswith(t + "_") for t in moved)}
    assert keep(plain.scene) == keep(ripped.scene)


def test_contact_rip_up_reroutes_chains_whose_layers_would_touch_when_a_wire_switches(monkeypatch):
    """With the contact margin raised to 0.6 sigma (0.05 by default), chain pairs of the
    full adder (wires g4 and g5 routed first) whose layers, as rigid rhombi in any state of
    their wires, clear each other by less are routed again (the one routed earlier first);
    each pair re-routed clears by more than before, and every other chain keeps its bodies."""
    from mlc.circuit import build as B
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    opt = B.CircuitOptions()
    monkeypatch.setattr(B, "RIP_GAP", 0.0)
    monkeypatch.setattr(B, "CONTACT_MARGIN", 0.6)
    real = B._rip_up_contacts
    monkeypatch.setattr(B, "_rip_up_contacts", _no_contact_rip_up)
    plain = B._build_circuit(c.netlist, spec, opt, first_wires=("g4", "g5")).assemble()
    monkeypatch.setattr(B, "_rip_up_contacts", real)
    ripped = B._build_circuit(c.netlist, spec, opt, first_wires=("g4", "g5")).assemble()
    pairs = ripped.scene.meta["connector"].get("rerouted_contacts")
    assert pairs, "no chain was routed again"
    assert "rerouted_contacts" not in plain.scene.meta["connector"]

    def worst(circ, tags):
        return min(k.clearance for k in circ.contacts if k.a in tags or k.b in tags)
    for a, b in pairs:
        assert worst(ripped, {a, b}) > worst(plain, {a, b}), (a, b)
    ripped.scene.check()
    moved = {t for pair in pairs for t in pair}
    keep = lambda sc: {b.name: tuple(b.position) for b in sc.bodies if not any(b.name.startswith(t + "_") for t in moved)}
    assert keep(plain.scene) == keep(ripped.scene)


def test_build_time_estimate_follows_the_measured_circuits():
    """The refusal's estimate (mlc.circuit.build.build_cpu_estimate) against the committed
    build CPU of the adders and multipliers of 10 gates and more (benchmarks/circuit_scaling.py):
    within a factor 3 of each (a power law through noisy points: a second build when chains
    are left tight doubles a build), and MAX_GATES is where the estimate reaches an hour."""
    import json
    from pathlib import Path

    from mlc.circuit import build as cb
    res = json.loads((Path(__file__).resolve().parents[1] / "benchmarks" / "results" /
                      "circuit_scaling.json").read_text())
    pts = [a for a in res["adders"] + res.get("multipliers", []) if a["gates"] >= 10 and "build_cpu_s" in a]
    assert len(pts) >= 4
    for a in pts:
        ratio = cb.build_cpu_estimate(a["gates"]) / a["build_cpu_s"]
        assert 1 / 3 < ratio < 3, (a["gates"], a["build_cpu_s"], ratio)
    assert cb.build_cpu_estimate(cb.MAX_GATES) <= cb.MAX_BUILD_CPU < cb.build_cpu_estimate(cb.MAX_GATES + 1)


def test_the_fast_routers_estimate_follows_its_measured_circuits():
    """The fast router's estimate against the committed build CPU of its series
    (``circuit_scaling.py --router fast``: the adders and meshes of circuit_scaling_fast.json)
    from 10 gates on: within a factor 3 of each, and MAX_FAST_GATES is where it reaches an
    hour."""
    import json
    from pathlib import Path

    from mlc.circuit import build as cb
    res = Path(__file__).resolve().parents[1] / "benchmarks" / "results"
    d = json.loads((res / "circuit_scaling_fast.json").read_text())
    pts = [a for a in d.get("adders", []) + d.get("meshes", []) if a["gates"] >= 10 and "build_cpu_s" in a]
    assert len(pts) >= 5 and max(a["gates"] for a in pts) >= 200
    assert all(a["router"] == "fast" for a in pts)
    for a in pts:
        ratio = cb.build_cpu_estimate(a["gates"], "fast") / a["build_cpu_s"]
        assert 1 / 3 < ratio < 3, (a["gates"], a["build_cpu_s"], ratio)
    est = lambda g: cb.build_cpu_estimate(g, "fast")
    assert est(cb.MAX_FAST_GATES) <= cb.MAX_BUILD_CPU < est(cb.MAX_FAST_GATES + 1)


def test_a_netlist_too_large_to_build_is_refused_with_the_estimate(monkeypatch, tmp_path, capsys):
    """An 84-AND circuit (EPFL ctrl) routed for 45 min without a word; now refused before the work,
    naming the estimate, --no-circuit and the --max-gates that would build it, exit 2, nothing
    written; with that --max-gates (not one less) it builds."""
    import re

    from mlc.circuit import build as cb
    from mlc.cli import main
    monkeypatch.setattr(cb, "MAX_GATES", 2)
    out = tmp_path / "o"
    assert main(["compile", "-e", "s = a ^ b ^ c; k = a & b | c", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "gates; placing and routing it as one mechanism would take about" in err and "--no-circuit" in err, err
    assert err.count("\n") == 1 and not out.exists()
    n = int(re.search(r"netlist has (\d+) gates", err).group(1))
    assert f"--max-gates {n}" in err, err
    assert main(["compile", "-e", "s = a ^ b ^ c; k = a & b | c", "-o", str(out), "--max-gates", str(n - 1)]) == 2
    assert not out.exists() and "at most %d gates" % (n - 1) in capsys.readouterr().err
    assert main(["compile", "-e", "s = a ^ b ^ c; k = a & b | c", "-o", str(out), "--max-gates", str(n)]) == 0
    assert (out / "circuit.yaml").is_file()                     # the limit lifted, the circuit built


def test_max_gates_is_checked_before_the_work(tmp_path, capsys):
    from mlc.cli import main
    out = tmp_path / "o"
    assert main(["compile", "-e", "s = a & b", "-o", str(out), "--max-gates", "0"]) == 2
    assert "--max-gates must be at least 1" in capsys.readouterr().err and not out.exists()
    assert main(["compile", "-e", "s = a & b", "-o", str(out), "--no-circuit", "--max-gates", "5"]) == 2
    assert "--max-gates only applies to the circuit" in capsys.readouterr().err and not out.exists()


def _chain_edges(nl, sources):
    names = {w.name for w in sources}
    return [(p.src, ("gate", g.id)) for g in nl.gates for p in (g.a, g.b)
            if p.src[0] == "gate" or p.src[1] in names]


def _sources(nl):
    cons = {}
    for g in nl.gates:
        for p in (g.a, g.b):
            cons.setdefault(p.src, []).append("pin")
    for o in nl.outputs:
        if o.kind != "const":
            cons.setdefault(o.src, []).append("out")
    return [w for w in nl.inputs if cons.get(("input", w.name)) != ["pin"]]


@pytest.mark.parametrize("example", ["full_adder.tt", "mux4.blif", "tetris.tt"])
def test_placement_levels_are_the_least_rise_found_by_enumeration(example):
    """place_levels (a linear programme) against an exhaustive search over every placement
    whose chains all rise, each node between its depth and the deepest level: the same
    least summed rise, ties to the lowest levels (the sum of levels also equal)."""
    import itertools

    from mlc.circuit.build import place_levels
    nl = compile_spec(load(f"examples/{example}", None)).netlist
    src = _sources(nl)
    got = place_levels(nl, src)
    edges = _chain_edges(nl, src)
    dmax = max(g.depth for g in nl.gates)
    nodes = sorted(got)
    lo = {("gate", g.id): g.depth for g in nl.gates} | {("input", w.name): 0 for w in src}
    best = None
    for combo in itertools.product(*[range(lo[v], dmax + (v[0] == "gate")) for v in nodes]):
        lv = dict(zip(nodes, combo))
        if all(lv[v] >= lv[u] + 1 for u, v in edges):
            key = (sum(lv[v] - lv[u] for u, v in edges), sum(combo))
            best = key if best is None or key < best else best
    assert (sum(got[v] - got[u] for u, v in edges), sum(got.values())) == best
    assert all(got[v] >= got[u] + 1 for u, v in edges) and all(got[v] >= 1 for v in got if v[0] == "gate")


def test_placement_levels_shorten_a_ripple_adders_wires():
    """Logic depth puts every input's source at level 0 and every gate at its depth, so the
    inputs of a wide adder's last bit rise through the whole circuit: the summed rise grows
    as the width squared (246 levels at 8 bits, 878 at 16).  The least-rise levels keep each
    bit's wires bounded: at most half of that at 8 bits, and growing linearly with the width."""
    from mlc.circuit.build import place_levels
    from mlc.logic.library import ripple_adder
    rises = {}
    for w in (8, 16):
        nl = compile_spec(ripple_adder(w), 2, "expand").netlist
        src = _sources(nl)
        got = place_levels(nl, src)
        edges = _chain_edges(nl, src)
        depth = {("gate", g.id): g.depth for g in nl.gates} | {("input", w.name): 0 for w in src}
        rise = lambda lv: sum(lv[v] - lv[u] for u, v in edges)
        rises[w] = (rise(got), rise(depth))
        assert max(got.values()) == max(depth.values())
    assert rises[8][1] == 246 and rises[16][1] == 878, rises
    assert rises[8][0] <= 0.5 * rises[8][1], rises
    assert rises[16][0] <= 2.2 * rises[8][0], rises


def test_a_source_above_level_0_stands_in_its_levels_row_and_the_circuit_computes():
    """The full adder's input a feeds gates two levels up: its source stands in level 1's row
    (at that level's height, off every gate's x), and the circuit reads right in the rows
    where only a switches (static equilibrium, clear of interpenetration)."""
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    circ = build_circuit(c.netlist, spec)
    sc = circ.scene
    src = [b for b in sc.bodies if b.name.startswith("src_a_")]
    assert src, "input a has no source"
    za = np.mean([b.position[2] for b in src])
    gz = sorted({round(v["origin"][2], 6) for v in sc.meta["gates"].values()})
    assert za > 1.0 and any(abs(za - z) < 3.0 for z in gz), (za, gz)
    xa = np.mean([b.position[0] for b in src])
    same_level = [v["origin"][0] for v in sc.meta["gates"].values() if abs(v["origin"][2] - za) < 3.0]
    assert min(abs(xa - x) for x in same_level) > 6.0
    rep = verify_static(sc, rows=["000", "100"])
    assert rep.ok, format_report(rep)
    assert min(r["clearance"] for r in rep.rows) > 0


def test_a_wire_longer_than_any_chain_is_refused_before_routing(monkeypatch):
    """A 4 x 4 array multiplier's input a0 feeds a gate 532 sigma from its source, beyond the
    400 half units (1 sigma each) of the longest chain the router tries.  Before, each such
    chain was tried plane by plane (17 minutes on the 6 x 6 multiplier) and then refused;
    now the build refuses it before routing any chain, naming the wire, the sink, the
    distance and the fix."""
    from mlc.circuit import build as cb
    from mlc.errors import MlcError
    from mlc.logic.library import array_multiplier

    def never(*a, **k):
        raise AssertionError("a chain was routed")
    monkeypatch.setattr(cb, "_route_chain", never)
    spec = array_multiplier(4)
    c = compile_spec(spec, 2, "expand")
    assert len(c.netlist.gates) <= cb.MAX_GATES
    with pytest.raises(MlcError) as e:
        build_circuit(c.netlist, spec)
    msg = str(e.value)
    assert "cannot route input a0 to g" in msg and "beyond the longest connector chain" in msg, msg
    assert "--no-circuit" in msg
    d = float(msg.split("stands ")[1].split(" sigma")[0])
    assert d > 400


@pytest.fixture(scope="module")
def full_adder():
    spec = load("examples/full_adder.tt", None)
    return build_circuit(compile_spec(spec).netlist, spec).scene


def test_body_levels_put_every_wire_with_or_before_the_gate_it_feeds(full_adder, tetris):
    """mlc.circuit.levels: a gate's bodies take its depth; a wire takes the depth of the
    gate whose input lever it drives, so it is solved with that gate and after its driver."""
    from mlc.circuit.levels import body_levels

    sc = full_adder
    lv = body_levels(sc)
    gates = sc.meta["gates"]
    names = [b.name for b in sc.bodies]
    for b, n in enumerate(names):
        g = n.split("_")[0]
        if g in gates:
            assert lv[b] == gates[g]["depth"], n
    A = sc.arrays()
    bi, bj = A.site_body[A.bond_i], A.site_body[A.bond_j]
    fed = drives = 0
    for x, y in zip(bi, bj):
        for w, g in ((x, y), (y, x)):
            gn, _, part = names[g].partition("_")
            if names[w].startswith("w_") and gn in gates:
                if part in ("a_lo", "a_hi", "b_lo", "b_hi"):
                    assert lv[w] <= gates[gn]["depth"], (names[w], names[g])
                    fed += 1
                elif part.startswith("out"):
                    assert lv[w] > gates[gn]["depth"], (names[w], names[g])
                    drives += 1
    assert fed and drives
    from mlc.gates.library import gate_scene

    assert body_levels(gate_scene("NAND")) is None          # a gate alone has no levels
    # Tetris: one level of gates; its constant outputs' bodies, bonded to no gate, join it
    assert set(body_levels(tetris[2].scene)) == {1}


def test_the_level_by_level_continuation_reaches_the_stock_equilibrium(full_adder):
    """mlc.verify.static._staged: level by level, each level's inputs already right, leaves
    the circuit next to its equilibrium (every output within 1e-3 sigma of its ideal length
    before any minimisation of the whole scene); the equilibrium that follows reads the same
    lengths as the stock continuation's, to within 1e-4 sigma: both poses meet every joint
    to POLISH_ABOVE (1e-7 sigma), the stock one after minimising the whole scene, and the
    levers amplify what is left; a wrong branch would be tenths of sigma off."""
    import mlc.verify.static as st
    from mlc.circuit.levels import body_levels

    sc = full_adder
    lv = body_levels(sc)
    assert len(np.unique(lv)) == 4                  # depths 1 to 4
    A = sc.arrays()
    row = "011"
    L0, L1 = A.muscle_lengths(st._state_bits(sc, "000")), A.muscle_lengths(st._state_bits(sc, row))
    prob = st._Problem(sc, A.pos, A.quat, pin_first=False)
    st._staged(prob, lv, L0, L1, CONTINUATION_STEPS)
    p, _ = prob.sites()
    want = sc.truth_table[row]
    for pr, i, j in zip(sc.probes, A.probe_i, A.probe_j):
        bit = int(want[sc.outputs.index(pr.output)])
        assert abs(np.linalg.norm(p[i] - p[j]) - (pr.actuated if bit else pr.rest)) < 1e-3, pr.name
    stock = st.equilibrium(sc, row, polish=None)
    staged = st.equilibrium(sc, row, polish=None, levels=lv)
    assert staged.converged and staged.max_joint_stretch < 1e-6
    for k in stock.probes:
        assert abs(stock.probes[k] - staged.probes[k]) < 1e-4, k


def test_the_router_is_chosen_by_size_and_an_unknown_one_is_refused():
    from mlc.circuit.build import FAST_FROM, CircuitOptions, router_of
    assert router_of(CircuitOptions(), FAST_FROM - 1) == "ik"
    assert router_of(CircuitOptions(), FAST_FROM) == "fast"
    assert router_of(CircuitOptions(router="ik"), 10 * FAST_FROM) == "ik"
    assert router_of(CircuitOptions(router="fast"), 1) == "fast"
    with pytest.raises(ValueError):
        router_of(CircuitOptions(router="astar"), 3)


def test_the_fast_router_builds_a_full_adder_that_computes_every_row():
    """The fast router (each chain steered along its lane and closed near its end) builds
    the full adder into a scene whose every row reads right at static equilibrium, clear
    of interpenetration and with no gate strained; the scene says which router made it, and
    its chains are not the whole-chain solver's."""
    from mlc.circuit.build import CircuitOptions
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    fast = build_circuit(c.netlist, spec, CircuitOptions(router="fast"))
    assert fast.scene.meta["connector"]["router"] == "fast"
    ik = build_circuit(c.netlist, spec)
    assert "router" not in ik.scene.meta["connector"]
    assert fast.half_units != ik.half_units or dump_scene(fast.scene) != dump_scene(ik.scene)
    rep = verify_static(fast.scene)
    assert rep.ok and len(rep.rows) == 8, format_report(rep)
    assert min(r["clearance"] for r in rep.rows) > 0, format_report(rep)


def test_the_contact_test_builds_only_the_layers_it_measures_and_finds_the_same_contacts(monkeypatch):
    """``_state_contacts`` builds the boxes of the candidate layers alone
    (``_chain_parts(..., only=...)``, the last half unit with its longer post as the whole
    chain makes it): its contacts are the same, clearance for clearance, as those measured on
    the whole chains' boxes (the full adder, wires g4 and g5 routed first, contact margin
    raised to 0.6 sigma so that there are contacts, the last half units among them)."""
    from mlc.circuit import build as B
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    monkeypatch.setattr(B, "CONTACT_MARGIN", 0.6)
    monkeypatch.setattr(B, "_rip_up_contacts", _no_contact_rip_up)
    routed = {}
    real_rip = B._rip_up

    def keep(r, *a, **k):
        routed.update(r)
        return real_rip(r, *a, **k)
    monkeypatch.setattr(B, "_rip_up", keep)
    B._build_circuit(c.netlist, spec, B.CircuitOptions(), first_wires=("g4", "g5"))
    geo = next(iter(routed.values())).geo_ext[0]
    fast = B._state_contacts(routed, geo)
    real = B._chain_parts
    monkeypatch.setattr(B, "_chain_parts", lambda ch, geo, flip=0, only=None: real(ch, geo, flip))
    whole = B._state_contacts(routed, geo)
    assert len(fast) > 20 and fast == whole
    last = {t: len(ch.route.bends) - 1 for t, ch in routed.items()}
    assert any(k.i == last[k.a] or k.j == last[k.b] for k in fast)


def test_a_branch_chains_first_layers_are_held_apart_before_it_is_routed(monkeypatch):
    """A chain of a branch is kept apart from its siblings' first layers even when it is
    routed before them: each branch chain's head layers (``_head_layers``, straight on from
    its page) are in the keep-apart space from the start, each chain sees every other
    chain's (routed or held) when it is routed, and the held ones are where the routed
    first layers come to lie, within a fraction of a layer's bound."""
    from mlc.circuit import build as B
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    seen, done = {}, {}
    route_chain = B._route_chain

    def spy(ch, lanes, space, space_clear, pf=None):
        seen[ch.tag] = {tuple(np.round(p, 9)) for p in space.points(ch.tag)}
        route_chain(ch, lanes, space, space_clear, pf)
        done[ch.tag] = ch

    monkeypatch.setattr(B, "_route_chain", spy)
    B._build_circuit(c.netlist, spec, B.CircuitOptions(router="fast"))
    branch = [ch for ch in done.values() if ch.skip]
    assert len(branch) >= 4, "the full adder has fan-out: some chains start on branch pages"
    for ch in branch:
        heads = B._head_layers(ch)
        assert heads.shape == (B.BRANCH_LAYERS, 3)
        # every other branch chain's first layers were in the space this chain was routed in
        for other in branch:
            if other is not ch:
                want = B._head_layers(other) if list(done).index(other.tag) > list(done).index(ch.tag) \
                    else other.layers()[:other.skip]
                got = seen[ch.tag]
                assert all(tuple(np.round(p, 9)) in got for p in want), (ch.tag, other.tag)
        # held where the routed chain starts: well within a layer's bounding radius
        assert np.linalg.norm(ch.layers()[:ch.skip] - heads, axis=1).max() < 0.5 * B.LAYER_RADIUS


def test_the_fast_routers_two_way_branch_pages_are_held_clear_of_each_other():
    """In a fast build a 2-way branch's pages leave up and towards the routing planes
    (``FAST_PAIR_PAGES``), with a stop between them (``_page_stop``): free while the pages
    are at least ``PAGE_MIN_ANGLE`` apart about the pair they hang on, stiff when they close
    further; their posts are long enough that at that angle the two pages' slabs are still
    clear (exact box clearance), and closer than their posts allow they would touch."""
    import math

    from mlc.circuit import build as B
    from mlc.geometry.rotation import expmap, matrix_to_quat, quat_to_matrix
    spec = load("examples/full_adder.tt", None)
    c = compile_spec(spec)
    sc = build_circuit(c.netlist, spec, B.CircuitOptions(router="fast")).scene
    stops = [b for b in sc.bonds if b.name.endswith("_pp")]
    assert stops, "the full adder's 2-way branches get a page stop"
    by = {b.name: b for b in sc.bodies}
    for bond in stops:
        p0, p1 = bond.a.split("_AB.")[0], bond.b.split("_AB.")[0]
        names = [f"{p}_{s}" for p in (p0, p1) for s in ("AB", "BC", "CD", "DA")]
        # the axis both pages turn about: through the joints of the second page's A and C posts
        a, cpt = by[f"{p1}_AB"].world("A"), by[f"{p1}_CD"].world("C")
        assert np.allclose(a, by[f"{p0}_AB"].world("A")) and np.allclose(cpt, by[f"{p0}_CD"].world("C"))
        u = (cpt - a) / np.linalg.norm(cpt - a)
        t0 = by[f"{p0}_AB"].world("stop_in") - a
        t1 = by[f"{p1}_AB"].world("stop_in") - a
        built = math.acos(float(t0 @ t1 / np.linalg.norm(t0) / np.linalg.norm(t1)))
        assert abs(built - (B.FAST_PAIR_PAGES[1] - B.FAST_PAIR_PAGES[0])) < 1e-9
        sign = 1.0 if float(np.cross(t1, t0) @ u) > 0 else -1.0    # turning p1 by +sign closes them

        def posed(close):
            """The two pages' bodies and their own bonds, p1 turned by ``close`` towards p0."""
            R = expmap(sign * close * u)
            sub = copy.copy(sc)
            sub.bodies = [copy.deepcopy(by[n]) for n in names]
            for b in sub.bodies:
                if b.name.startswith(p1 + "_"):
                    b.position = a + R @ (b.position - a)
                    b.orientation = matrix_to_quat(R @ quat_to_matrix(b.orientation))
            keep = set(names)
            sub.bonds = [bd for bd in sc.bonds if {bd.a.split(".")[0], bd.b.split(".")[0]} <= keep]
            return sub

        def energy(sub):
            bb = {b.name: b for b in sub.bodies}
            d = np.linalg.norm(bb[bond.a.split(".")[0]].world("stop_in") - bb[bond.b.split(".")[0]].world("stop_in"))
            return 0.5 * bond.k * max(0.0, abs(d - bond.rest) - bond.tolerance) ** 2

        at_stop = built - B.PAGE_MIN_ANGLE
        assert energy(posed(0.0)) == 0.0 and energy(posed(at_stop - 1e-3)) == 0.0
        assert energy(posed(at_stop + 0.05)) > 0.0           # closer than the stop: held
        assert clearance(posed(at_stop)).min_clearance > 0    # clear at the stop's angle
        # and the stop is needed: the pages, free to close to 20 degrees apart, would touch
        assert clearance(posed(built - math.radians(20.0))).min_clearance < 0


def test_layers_of_a_long_chain_are_its_built_frames_where_the_fast_recurrence_diverges():
    """``_layers`` takes the router's quick frame recurrence, whose error grows along a
    chain; on 150 half units of alternating bends it overflows to NaN (session 39: a chain
    of the fast-built 4-bit adder stopped the build).  The layer centres are then those of
    the exact frames that build the bodies (``chain_frames``), and where the recurrence
    holds they are its own, unchanged."""
    from types import SimpleNamespace

    from mlc.circuit import build as B
    from mlc.circuit.lanes import layer_centres
    from mlc.circuit.route import _fk
    from mlc.gates.connector import chain_frames
    u0 = np.array([-0.21784433, 0.97598353, 0.0])
    u0 /= np.linalg.norm(u0)
    t0 = np.array([0.0, 0.0, 1.0])
    geo = SimpleNamespace(pitch=1.0)
    for n, expect_diverged in ((150, True), (40, False)):
        bends = np.tile([0.386, -0.386, 0.386, 0.383, -0.386, -0.38], n)[:n]
        route = SimpleNamespace(centre=np.zeros(3), axis=u0, tangent=t0, bends=bends)
        with np.errstate(all="ignore"):
            quick = layer_centres(_fk(route.centre, u0, t0, bends, 1.0)[0])
        assert (not np.all(np.isfinite(quick))) == expect_diverged
        got = B._layers(route, geo, 0.0)
        want = layer_centres(chain_frames(route.centre, u0, t0, bends, 1.0)[0])
        assert np.all(np.isfinite(got)) and np.allclose(got, want, atol=1e-9)
        if not expect_diverged:
            assert np.array_equal(got, quick)          # the recurrence's own bits where it holds


@pytest.mark.parametrize("which", ["circuit", "robot"])
def test_a_chain_ends_under_its_input_levers_on_their_pivot_axis_clear_of_the_joint_at_d(which):
    """A chain into a gate's input ends on sites ``in_end``: the levers' ``in`` sites moved
    END_DROP (a robot's circuit: CIRCUIT_END_DROP) down the pivot axis, so they turn as
    ``in`` does (the lever's stroke is the same), carried by a post.  In every row the end
    joints stay at least 0.48 sigma (a junction's ball and collar) from the sink gate's
    universal joint at d, where ``in`` itself comes within 0.3 sigma in some row of
    (a & b) | c (docs/circuits.md)."""
    from mlc.circuit.build import END_DROP, POST_WIDTH, CircuitOptions
    from mlc.geometry.rotation import quat_to_matrix
    from mlc.robot.build import CIRCUIT_END_DROP
    from mlc.verify.static import solve_states

    drop = END_DROP if which == "circuit" else CIRCUIT_END_DROP
    spec = load(None, "(a & b) | c")
    sc = build_circuit(compile_spec(spec).netlist, spec, CircuitOptions(end_drop=drop)).scene
    ends = [bd for bd in sc.bonds if bd.name.startswith("w_") and "_end_" in bd.name]
    assert len(ends) == 2
    sinks = {bd.b.split(".")[0] for bd in ends}
    assert all(bd.b.endswith(".in_end") for bd in ends) and len(sinks) == 2
    for bn in sinks:
        b = sc.body(bn)
        axis = b.sites["piv_1"] - b.sites["piv_0"]
        axis /= np.linalg.norm(axis)
        off = b.sites["in_end"] - b.sites["in"]
        assert abs(np.linalg.norm(off) - drop) < 1e-9
        assert np.linalg.norm(np.cross(off, axis)) < 1e-9          # on the pivot axis through in
        post = b.boxes[-1]                                          # the post ends POST_WIDTH short of it
        tip = post.center + 0.5 * post.size[0] * (quat_to_matrix(post.orientation) @ [1.0, 0, 0])
        assert abs(np.linalg.norm(tip - b.sites["in_end"]) - POST_WIDTH) < 1e-9
    gid = next(iter(sinks)).split("_")[0]
    idx = {b.name: i for i, b in enumerate(sc.bodies)}

    def at(eq, ref):
        bn, site = ref.split(".")
        return eq.pos[idx[bn]] + quat_to_matrix(eq.quat[idx[bn]]) @ sc.body(bn).sites[site]

    near_in, near_end = np.inf, np.inf
    for row, eq in solve_states(sc).items():
        d = at(eq, f"{gid}_core_cd.d")
        for bn in sinks:
            near_in = min(near_in, np.linalg.norm(at(eq, f"{bn}.in") - d))
            near_end = min(near_end, np.linalg.norm(at(eq, f"{bn}.in_end") - d))
        assert sc.truth_table[row] == "".join("1" if L > 1.25 else "0" for L in eq.probes.values())
    assert near_in < 0.3 < 0.48 <= near_end, (near_in, near_end)


def test_end_drop_0_ends_chains_on_the_in_sites_as_before_session_44():
    """CircuitOptions(end_drop=0) ends every chain on the levers' in sites with no post: the
    scene before session 44 (a robot's circuit until session 45)."""
    from mlc.circuit.build import CircuitOptions
    spec = load(None, "(a & b) | c")
    net = compile_spec(spec).netlist
    flat = build_circuit(net, spec, CircuitOptions(end_drop=0.0)).scene
    low = build_circuit(net, spec).scene
    for sc, site in ((flat, ".in"), (low, ".in_end")):
        ends = [bd for bd in sc.bonds if bd.name.startswith("w_") and "_end_" in bd.name]
        assert len(ends) == 2 and all(bd.b.endswith(site) for bd in ends), [bd.b for bd in ends]
    assert not any("in_end" in b.sites for b in flat.bodies)
    assert sum(len(b.boxes) for b in low.bodies if b.name.startswith("g2_")) == \
        sum(len(b.boxes) for b in flat.bodies if b.name.startswith("g2_")) + 2     # the two posts
