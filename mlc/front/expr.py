"""Parser and printer for Boolean expressions (``-e EXPR`` and ``.expr`` files).

Grammar (``#`` starts a comment that runs to the end of the line)::

    program    := { statement ( ";" | NEWLINE ) } [ statement ]
    statement  := "inputs" NAME { [","] NAME }         -- optional; fixes the input order
                | "outputs" NAME { [","] NAME }        -- optional; only these names are outputs
                | "INORDER" "=" { NAME }               -- ABC / eqntott spelling of "inputs"
                | "OUTORDER" "=" { NAME }              -- ABC / eqntott spelling of "outputs"
                | NAME "=" expr                        -- defines NAME (an output unless "outputs" says otherwise)
                | expr                                 -- an unnamed output: f (or f0, f1, ... if several)
    expr       := implies { "<->" implies }            -- left associative
    implies    := or [ "->" implies ]                  -- right associative
    or         := xor { ( "|" | "+" ) xor }
    xor        := and { "^" and }
    and        := unary { ( "&" | "*" ) unary }
    unary      := ( "!" | "~" ) unary | primary
    primary    := "0" | "1" | NAME | "(" expr ")" | FUNC "(" expr { "," expr } ")"
    FUNC       := "maj" | "mux" | "ite" | "xor" | "xnor" | "and" | "or" | "nand" | "nor" | "not"
    NAME       := [A-Za-z_][A-Za-z0-9_.]* ( "[" [0-9]+ "]" )?

A line break ends a statement only outside parentheses and after a complete operand
(a name, 0, 1 or ")"), so a long expression may continue on the next line after an
operator.  In a file with an ``INORDER =`` line (ABC's ``write_eqn`` style) line
breaks never end a statement: every statement ends with ";".  ``mux(s, a, b)`` and ``ite(s, a, b)`` are ``s ? a : b``; ``maj`` takes an odd
number of arguments.  A name must be defined before it is used; a name never defined
is an input.  Function names are reserved only when followed by "(".

:func:`print_network` writes any :class:`~mlc.spec.NetworkSpec` in this syntax such
that ``print(parse(print(x))) == print(x)`` and parsing preserves the function.
"""
from __future__ import annotations

import re

from mlc.errors import Loc, MlcError
from mlc.front.load import finish_network
from mlc.spec import Node, NetworkSpec

NAME_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*(?:\[[0-9]+\])?")
TOKEN_RE = re.compile(r"""
    (?P<ws>[ \t\r\f\v]+)
  | (?P<comment>\#[^\n]*)
  | (?P<nl>\n)
  | (?P<name>[A-Za-z_][A-Za-z0-9_.]*(?:\[[0-9]+\])?)
  | (?P<num>[0-9]+)
  | (?P<op><->|->|[!~&|^(),=;*+])
  | (?P<bad>.)
""", re.VERBOSE)
FUNCS = {"maj": "maj", "mux": "mux", "ite": "mux", "xor": "xor", "xnor": "xnor", "and": "and", "or": "or",
         "nand": "nand", "nor": "nor", "not": "not"}
BINARY = {"|": "or", "+": "or", "^": "xor", "&": "and", "*": "and"}
EQN_RE = re.compile(r"^[ \t]*INORDER[ \t]*=", re.M)
MAX_DEPTH = 100          # nesting limit of the recursive-descent parser (about 8 frames a level)


class Tok:
    __slots__ = ("kind", "text", "line", "col")

    def __init__(self, kind, text, line, col):
        self.kind, self.text, self.line, self.col = kind, text, line, col

    def __repr__(self):
        return f"Tok({self.kind},{self.text!r},{self.line}:{self.col})"


