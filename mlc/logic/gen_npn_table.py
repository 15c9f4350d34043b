"""Generate ``npn4_exact.json``: a minimum-AND circuit for each 4-input NPN class.

    python -m mlc.logic.gen_npn_table [CACHE_DIR [reverse]]   # generate (resumable)
    python -m mlc.logic.gen_npn_table --prove SECONDS [reverse] # prove unproven entries

Offline only: the table is committed, and nothing at run time regenerates it.
Every SAT call uses CaDiCaL (python-sat) in a child process killed at its time
limit, with the class representative's input symmetries broken
(``exactsat.symmetric_inputs``: 2.7x faster on a fully symmetric class).  Per class: increasing k with a short limit per call (every k below the
answer is then *proven* infeasible); if a call times out, descend from mlc's own
heuristic circuit by SAT and try to prove the last step with a longer limit.
Entries whose minimality was not proven within the limits carry
``"proven": false`` and are listed under ``"unproven"``; ``--prove`` retries them
with SECONDS per call (several provers may share the work).  Every circuit is
re-simulated before it is written.  The hardest proofs (one gate fewer than 9
ANDs is infeasible) take about 1-8 minutes each on one core.
"""
from __future__ import annotations

import json
import sys
import time

from mlc.logic import exactsat, npn
from mlc.logic import tt as T


PROOF_SECONDS = 900.0    # per SAT call; a timed-out call leaves the entry unproven
QUICK_SECONDS = 10.0
SOLVER = "cadical195"


def solve_class(R: int) -> dict:
    n = 4
    full = 0xFFFF
    if R in (0, full):
        return {"ands": 0, "gates": [], "out": [-1, 1 if R else 0], "proven": True}
    for i in range(4):
        for c in (0, 1):
            if R == T.var(4, i) ^ (full if c else 0):
                return {"ands": 0, "gates": [], "out": [i, c], "proven": True}
    sup = len(T.support(R, 4))
    k = max(1, sup - 1)
    # easy classes: increasing k with a short limit per call
    while True:
        r = exactsat.synthesize_exact(n, [(R, full)], k, time_limit=QUICK_SECONDS, solver=SOLVER,
                                     symmetry=True)
        if r == "timeout":
            break
        if r is not None:
            return _entry(R, k, r, True)
        k += 1
    # hard classes: every k' < k is proven infeasible; descend from a heuristic circuit
    best = _heuristic(R)
    kk = len(best[0]) - 1
    proven = False
    while kk >= k:
        r = exactsat.synthesize_exact(n, [(R, full)], kk, time_limit=PROOF_SECONDS, solver=SOLVER,
                                     symmetry=True)
        if r == "timeout":
            break
        if r is None:
            proven = True
            break
        best = r
        kk -= 1
    if kk < k:
        proven = True           # reached the proven lower bound
    return _entry(R, len(best[0]), best, proven)


def _entry(R, k, circ, proven):
    gates, outs = circ
    assert len(gates) == k
    assert exactsat.circuit_tables(4, gates, outs) == [R]
    return {"ands": k, "gates": [list(g) for g in gates], "out": list(outs[0]),
            "proven": proven}


