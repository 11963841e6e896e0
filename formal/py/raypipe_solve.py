"""raypipe's SMT solver driver: one SMT-LIB 2 script, one solver, incremental checks.

Solvers: bitwuzla (PyPI `bitwuzla`; its wheel supports the FloatingPoint sorts of binary16,
binary32, binary64 and binary128 only), cvc5 (PyPI `cvc5`; every sort) and z3 (PyPI
`z3-solver`; every sort). `pick(width_pairs)` chooses bitwuzla when it can, else cvc5.

Run as a program (by `raypipe prove` and `raypipe equiv`): reads a JSON request on stdin,
`{"solver": name|"auto", "script": text, "timeout_s": number, "values": [names]}`, checks the
script's assertions once and prints `{"result": "sat"|"unsat"|"unknown", "solver": ...,
"version": ..., "seconds": ..., "values": {name: int}}` (values only when sat)."""

import json
import re
import sys
import time

STANDARD = {(5, 11), (8, 24), (11, 53), (15, 113)}


def fp_sorts(script):
    return {(int(e), int(s)) for e, s in re.findall(r"\(_ FloatingPoint (\d+) (\d+)\)", script)}


def pick(script):
    """bitwuzla when every FloatingPoint sort of the script is standard, else cvc5."""
    try:
        import bitwuzla  # noqa: F401
        if fp_sorts(script) <= STANDARD:
            return "bitwuzla"
    except ImportError:
        pass
    try:
        import cvc5  # noqa: F401
        return "cvc5"
    except ImportError:
        return "z3"


class Session:
    """An SMT-LIB 2 script loaded into a solver: assert more, check, read values."""

    def __init__(self, script, solver="auto", timeout_s=0):
        self.name = pick(script) if solver == "auto" else solver
        self.timeout_ms = int(timeout_s * 1000)
        getattr(self, "_init_" + self.name)(script)

    # bitwuzla
    def _init_bitwuzla(self, script):
        import bitwuzla as bz
        self.bz = bz
        self.version = bz.version()
        tm = bz.TermManager()
        o = bz.Options()
        o.set(bz.Option.PRODUCE_MODELS, True)
        if self.timeout_ms:
            o.set(bz.Option.TIME_LIMIT_PER, self.timeout_ms)
        self.p = bz.Parser(tm, o)
        self.p.parse(script, True, False)
        self.s = self.p.bitwuzla()

    # cvc5
    def _init_cvc5(self, script):
        import cvc5
        self.cvc5 = cvc5
        self.version = cvc5.__version__
        self.tm = cvc5.TermManager()
        self.s = cvc5.Solver(self.tm)
        self.s.setOption("produce-models", "true")
        self.s.setOption("incremental", "true")
        # cvc5 supports Float32 and Float64 only unless its SymFPU-based solver for every
        # FloatingPoint sort is enabled (--fp-exp)
        self.s.setOption("fp-exp", "true")
        if self.timeout_ms:
            self.s.setOption("tlimit-per", str(self.timeout_ms))
        self.sm = cvc5.SymbolManager(self.tm)
        self.p = cvc5.InputParser(self.s, self.sm)
        self.p.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, script, "model")
        while True:
            cmd = self.p.nextCommand()
            if cmd.isNull():
                break
            err = cmd.invoke(self.s, self.sm)
            if err.startswith("(error"):
                raise RuntimeError(f"cvc5: {err.strip()}")
        self.p.setIncrementalStringInput(cvc5.InputLanguage.SMT_LIB_2_6, "terms")

    # z3
    def _init_z3(self, script):
        import z3
        self.z3 = z3
        self.version = z3.get_version_string()
        self.s = z3.Solver()
        if self.timeout_ms:
            self.s.set("timeout", self.timeout_ms)
        self.script = script
        self.s.from_string(script)

    def term(self, text):
        if self.name == "bitwuzla":
            return self.p.parse_term(text)
        if self.name == "cvc5":
            self.p.appendIncrementalStringInput(text + " ")
            return self.p.nextTerm()
        raise NotImplementedError("z3 terms are asserted as text")

    def assert_text(self, formula):
        if self.name == "z3":
            self.s.from_string(self._z3_decls() + f"(assert {formula})")
        elif self.name == "bitwuzla":
            self.s.assert_formula(self.term(formula))
        else:
            self.s.assertFormula(self.term(formula))

    def _z3_decls(self):
        # z3's from_string needs the declarations again to parse a later assertion
        return "\n".join(line for line in self.script.splitlines()
                         if line.startswith(("(declare-const", "(define-fun", "(define-sort", "(declare-fun")))

    def push(self):
        self.s.push() if self.name == "z3" else self.s.push(1)

    def pop(self):
        self.s.pop() if self.name == "z3" else self.s.pop(1)

    def check(self):
        if self.name == "bitwuzla":
            r = self.s.check_sat()
            return {self.bz.Result.SAT: "sat", self.bz.Result.UNSAT: "unsat"}.get(r, "unknown")
        if self.name == "cvc5":
            r = self.s.checkSat()
            return "sat" if r.isSat() else "unsat" if r.isUnsat() else "unknown"
        r = self.s.check()
        return {self.z3.sat: "sat", self.z3.unsat: "unsat"}.get(r, "unknown")

    def value(self, name):
        """The current model's value of a bit-vector or Boolean term, as an int."""
        if self.name == "bitwuzla":
            t = self.term(name)
            v = self.s.get_value(t)
            return int(v.value(10)) if t.sort().is_bv() else int(v.value())
        if self.name == "cvc5":
            t = self.term(name)
            v = self.s.getValue(t)
            return int(v.getBitVectorValue(10)) if t.getSort().isBitVector() else int(v.getBooleanValue())
        m = self.s.model()
        v = m.eval(self.z3.parse_smt2_string(self._z3_decls() + f"(assert (= {name} {name}))")[0].arg(0),
                   model_completion=True)
        return int(v.as_long()) if self.z3.is_bv(v) else int(self.z3.is_true(v))


def main():
    req = json.load(sys.stdin)
    t0 = time.time()
    s = Session(req["script"], req.get("solver", "auto"), req.get("timeout_s", 0))
    r = s.check()
    out = {"result": r, "solver": s.name, "version": s.version, "seconds": round(time.time() - t0, 3)}
    if r == "sat":
        out["values"] = {n: s.value(n) for n in req.get("values", [])}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