def tokenize(text: str, filename: str) -> list[Tok]:
    """Split ``text`` into tokens; a newline becomes a ";" token when it can end a statement."""
    toks: list[Tok] = []
    line, line_start, depth = 1, 0, 0
    eqn = EQN_RE.search(text) is not None       # ABC/eqntott style: every statement ends in ';'
    for m in TOKEN_RE.finditer(text):
        kind = m.lastgroup
        col = m.start() - line_start + 1
        s = m.group()
        if kind in ("ws", "comment"):
            continue
        if kind == "nl":
            if not eqn and depth == 0 and toks and (toks[-1].kind in ("name", "num") or toks[-1].text == ")"):
                toks.append(Tok("op", ";", line, col))
            line, line_start = line + 1, m.end()
            continue
        if kind == "bad":
            raise MlcError(f"unexpected character {s!r}", Loc(filename, line, col),
                           "operators are ! ~ & * | + ^ -> <-> ( ) , = ;")
        if kind == "num" and s not in ("0", "1"):
            raise MlcError(f"unexpected number {s!r}", Loc(filename, line, col), "the only constants are 0 and 1")
        if s == "(":
            depth += 1
        elif s == ")":
            depth = max(0, depth - 1)
        elif s == ";":
            depth = 0
        toks.append(Tok(kind, s, line, col))
    toks.append(Tok("eof", "", line, len(text) - line_start + 1))
    return toks