def _heuristic(R):
    """A (not necessarily minimum) circuit from mlc's own synthesis, as gate tuples."""
    from mlc.spec import TableSpec
    from mlc.logic.synth import synthesize
    g = synthesize(TableSpec(["a", "b", "c", "d"], ["f"], [R], [0]), 2)
    gates = [(a // 2 - 1, b // 2 - 1, a & 1, b & 1, 0) for a, b in g.ands]
    lit = g.output_lits[0]
    return gates, [(lit // 2 - 1, lit & 1)]


def main(argv=None) -> int:
    """``gen_npn_table [CACHE_DIR [reverse]]``: per-class results are cached as JSON
    files in CACHE_DIR so that several processes (one in reverse order) can share the
    work; the table is written once every class is solved."""
    argv = sys.argv[1:] if argv is None else argv
    import os
    from pathlib import Path
    cache = Path(argv[0]) if argv else None
    if cache:
        cache.mkdir(parents=True, exist_ok=True)
    out_path = npn.TABLE_PATH
    reps = npn.classes()
    assert len(reps) == 222, len(reps)
    order = list(enumerate(reps))
    if len(argv) > 1 and argv[1] == "reverse":
        order.reverse()
    res = {}
    t0 = time.time()
    for idx, R in order:
        key = f"{R:04x}"
        if cache and (cache / key).exists():
            res[key] = json.loads((cache / key).read_text())
            continue
        if cache and (cache / (key + ".busy")).exists():
            continue
        if cache:
            (cache / (key + ".busy")).write_text(str(os.getpid()))
        t = time.time()
        res[key] = solve_class(R)
        if cache:
            (cache / key).write_text(json.dumps(res[key]))
        print(f"{idx + 1:3d}/222 {key} ands={res[key]['ands']} {time.time() - t:.1f}s",
              file=sys.stderr, flush=True)
    if len(res) < 222:
        if cache:
            for R in reps:
                key = f"{R:04x}"
                while key not in res:
                    if (cache / key).exists():
                        res[key] = json.loads((cache / key).read_text())
                    else:
                        time.sleep(2)
    data = {"format": "mlc-npn4-exact-v1",
            "description": "minimum two-input AND gates (free inversions) per NPN class of "
                           "4-input functions; gates [j, l, fj, fl, fo]: node 4+g = "
                           "((node_j ^ fj) & (node_l ^ fl)) ^ fo; nodes 0..3 are the inputs; "
                           "out [node, complement], node -1 = constant",
            "seconds": round(time.time() - t0, 1),
            "classes": res}
    _write(data)
    print(f"wrote {out_path} in {time.time() - t0:.0f}s; histogram {data['histogram']}",
          file=sys.stderr)
    return 0


def prove(seconds: float, reverse: bool = False, solver: str = SOLVER) -> int:
    """``gen_npn_table --prove SECONDS [reverse]``: for every unproven entry of the
    shipped table, try to show that one gate fewer is infeasible (or find such a
    circuit), with SECONDS per SAT call; rewrites the table after every change.
    Several provers may run at once (one with ``reverse``, largest entries first):
    each claims an entry with a lock file next to the table."""
    data = json.loads(npn.TABLE_PATH.read_text())
    keys = [k for k, v in data["classes"].items() if not v.get("proven", True)]
    keys.sort(key=lambda k: data["classes"][k]["ands"], reverse=reverse)
    for key in keys:
        lock = npn.TABLE_PATH.parent / f".prove_{key}.lock"
        try:
            lock.touch(exist_ok=False)
        except FileExistsError:
            continue
        try:
            _prove_one(key, seconds, solver)
        finally:
            lock.unlink()
    return 0


def _prove_one(key: str, seconds: float, solver: str) -> None:
    R = int(key, 16)
    while True:
        # re-read: another prover may have updated the file
        data = json.loads(npn.TABLE_PATH.read_text())
        ent = data["classes"][key]
        if ent.get("proven", True):
            return
        k = ent["ands"] - 1
        t = time.time()
        perm = _suffix_perm(R)
        if perm is not None:
            # the largest group of interchangeable inputs moved to the end: fences admit
            # the stronger first-use symmetry breaking; the circuit is mapped back
            Rp = _permuted(R, perm)
            size = max(len(g) for g in exactsat.symmetric_inputs(4, R))
            r = exactsat.synthesize_exact_fenced(4, [(Rp, 0xFFFF)], k, seconds, solver,
                                                 [list(range(4 - size, 4))])
            if r not in (None, "timeout"):
                r = _unpermute(r, perm)
        else:
            r = exactsat.synthesize_exact(4, [(R, 0xFFFF)], k, time_limit=seconds, solver=solver,
                                         symmetry=True)
        print(f"prove {key} k={k}: {'timeout' if r == 'timeout' else 'UNSAT' if r is None else 'SAT'}"
              f" {time.time() - t:.0f}s", file=sys.stderr, flush=True)
        if r == "timeout":
            return
        data = json.loads(npn.TABLE_PATH.read_text())
        if r is None:
            data["classes"][key]["proven"] = True
        else:
            data["classes"][key] = _entry(R, k, r, False)
        _write(data)


def _permuted(R: int, perm: list[int]) -> int:
    """The function g with g(x) = R(y), y[i] = x[perm[i]] (4 inputs)."""
    g = 0
    for m in range(16):
        y = sum(((m >> perm[i]) & 1) << i for i in range(4))
        g |= ((R >> y) & 1) << m
    return g


def _suffix_perm(R: int) -> list[int] | None:
    """An input permutation after which R's largest group of interchangeable inputs
    comes last, or None (no group)."""
    groups = exactsat.symmetric_inputs(4, R)
    if not groups:
        return None
    from mlc.errors import InternalError
    big = max(groups, key=len)
    order = [i for i in range(4) if i not in big] + big   # R's inputs, the group last
    perm = [order.index(i) for i in range(4)]
    if list(range(4 - len(big), 4)) not in exactsat.symmetric_inputs(4, _permuted(R, perm)):
        raise InternalError(f"gen_npn_table: moving inputs {big} last failed for {R:04x}")
    return perm


def _unpermute(circ, perm):
    """A circuit for _permuted(R, perm), rewired into one for R."""
    gates, outs = circ
    m = {q: perm.index(q) for q in range(4)}   # input q of the permuted function is fed by R's input perm^-1[q]
    gates = [((m.get(j, j)), m.get(l, l), fj, fl, fo) for j, l, fj, fl, fo in gates]
    gates = [(j, l, fj, fl, fo) if j < l or l >= 4 else (l, j, fl, fj, fo) for j, l, fj, fl, fo in gates]
    return gates, outs


def _write(data: dict) -> None:
    hist: dict[int, int] = {}
    for v in data["classes"].values():
        hist[v["ands"]] = hist.get(v["ands"], 0) + 1
    data["histogram"] = {str(k): hist[k] for k in sorted(hist)}
    data["unproven"] = sorted(k for k, v in data["classes"].items() if not v.get("proven", True))
    tmp = npn.TABLE_PATH.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=0, sort_keys=True) + "\n")
    tmp.replace(npn.TABLE_PATH)


def improve_heuristically() -> int:
    """``gen_npn_table --improve``: replace unproven entries by mlc's own synthesis
    result (which rewrites with the other entries) where that is smaller."""
    data = json.loads(npn.TABLE_PATH.read_text())
    changed = 0
    for key in list(data.get("unproven", [])):
        R = int(key, 16)
        npn.table.cache_clear()
        gates, outs = _heuristic(R)
        if len(gates) < data["classes"][key]["ands"]:
            print(f"improve {key}: {data['classes'][key]['ands']} -> {len(gates)}", file=sys.stderr)
            data["classes"][key] = _entry(R, len(gates), (gates, outs), False)
            changed += 1
            _write(data)
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--improve":
        raise SystemExit(improve_heuristically())
    if len(sys.argv) > 2 and sys.argv[1] == "--prove":
        raise SystemExit(prove(float(sys.argv[2]), len(sys.argv) > 3 and sys.argv[3] == "reverse"))
    raise SystemExit(main())
