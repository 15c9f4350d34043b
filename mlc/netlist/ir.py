"""The gate netlist IR: library gates, lever types, connector branches and half units.

A :class:`Netlist` is what technology mapping (:mod:`mlc.netlist.mapper`) produces and
what the back end turns into mechanisms.  It is stored as JSON (schema
``mlc/schemas/netlist.schema.json``, documented in docs/netlist-format.md) and has a
stable text form for golden tests, DOT and PNG drawings, and BLIF / AIGER exports.

Signals.  Every wire carries a *physical* signal in the netlist's convention
(``signal``: expand or contract): a primary input wire is a muscle; a gate's output
wire is the gate's output lever.  A gate computes ``(a^pa AND b^pb)^pout`` of the
physical signals on its input wires: the inversions ``pa``, ``pb``, ``pout`` are its
levers' (free) inversions, and its library type is the one with that polarity.

References.  A gate input or an output names its source as ``("input", name)`` or
``("gate", id)``; gate ids are ``g1, g2, ...`` in topological order.

Invariants (checked by :meth:`Netlist.check`):

1. ``signal`` is expand or contract; input, output and gate names are unique; gate
   ids are ``g1 .. gN`` in order;
2. every gate input refers to a primary input or to an earlier gate (acyclic);
3. every gate's type is the library gate with polarity ``(pa, pb, pout)`` and its
   lever types are ``lever_types(pa, pb, pout, signal)``;
4. each pin's ``invert`` is the AIG edge's complement XOR the source gate's ``pout``
   (primary inputs have ``pout = 0``): the inversion an AIG edge asks for is either in
   the source's output lever or in this input lever;
5. every gate's depth is one more than its deepest source (inputs have depth 0);
6. each wire's ``fanout`` is the number of gate inputs and outputs it feeds, and its
   ``branches`` is ``fanout`` when that exceeds 1, else 0;
7. an output is a constant (with a value and no source), a plain input or a gate; it
   has a connector half unit exactly when its AIG edge's complement differs from the
   source's ``pout``;
8. every gate drives something (no dangling gates);
9. ``stats`` equals what the gates, wires and outputs add up to.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field

from mlc.errors import InternalError, Loc, MlcError

FORMAT_VERSION = 1
SIGNALS = ("expand", "contract")


@dataclass
class Pin:
    """One input of a gate: its source, the AIG edge's complement, and the lever."""

    src: tuple[str, str]        # ("input", name) or ("gate", id)
    edge_invert: int            # complement bit of the AIG edge
    invert: int                 # this input lever inverts (pa / pb)
    lever: str = ""             # "open" or "crossed"


@dataclass
class Gate:
    id: str
    type: str
    a: Pin
    b: Pin
    out_invert: int             # pout: the output lever inverts
    out_lever: str = ""
    depth: int = 0
    fanout: int = 0
    branches: int = 0
    aig_node: int | None = None

    @property
    def polarity(self) -> tuple[int, int, int]:
        return (self.a.invert, self.b.invert, self.out_invert)


@dataclass
class Input:
    name: str
    fanout: int = 0
    branches: int = 0


@dataclass
class Output:
    name: str
    kind: str                   # "const", "input" or "gate"
    src: tuple[str, str] | None = None
    value: int | None = None    # for kind == "const"
    edge_invert: int = 0        # complement bit of the AIG output literal
    half_unit: bool = False     # an inverting connector half unit on the way to the output