class _Parser:
    def __init__(self, text: str, filename: str):
        self.filename = filename
        self.toks = tokenize(text, filename)
        self.i = 0
        self.nodes: list[Node] = []
        self.env: dict[str, int] = {}               # defined names -> node
        self.input_use: dict[str, Loc] = {}         # auto inputs -> first use
        self.declared_inputs: list[str] | None = None
        self.declared_outputs: list[tuple[str, Loc]] | None = None
        self.defined: dict[str, Loc] = {}           # assigned names -> where
        self.statements: list[tuple[str | None, int, Loc]] = []
        self.depth = 0
        self.any_assignment = False

    # ---- helpers
    def peek(self, k=0) -> Tok:
        return self.toks[min(self.i + k, len(self.toks) - 1)]

    def loc(self, t: Tok) -> Loc:
        return Loc(self.filename, t.line, t.col)

    def next(self) -> Tok:
        t = self.toks[self.i]
        self.i += 1
        return t

    def expect(self, text: str, what: str) -> Tok:
        t = self.peek()
        if t.text != text or t.kind not in ("op",):
            found = "end of input" if t.kind == "eof" else repr(t.text)
            raise MlcError(f"expected {what}, found {found}", self.loc(t))
        return self.next()

    def add(self, op, args=(), name=None, loc=None) -> int:
        self.nodes.append(Node(op, tuple(args), name, loc))
        return len(self.nodes) - 1

    # ---- program
    def program(self) -> NetworkSpec:
        while self.peek().kind != "eof":
            if self.peek().text == ";":
                self.next()
                continue
            self.statement()
            t = self.peek()
            if t.kind != "eof" and t.text != ";":
                raise MlcError(f"expected ';' or a line break, found {t.text!r}", self.loc(t),
                               "did you forget an operator?")
        return self.finish()

    def statement(self):
        t = self.peek()
        if t.kind == "name" and t.text in ("inputs", "outputs") and self.peek(1).kind == "name":
            return self.declaration()
        if t.kind == "name" and t.text in ("INORDER", "OUTORDER") and self.peek(1).text == "=":
            return self.declaration()
        if t.kind == "name" and self.peek(1).text == "=":
            self.next()
            self.next()
            name, where = t.text, self.loc(t)
            if name in self.defined:
                d = self.defined[name]
                raise MlcError(f"{name!r} is defined twice (first at line {d.line})", where)
            if name in self.input_use:
                u = self.input_use[name]
                raise MlcError(f"{name!r} is defined here but was used as an input before, at line {u.line} "
                               f"column {u.col}", where, "define names before using them")
            if self.declared_inputs is not None and name in self.declared_inputs:
                raise MlcError(f"{name!r} is declared as an input and cannot be defined", where)
            self.any_assignment = True
            k = self.expr()
            if name in self.input_use:
                raise MlcError(f"{name!r} is used in its own definition", where,
                               "a name cannot be both an input and defined")
            if self.nodes[k].name is None and self.nodes[k].op != "input":
                self.nodes[k].name = name
            self.env[name] = k
            self.defined[name] = where
            self.statements.append((name, k, where))
            return
        where = self.loc(t)
        k = self.expr()
        self.any_assignment = True
        self.statements.append((None, k, where))

    def declaration(self):
        kw = self.next()
        where = self.loc(kw)
        if kw.text in ("INORDER", "OUTORDER"):
            self.next()                                   # the '='
            kw = Tok(kw.kind, "inputs" if kw.text == "INORDER" else "outputs", kw.line, kw.col)
        if self.any_assignment:
            raise MlcError(f"'{kw.text}' must come before the first expression", where)
        names = []
        seen = {}
        while self.peek().kind == "name":
            t = self.next()
            if t.text in seen:
                raise MlcError(f"{t.text!r} is listed twice", self.loc(t))
            seen[t.text] = self.loc(t)
            names.append((t.text, self.loc(t)))
            if self.peek().text == ",":
                self.next()
                if self.peek().kind != "name":
                    raise MlcError("expected a name after ','", self.loc(self.peek()))
        if kw.text == "inputs":
            if self.declared_inputs is not None:
                raise MlcError("second 'inputs' declaration", where)
            if self.declared_outputs and any(n in seen for n, _ in self.declared_outputs):
                bad = next(n for n, _ in self.declared_outputs if n in seen)
                raise MlcError(f"{bad!r} is declared both as an input and as an output", seen[bad])
            self.declared_inputs = [n for n, _ in names]
        else:
            if self.declared_outputs is not None:
                raise MlcError("second 'outputs' declaration", where)
            if self.declared_inputs and any(n in self.declared_inputs for n, _ in names):
                bad = next(n for n, _ in names if n in self.declared_inputs)
                raise MlcError(f"{bad!r} is declared both as an input and as an output", seen[bad])
            self.declared_outputs = names

    # ---- expressions
    def expr(self) -> int:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise MlcError(f"expression nested more than {MAX_DEPTH} deep", self.loc(self.peek()),
                           "split it into named parts: t = ...; f = t & ...")
        try:
            k = self.implies()
            while self.peek().text == "<->" and self.peek().kind == "op":
                t = self.next()
                r = self.implies()
                k = self.add("iff", (k, r), loc=self.loc(t))
            return k
        finally:
            self.depth -= 1

    def implies(self) -> int:
        k = self.nary(0)
        if self.peek().text == "->" and self.peek().kind == "op":
            t = self.next()
            self.depth += 1
            if self.depth > MAX_DEPTH:
                raise MlcError(f"expression nested more than {MAX_DEPTH} deep", self.loc(t))
            try:
                r = self.implies()
            finally:
                self.depth -= 1
            k = self.add("implies", (k, r), loc=self.loc(t))
        return k

    LEVELS = (("|", "+"), ("^",), ("&", "*"))

    def nary(self, level: int) -> int:
        if level == len(self.LEVELS):
            return self.unary()
        syms = self.LEVELS[level]
        sym = syms[0]
        first = self.nary(level + 1)
        args = [first]
        loc = None
        while self.peek().text in syms and self.peek().kind == "op":
            t = self.next()
            loc = loc or self.loc(t)
            args.append(self.nary(level + 1))
        if len(args) == 1:
            return first
        return self.add(BINARY[sym], args, loc=loc)

    def unary(self) -> int:
        t = self.peek()
        if t.kind == "op" and t.text in ("!", "~"):
            self.next()
            self.depth += 1
            if self.depth > MAX_DEPTH:
                raise MlcError(f"expression nested more than {MAX_DEPTH} deep", self.loc(t))
            try:
                a = self.unary()
            finally:
                self.depth -= 1
            return self.add("not", (a,), loc=self.loc(t))
        return self.primary()

    def primary(self) -> int:
        t = self.next()
        if t.kind == "num":
            return self.add("const1" if t.text == "1" else "const0", loc=self.loc(t))
        if t.kind == "name":
            if self.peek().text == "(" and t.text in FUNCS:
                return self.call(t)
            if self.peek().text == "(":
                raise MlcError(f"unknown function {t.text!r}", self.loc(t),
                               "functions: " + ", ".join(sorted(FUNCS)))
            return self.reference(t)
        if t.text == "(":
            k = self.expr()
            self.expect(")", "')'")
            return k
        found = "end of input" if t.kind == "eof" else repr(t.text)
        raise MlcError(f"expected a name, 0, 1, '(' or '!', found {found}", self.loc(t))

    def reference(self, t: Tok) -> int:
        name = t.text
        if name in self.env:
            return self.env[name]
        if self.declared_inputs is not None and name not in self.declared_inputs:
            raise MlcError(f"{name!r} is neither a declared input nor defined before", self.loc(t),
                           "add it to the inputs declaration or define it earlier")
        if self.declared_outputs is not None and any(n == name for n, _ in self.declared_outputs):
            raise MlcError(f"output {name!r} is used before it is defined", self.loc(t),
                           "define names before using them")
        k = self.add("input", (), name, self.loc(t))
        self.env[name] = k
        self.input_use[name] = self.loc(t)
        return k

    def call(self, t: Tok) -> int:
        op = FUNCS[t.text]
        self.expect("(", "'('")
        args = [self.expr()]
        while self.peek().text == ",":
            self.next()
            args.append(self.expr())
        self.expect(")", "')' or ','")
        where = self.loc(t)
        if op == "mux" and len(args) != 3:
            raise MlcError(f"{t.text} takes 3 arguments (select, then, else), got {len(args)}", where)
        if op == "not" and len(args) != 1:
            raise MlcError(f"not takes 1 argument, got {len(args)}", where)
        if op == "maj" and len(args) % 2 == 0:
            raise MlcError(f"maj takes an odd number of arguments, got {len(args)}", where)
        return self.add(op, args, loc=where)

    # ---- result
    def finish(self) -> NetworkSpec:
        if not self.statements:
            raise MlcError("no expressions", Loc(self.filename, 1), "write NAME = EXPR, e.g. f = a & b")
        unnamed = [s for s in self.statements if s[0] is None]
        taken = set(self.env) | set(self.declared_inputs or [])
        fresh = []
        if len(unnamed) == 1 and "f" not in taken:
            fresh = ["f"]
        else:
            j = 0
            while len(fresh) < len(unnamed):
                if f"f{j}" not in taken:
                    fresh.append(f"f{j}")
                j += 1
        it = iter(fresh)
        stmts = [(name if name is not None else next(it), k, where) for name, k, where in self.statements]
        if self.declared_outputs is not None:
            defined = {name: (k, where) for name, k, where in stmts}
            outputs, output_nodes, locs = [], [], []
            for name, where in self.declared_outputs:
                if name not in defined:
                    raise MlcError(f"output {name!r} is declared but never defined", where)
                outputs.append(name)
                output_nodes.append(defined[name][0])
                locs.append(defined[name][1])
        else:
            outputs = [s[0] for s in stmts]
            output_nodes = [s[1] for s in stmts]
            locs = [s[2] for s in stmts]
        if self.declared_inputs is not None:
            inputs = list(self.declared_inputs)
        else:
            inputs = list(self.input_use)
        clash = set(inputs) & set(outputs)
        if clash:
            name = sorted(clash)[0]
            raise MlcError(f"{name!r} is both an input and an output", locs[outputs.index(name)])
        return finish_network(inputs, outputs, self.nodes, output_nodes, self.filename, locs)


def parse(text: str, filename: str = "<input>") -> NetworkSpec:
    """Parse expression statements into a :class:`NetworkSpec`."""
    parser = _Parser(text, filename)
    try:
        return parser.program()
    except RecursionError:
        raise MlcError("expression nested too deeply", Loc(filename, parser.peek().line, parser.peek().col),
                       "split it into named parts: t = ...; f = t & ...") from None


# --------------------------------------------------------------------------- printer

PREC = {"iff": 1, "implies": 2, "or": 3, "xor": 4, "and": 5, "not": 6}
SYM = {"or": "|", "xor": "^", "and": "&", "iff": "<->", "implies": "->"}
ATOM = 7
INLINE_DEPTH = 40        # deeper inlined subexpressions get a statement of their own


def _check_name(name: str, spec: NetworkSpec) -> str:
    if not NAME_RE.fullmatch(name):
        raise MlcError(f"name {name!r} cannot be written as an expression", spec.source,
                       "rename it to letters, digits, _ and .")
    return name


def print_network(spec: NetworkSpec) -> str:
    """Write ``spec`` as expression statements (with ``inputs`` and ``outputs`` declarations)."""
    nodes = spec.nodes
    refs = [0] * len(nodes)
    for nd in nodes:
        for a in nd.args:
            refs[a] += 1
    out_of: dict[int, str] = {}
    for name, k in zip(spec.outputs, spec.output_nodes):
        refs[k] += 1
        out_of.setdefault(k, name)
    used = set(spec.inputs) | set(spec.outputs)
    stmt_name: dict[int, str] = {}
    text: dict[int, tuple[str, int]] = {}       # node -> (text, precedence) of its inline form
    depth = [0] * len(nodes)
    lines = ["inputs " + ", ".join(_check_name(x, spec) for x in spec.inputs) + ";" if spec.inputs else "",
             "outputs " + ", ".join(_check_name(x, spec) for x in spec.outputs) + ";"]
    lines = [x for x in lines if x]

    def ref(a: int) -> tuple[str, int]:
        nd = nodes[a]
        if nd.op == "input":
            return nd.name, ATOM
        if a in stmt_name:
            return stmt_name[a], ATOM
        return text[a]

    def wrap(a: int, limit: int) -> str:
        s, p = ref(a)
        return f"({s})" if p <= limit else s

    for k, nd in enumerate(nodes):
        if nd.op == "input":
            continue
        op, args = nd.op, nd.args
        d = 1 + max((depth[a] for a in args if nodes[a].op != "input" and a not in stmt_name), default=0)
        if op == "const0":
            t = ("0", ATOM)
        elif op == "const1":
            t = ("1", ATOM)
        elif op == "buf":
            t = ref(args[0])
        elif op == "not":
            t = ("!" + wrap(args[0], PREC["not"] - 1), PREC["not"])
        elif op in ("and", "or", "xor") and len(args) >= 2:
            p = PREC[op]
            t = (f" {SYM[op]} ".join(wrap(a, p) for a in args), p)
        elif op in ("iff", "implies"):
            p = PREC[op]
            t = (f"{wrap(args[0], p)} {SYM[op]} {wrap(args[1], p)}", p)
        elif op == "sop":
            t = _sop_text(nd, [ref(a) for a in args])
        else:
            t = (f"{op}(" + ", ".join(ref(a)[0] for a in args) + ")", ATOM)
        text[k] = t
        depth[k] = d
        if k in out_of or refs[k] > 1 or d > INLINE_DEPTH:
            if k in out_of:
                name = out_of[k]
            else:
                name = nd.name if nd.name and NAME_RE.fullmatch(nd.name) and nd.name not in used else None
                j = k
                while name is None or name in used:
                    name = f"_t{j}"
                    j += 1
                used.add(name)
            stmt_name[k] = name
            lines.append(f"{name} = {t[0]};")
    for name, k in zip(spec.outputs, spec.output_nodes):
        if stmt_name.get(k) != name:
            lines.append(f"{name} = {ref(k)[0]};")
    return "\n".join(lines) + "\n"


def _sop_text(nd: Node, refs: list[tuple[str, int]]) -> tuple[str, int]:
    cover = nd.cover or []
    if not cover:
        return "0", ATOM
    terms = []
    for cube, _bit in cover:
        lits = []
        for ch, (s, p) in zip(cube, refs):
            if ch == "1":
                lits.append(s if p > PREC["and"] else f"({s})")
            elif ch == "0":
                lits.append("!" + (s if p >= ATOM else f"({s})"))
        if not lits:
            terms = None
            break
        terms.append((" & ".join(lits), PREC["and"] if len(lits) > 1 else ATOM if not lits[0].startswith("!") else PREC["not"]))
    if terms is None:
        body = ("1", ATOM)
    elif len(terms) == 1:
        body = terms[0]
    else:
        body = (" | ".join(s if p > PREC["or"] else f"({s})" for s, p in terms), PREC["or"])
    if cover[0][1] == "0":
        s, p = body
        return "!" + (s if p >= ATOM else f"({s})"), PREC["not"]
    return body