@dataclass
class Netlist:
    inputs: list[Input]
    outputs: list[Output]
    gates: list[Gate]
    signal: str = "expand"
    source: str = "<input>"
    stats: dict = field(default_factory=dict)

    # ------------------------------------------------------------ derived data
    def gate_by_id(self) -> dict[str, Gate]:
        return {g.id: g for g in self.gates}

    def src_depth(self, src, by_id=None) -> int:
        if src[0] == "input":
            return 0
        return (by_id or self.gate_by_id())[src[1]].depth

    def src_pout(self, src, by_id=None) -> int:
        if src[0] == "input":
            return 0
        return (by_id or self.gate_by_id())[src[1]].out_invert

    def compute_stats(self) -> dict:
        by_id = self.gate_by_id()
        levers = {"open": 0, "crossed": 0}
        by_type: dict[str, int] = {}
        for g in self.gates:
            for lev in (g.a.lever, g.b.lever, g.out_lever):
                levers[lev] = levers.get(lev, 0) + 1
            by_type[g.type] = by_type.get(g.type, 0) + 1
        depth = max((self.src_depth(o.src, by_id) for o in self.outputs if o.src), default=0)
        return {
            "gates": len(self.gates),
            "depth": depth,
            "branches": sum(w.branches for w in self.inputs) + sum(g.branches for g in self.gates),
            "half_units": sum(1 for o in self.outputs if o.half_unit),
            "levers": levers,
            "gate_types": dict(sorted(by_type.items())),
            "const_outputs": sum(1 for o in self.outputs if o.kind == "const"),
            "input_outputs": sum(1 for o in self.outputs if o.kind == "input"),
        }

    def fanouts(self) -> dict[tuple[str, str], int]:
        count: dict[tuple[str, str], int] = {("input", w.name): 0 for w in self.inputs}
        for g in self.gates:
            count[("gate", g.id)] = 0
        for g in self.gates:
            for p in (g.a, g.b):
                count[p.src] = count.get(p.src, 0) + 1
        for o in self.outputs:
            if o.src is not None:
                count[o.src] = count.get(o.src, 0) + 1
        return count

    # ------------------------------------------------------------ invariants
    def check(self) -> None:
        """Raise InternalError unless every invariant of the module docstring holds."""
        from mlc.gates.library import lever_types, load_library

        def bad(msg):
            raise InternalError(f"malformed netlist: {msg}")

        if self.signal not in SIGNALS:
            bad(f"signal {self.signal!r}")
        names = [w.name for w in self.inputs]
        if len(set(names)) != len(names):
            bad("duplicate input names")
        onames = [o.name for o in self.outputs]
        if len(set(onames)) != len(onames):
            bad("duplicate output names")
        by_pol = {tuple(d.polarity[k] for k in ("a", "b", "out")): name for name, d in load_library().items()}
        known = {("input", x) for x in names}
        depth: dict[tuple[str, str], int] = {("input", x): 0 for x in names}
        pout: dict[tuple[str, str], int] = {("input", x): 0 for x in names}
        for k, g in enumerate(self.gates, 1):
            if g.id != f"g{k}":
                bad(f"gate {k} has id {g.id!r}, expected g{k}")
            for pin_name, p in (("a", g.a), ("b", g.b)):
                if p.src not in known:
                    bad(f"{g.id}.{pin_name} refers to {p.src}, which is not an input or an earlier gate")
                if p.invert != p.edge_invert ^ pout[p.src]:
                    bad(f"{g.id}.{pin_name}: invert {p.invert} != edge {p.edge_invert} ^ source pout {pout[p.src]}")
            want_type = by_pol.get(g.polarity)
            if g.type != want_type:
                bad(f"{g.id} has type {g.type} but polarity {g.polarity} is {want_type}")
            lev = lever_types(g.a.invert, g.b.invert, g.out_invert, self.signal)
            if (g.a.lever, g.b.lever, g.out_lever) != (lev["a"], lev["b"], lev["out"]):
                bad(f"{g.id} lever types {(g.a.lever, g.b.lever, g.out_lever)} should be {lev}")
            d = 1 + max(depth[g.a.src], depth[g.b.src])
            if g.depth != d:
                bad(f"{g.id} depth {g.depth}, expected {d}")
            known.add(("gate", g.id))
            depth[("gate", g.id)] = d
            pout[("gate", g.id)] = g.out_invert
        for o in self.outputs:
            if o.kind == "const":
                if o.src is not None or o.value not in (0, 1) or o.half_unit:
                    bad(f"constant output {o.name} malformed")
                continue
            if o.kind not in ("input", "gate") or o.src is None or o.src[0] != o.kind:
                bad(f"output {o.name}: kind {o.kind} with source {o.src}")
            if o.src not in known:
                bad(f"output {o.name} refers to unknown {o.src}")
            if o.half_unit != bool(o.edge_invert ^ pout[o.src]):
                bad(f"output {o.name}: half_unit {o.half_unit} but edge {o.edge_invert} and pout {pout[o.src]}")
        fo = self.fanouts()
        for w in self.inputs:
            if w.fanout != fo[("input", w.name)] or w.branches != (w.fanout if w.fanout > 1 else 0):
                bad(f"input {w.name}: fanout {w.fanout}/branches {w.branches}, counted {fo[('input', w.name)]}")
        for g in self.gates:
            if g.fanout != fo[("gate", g.id)] or g.branches != (g.fanout if g.fanout > 1 else 0):
                bad(f"{g.id}: fanout {g.fanout}/branches {g.branches}, counted {fo[('gate', g.id)]}")
            if g.fanout == 0:
                bad(f"{g.id} drives nothing")
        if self.stats != self.compute_stats():
            bad(f"stats {self.stats} != recomputed {self.compute_stats()}")

    # ------------------------------------------------------------ simulation / AIG
    def to_aig(self):
        """The netlist as an :class:`mlc.logic.aig.AIG` (for the equivalence proof)."""
        from mlc.logic.aig import AIG
        g = AIG([w.name for w in self.inputs])
        lit: dict[tuple[str, str], int] = {("input", w.name): g.input_lit(i) for i, w in enumerate(self.inputs)}
        for gate in self.gates:
            x = g.and_(lit[gate.a.src] ^ gate.a.invert, lit[gate.b.src] ^ gate.b.invert)
            lit[("gate", gate.id)] = x ^ gate.out_invert
        for o in self.outputs:
            if o.kind == "const":
                g.add_output(o.name, o.value)
            else:
                g.add_output(o.name, lit[o.src] ^ int(o.half_unit))
        return g

    # ------------------------------------------------------------ JSON
    def to_json(self) -> dict:
        def ref(src):
            return {src[0]: src[1]}

        def pin(p: Pin):
            return {"from": ref(p.src), "edge_invert": p.edge_invert, "invert": p.invert, "lever": p.lever}

        outs = []
        for o in self.outputs:
            d = {"name": o.name, "kind": o.kind}
            if o.kind == "const":
                d["value"] = o.value
            else:
                d.update({"from": ref(o.src), "edge_invert": o.edge_invert, "half_unit": o.half_unit})
            outs.append(d)
        return {
            "mlc_netlist": FORMAT_VERSION,
            "source": self.source,
            "signal": self.signal,
            "inputs": [{"name": w.name, "fanout": w.fanout, "branches": w.branches} for w in self.inputs],
            "gates": [{"id": g.id, "type": g.type, "depth": g.depth, "a": pin(g.a), "b": pin(g.b),
                       "out": {"invert": g.out_invert, "lever": g.out_lever, "fanout": g.fanout,
                               "branches": g.branches}}
                      for g in self.gates],
            "outputs": outs,
            "stats": self.stats,
        }

    def dumps(self) -> str:
        """JSON text with one input, gate or output per line (fast, and diffs well)."""
        data = self.to_json()
        parts = []
        for key, value in data.items():
            if isinstance(value, list) and value:
                items = ",\n".join("  " + json.dumps(v, separators=(", ", ": ")) for v in value)
                parts.append(f" {json.dumps(key)}: [\n{items}\n ]")
            else:
                parts.append(f" {json.dumps(key)}: {json.dumps(value, separators=(', ', ': '))}")
        return "{\n" + ",\n".join(parts) + "\n}\n"

    @classmethod
    def from_json(cls, data: dict, filename: str = "<input>") -> "Netlist":
        """Build a netlist from JSON data validated against the schema, then check it."""
        from mlc.io.schema import load_schema, validate
        validate(data, load_schema("netlist"), filename)

        def src(d):
            (k, v), = d.items()
            return (k, v)

        def pin(d):
            return Pin(src(d["from"]), d["edge_invert"], d["invert"], d["lever"])

        gates = [Gate(g["id"], g["type"], pin(g["a"]), pin(g["b"]), g["out"]["invert"], g["out"]["lever"],
                      g["depth"], g["out"]["fanout"], g["out"]["branches"]) for g in data["gates"]]
        outs = []
        for o in data["outputs"]:
            if o["kind"] == "const":
                outs.append(Output(o["name"], "const", None, o.get("value")))
            else:
                outs.append(Output(o["name"], o["kind"], src(o["from"]), None, o.get("edge_invert", 0),
                                   o.get("half_unit", False)))
        nl = cls([Input(w["name"], w["fanout"], w["branches"]) for w in data["inputs"]], outs, gates,
                 data["signal"], data.get("source", filename), dict(data["stats"]))
        try:
            nl.check()
        except InternalError as e:
            raise MlcError(f"inconsistent netlist: {e}", Loc(filename)) from None
        return nl

    @classmethod
    def loads(cls, text: str, filename: str = "<input>") -> "Netlist":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise MlcError(f"not valid JSON: {e.msg}", Loc(filename, e.lineno, e.colno)) from None
        return cls.from_json(data, filename)

    # ------------------------------------------------------------ text / DOT
    def to_text(self) -> str:
        """Stable human-readable form (golden tests)."""
        s = self.stats
        lines = [f"netlist signal={self.signal} inputs={len(self.inputs)} outputs={len(self.outputs)} "
                 f"gates={s['gates']} depth={s['depth']} branches={s['branches']} half_units={s['half_units']} "
                 f"levers=open:{s['levers'].get('open', 0)},crossed:{s['levers'].get('crossed', 0)}"]

        def r(src):
            return src[1] if src[0] == "gate" else f"${src[1]}"

        for w in self.inputs:
            lines.append(f"input ${w.name} fanout={w.fanout}")
        for g in self.gates:
            def pin(p):
                return f"{'!' if p.invert else ''}{r(p.src)}:{p.lever}"
            lines.append(f"{g.id} = {g.type}({pin(g.a)}, {pin(g.b)}) out:{g.out_lever}"
                         f"{' inverting' if g.out_invert else ''} depth={g.depth} fanout={g.fanout}")
        for o in self.outputs:
            if o.kind == "const":
                lines.append(f"output {o.name} = const {o.value}")
            else:
                hu = " via half unit (inverting)" if o.half_unit else ""
                lines.append(f"output {o.name} = {o.kind} {r(o.src)}{hu}")
        return "\n".join(lines) + "\n"

    def to_dot(self) -> str:
        def q(s):
            return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'

        def nid(src):
            return q(("in:" if src[0] == "input" else "") + src[1])

        lines = ["digraph netlist {", "  rankdir=LR;", "  node [fontname=Helvetica];",
                 f"  label={q(f'{self.source} ({self.signal}ing signals)')};"]
        for w in self.inputs:
            lines.append(f"  {nid(('input', w.name))} [shape=circle, label={q(w.name)}];")
        for g in self.gates:
            inv = "inverting" if g.out_invert else "plain"
            lines.append(f"  {q(g.id)} [shape=box, label={q(f'{g.id}: {g.type}')}, tooltip={q(f'out lever {g.out_lever}, {inv}')}];")
            for pname, p in (("a", g.a), ("b", g.b)):
                lab = f"{pname}: {p.lever}{' (inv)' if p.invert else ''}"
                lines.append(f"  {nid(p.src)} -> {q(g.id)} [label={q(lab)}];")
        for o in self.outputs:
            oid = q("out:" + o.name)
            lines.append(f"  {oid} [shape=doublecircle, label={q(o.name)}];")
            if o.kind == "const":
                cid = q(f"const:{o.name}")
                lines.append(f"  {cid} [shape=plaintext, label={q(str(o.value))}];")
                lines.append(f"  {cid} -> {oid};")
            else:
                lab = ' [label="half unit (inv)", style=dashed]' if o.half_unit else ""
                lines.append(f"  {nid(o.src)} -> {oid}{lab};")
        lines.append("}")
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------ BLIF / AIGER
    def _signal_names(self) -> dict:
        used = {w.name for w in self.inputs} | {o.name for o in self.outputs}
        names = {("input", w.name): w.name for w in self.inputs}
        for g in self.gates:
            base = g.id
            name = base
            while name in used:
                name = "_" + name
            used.add(name)
            names[("gate", g.id)] = name
        return names

    def to_blif(self, model: str = "mlc_netlist") -> str:
        """BLIF with one ``.names`` per gate (the physical signal of its output lever)."""
        names = self._signal_names()
        lines = [f"# mlc gate netlist of {self.source}: one .names per library gate",
                 f".model {model}", ".inputs " + " ".join(w.name for w in self.inputs),
                 ".outputs " + " ".join(o.name for o in self.outputs)]
        for g in self.gates:
            a, b = names[g.a.src], names[g.b.src]
            lines.append(f"# {g.id} {g.type}")
            lines.append(f".names {a} {b} {names[('gate', g.id)]}")
            row = f"{1 - g.a.invert}{1 - g.b.invert}"
            lines.append(f"{row} {0 if g.out_invert else 1}")
        for o in self.outputs:
            if o.kind == "const":
                lines.append(f".names {o.name}")
                if o.value:
                    lines.append("1")
                continue
            src = names[o.src]
            if src == o.name and not o.half_unit:
                continue
            lines.append(f".names {src} {o.name}")
            lines.append("0 1" if o.half_unit else "1 1")
        lines.append(".end")
        return "\n".join(lines) + "\n"

    def to_aiger(self) -> str:
        """ASCII AIGER: one AND per gate; lever inversions become complemented edges."""
        n = len(self.inputs)
        lit = {("input", w.name): 2 * (i + 1) for i, w in enumerate(self.inputs)}
        ands = []
        for k, g in enumerate(self.gates):
            v = 2 * (n + 1 + k)
            r0 = lit[g.a.src] ^ g.a.invert
            r1 = lit[g.b.src] ^ g.b.invert
            ands.append((v, max(r0, r1), min(r0, r1)))
            lit[("gate", g.id)] = v ^ g.out_invert
        outs = []
        for o in self.outputs:
            outs.append(o.value if o.kind == "const" else lit[o.src] ^ int(o.half_unit))
        lines = [f"aag {n + len(ands)} {n} 0 {len(outs)} {len(ands)}"]
        lines += [str(2 * (i + 1)) for i in range(n)]
        lines += [str(x) for x in outs]
        lines += [f"{v} {a} {b}" for v, a, b in ands]
        lines += [f"i{i} {w.name}" for i, w in enumerate(self.inputs)]
        lines += [f"o{i} {o.name}" for i, o in enumerate(self.outputs)]
        lines += ["c", f"mlc gate netlist of {self.source}"]
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------ drawing
    def draw(self, path) -> None:
        """Draw the circuit to a PNG file (atomically)."""
        from mlc.io.atomic import write_bytes
        write_bytes(path, self.render_png())

    DRAW_LABEL_LIMIT = 150      # above this many gates the drawing omits per-gate labels

    def render_png(self) -> bytes:
        """The circuit drawing as PNG bytes: inputs left, gates by depth, outputs right.

        Lever markers: o open hinge, x crossed hinge; a dashed output edge with a
        diamond is a connector half unit."""
        import io

        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.collections import LineCollection, PatchCollection
        from matplotlib.patches import Rectangle

        depth_max = self.stats.get("depth", 0)
        pos: dict = {}
        for i, w in enumerate(self.inputs):
            pos[("input", w.name)] = (0.0, -1.2 * i)
        layers: dict[int, list[Gate]] = {}
        for g in self.gates:
            layers.setdefault(g.depth, []).append(g)
        for d in sorted(layers):
            gs = layers[d]
            bary = {g.id: (pos[g.a.src][1] + pos[g.b.src][1]) / 2 for g in gs}
            gs.sort(key=lambda g: -bary[g.id])
            ys = [bary[g.id] for g in gs]
            for j in range(1, len(ys)):              # at least 1.2 apart, order kept
                ys[j] = min(ys[j], ys[j - 1] - 1.2)
            for g, y in zip(gs, ys):
                pos[("gate", g.id)] = (2.0 * d, y)
        ys_all = [p[1] for p in pos.values()] or [0.0]
        lo, hi = min(ys_all), max(ys_all)
        n_out = max(len(self.outputs), 1)
        span = max(hi - lo, 1.2 * (n_out - 1))
        out_y = [hi - span * (i / max(n_out - 1, 1)) for i in range(len(self.outputs))]
        x_out = 2.0 * (depth_max + 1)
        labels = len(self.gates) <= self.DRAW_LABEL_LIMIT
        fig_w = min(30.0, max(4.0, 1.8 * (depth_max + 2) + 1.5))
        fig_h = min(30.0, max(2.5, 0.5 * (span + 1.2) + 1.2))
        fig, ax = plt.subplots(figsize=(fig_w, fig_h))
        ax.set_axis_off()
        segs, dashed, marks = [], [], {"open": [], "crossed": []}
        boxes = []
        for g in self.gates:
            x, y = pos[("gate", g.id)]
            for p, dy in ((g.a, 0.22), (g.b, -0.22)):
                sx, sy = pos[p.src]
                segs.append([(sx + (0.45 if p.src[0] == "gate" else 0.15), sy), (x - 0.45, y + dy)])
                marks[p.lever].append((x - 0.45, y + dy))
            marks[g.out_lever].append((x + 0.45, y))
            boxes.append(Rectangle((x - 0.45, y - 0.35), 0.9, 0.7))
        half = []
        for o, y in zip(self.outputs, out_y):
            if o.kind == "const":
                continue
            sx, sy = pos[o.src]
            seg = [(sx + (0.45 if o.src[0] == "gate" else 0.15), sy), (x_out - 0.15, y)]
            (dashed if o.half_unit else segs).append(seg)
            if o.half_unit:
                half.append((x_out - 0.5, y + (sy - y) * 0.5 / max(x_out - sx, 0.5)))
        ax.add_collection(LineCollection(segs, colors="0.45", linewidths=0.8, zorder=1))
        if dashed:
            ax.add_collection(LineCollection(dashed, colors="#2ca02c", linewidths=0.8, linestyles="--", zorder=1))
        ax.add_collection(PatchCollection(boxes, facecolor="#fff7d6", edgecolor="k", linewidth=0.8, zorder=2))
        for kind, style, color in (("open", "o", "#1f77b4"), ("crossed", "x", "#d62728")):
            if marks[kind]:
                xs, ys = zip(*marks[kind])
                ax.scatter(xs, ys, marker=style, c=color, s=18, zorder=3, linewidths=1)
        if half:
            xs, ys = zip(*half)
            ax.scatter(xs, ys, marker="D", c="#2ca02c", s=20, zorder=3)
        if labels:
            for g in self.gates:
                x, y = pos[("gate", g.id)]
                ax.text(x, y, f"{g.type}\n{g.id}", ha="center", va="center", fontsize=6, zorder=4)
        colors = ("#ffd54f", "#90caf9")          # the paper's yellow and blue muscles
        if self.inputs:
            xs, ys = zip(*(pos[("input", w.name)] for w in self.inputs))
            ax.scatter(xs, ys, s=160, c=[colors[i % 2] for i in range(len(xs))], edgecolors="k", zorder=2)
        for w in self.inputs:
            x, y = pos[("input", w.name)]
            ax.text(x - 0.3, y, w.name, ha="right", va="center", fontsize=8)
        if self.outputs:
            ax.scatter([x_out] * len(out_y), out_y, marker="s", s=60, facecolors="white", edgecolors="k", zorder=2)
        for o, y in zip(self.outputs, out_y):
            ax.text(x_out + 0.3, y, o.name, ha="left", va="center", fontsize=8)
            if o.kind == "const":
                ax.text(x_out - 0.5, y, str(o.value), ha="center", va="center", fontsize=8, color="0.3")
        s = self.stats
        ax.set_title(f"{self.source}: {s['gates']} gates, depth {s['depth']}, {s['branches']} branches, "
                     f"{s['half_units']} half units ({self.signal}ing muscles)\n"
                     "lever: o open, x crossed; dashed + diamond: connector half unit", fontsize=8)
        ax.set_xlim(-1.5, x_out + 2.0)
        ax.set_ylim(min(lo, hi - span) - 1.0, hi + 1.0)
        fig.tight_layout()
        buf = io.BytesIO()
        try:
            fig.savefig(buf, dpi=100 if len(self.gates) > self.DRAW_LABEL_LIMIT else 120, format="png",
                        metadata={"Software": "mlc"})
        finally:
            plt.close(fig)
        return buf.getvalue()
