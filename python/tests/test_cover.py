"""`raypipe cover --ucis FILE`: the coverage as UCIS 1.0 XML that pyucis reads back with the
same totals as raypipe's own JSON (reachable bins, bins hit, unreachable bins as ignore bins),
also for several sets merged."""

import json
import os
import shutil
import subprocess

import pytest

import ucis  # noqa: F401  (pyucis: a missing package fails the tests, never skips them)
from ucis.cover_type_t import CoverTypeT  # noqa: E402
from ucis.scope_type_t import ScopeTypeT  # noqa: E402
from ucis.xml.xml_factory import XmlFactory  # noqa: E402


def exe():
    e = os.environ.get("RAYPIPE") or shutil.which("raypipe")
    if e is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    return e


def ucis_totals(path):
    """(bins hit, bins, ignore bins, coverpoints) as pyucis reads the file."""
    db = XmlFactory.read(str(path))
    hit = total = ignored = points = 0
    for inst in db.scopes(ScopeTypeT.INSTANCE):
        for cg in inst.scopes(ScopeTypeT.COVERGROUP):
            for cgi in cg.scopes(ScopeTypeT.COVERINSTANCE):
                for cp in cgi.scopes(ScopeTypeT.COVERPOINT):
                    points += 1
                    for ci in cp.coverItems(CoverTypeT.CVGBIN):
                        total += 1
                        hit += ci.getCoverData().data > 0
                    for ci in cp.coverItems(CoverTypeT.IGNOREBIN):
                        ignored += 1
    return hit, total, ignored, points


@pytest.mark.parametrize("unit,fmt,opts", [
    ("rti", "fp16", []),
    ("slab", "f32:ftz", ["--variant", "plain"]),
    ("op", "bf16", []),
])
def test_pyucis_reads_the_totals_raypipe_reports(unit, fmt, opts, tmp_path):
    e = exe()
    sets = []
    for seed in ("1", "2"):
        d = tmp_path / f"set{seed}"
        subprocess.run([e, "vectors", "--unit", unit, "--format", fmt, *opts, "--count", "2", "--seed", seed,
                        "--out", str(d)], check=True, capture_output=True)
        sets.append(str(d))
    for chosen in (sets[:1], sets):
        xml = tmp_path / f"cov{len(chosen)}.xml"
        p = subprocess.run([e, "cover", *chosen, "--ucis", str(xml), "--json"], check=True, capture_output=True,
                           text=True)
        j = json.loads(p.stdout)
        hit, total, ignored, points = ucis_totals(xml)
        assert (hit, total, ignored) == (j["bins_hit"], j["bins"], j["bins_unreachable"]), (unit, fmt, chosen)
        assert points == len(j["coverpoints"])
        assert 0 < hit <= total


def ucis_instances(path):
    """{instance name: (bins hit, bins, ignore bins)} as pyucis reads the file."""
    db = XmlFactory.read(str(path))
    out = {}
    for inst in db.scopes(ScopeTypeT.INSTANCE):
        hit = total = ignored = 0
        for cg in inst.scopes(ScopeTypeT.COVERGROUP):
            for cgi in cg.scopes(ScopeTypeT.COVERINSTANCE):
                for cp in cgi.scopes(ScopeTypeT.COVERPOINT):
                    for ci in cp.coverItems(CoverTypeT.CVGBIN):
                        total += 1
                        hit += ci.getCoverData().data > 0
                    for ci in cp.coverItems(CoverTypeT.IGNOREBIN):
                        ignored += 1
        out[inst.getScopeName()] = (hit, total, ignored)
    return out


def test_pyucis_reads_every_model_of_a_verify_run(tmp_path):
    """`verify --cover` measures one model per unit, format and slab variant; `cover --ucis`
    writes one UCIS instance per model, and pyucis reads each with raypipe's totals."""
    e = exe()
    f = tmp_path / "verify.json"
    subprocess.run([e, "verify", "--rays", "16", "--format", "fp16,q8.24", "--quiet", "--cover", str(f)],
                   check=True, capture_output=True)
    xml = tmp_path / "cov.xml"
    p = subprocess.run([e, "cover", str(f), "--ucis", str(xml), "--json"], check=True, capture_output=True,
                       text=True)
    j = json.loads(p.stdout)
    models = j["models"]
    assert len(models) >= 4 and {m["unit"] for m in models} == {"rti", "slab"}
    got = ucis_instances(xml)
    assert len(got) == len(models)
    for m in models:
        name = "raypipe_%s_%s" % (m["unit"], m["format"].replace(".", "_").replace(":", "_"))
        if m["variant"]:
            name += "_" + m["variant"].replace("-", "_")
        assert got[name] == (m["bins_hit"], m["bins"], m["bins_unreachable"]), name
        assert 0 < m["bins_hit"] <= m["bins"]


def _fp16(bits):
    """An fp16 encoding's exact value (a Fraction), ('inf', sign), or None for a NaN."""
    from fractions import Fraction as F
    bits = int(bits)
    sgn = -1 if bits >> 15 else 1
    e, f = (bits >> 10) & 31, bits & 1023
    if e == 31:
        return None if f else ("inf", sgn)
    if e == 0:
        return sgn * F(f, 2 ** 24)
    return sgn * F(1024 + f) * F(2) ** (e - 25)


def test_rounding_events_match_exact_rational_arithmetic(tmp_path):
    """The rounding events `raypipe cover` counts for a subtract and a multiply of the fp16 RTI
    set equal an independent classification in exact rational arithmetic (fractions)."""
    import bisect
    from collections import Counter
    from fractions import Fraction as F
    import raypipe

    e = exe()
    d = tmp_path / "rti"
    subprocess.run([e, "vectors", "--unit", "rti", "--format", "fp16", "--out", str(d)], check=True,
                   capture_output=True)
    j = json.loads(subprocess.run([e, "cover", str(d), "--json"], check=True, capture_output=True,
                                  text=True).stdout)
    s = raypipe.read_set(str(d))
    names = {f["name"]: [x["name"] for x in f["fields"]] for f in s["manifest"]["files"]}
    ins, st = s["files"]["rti_inputs.hex"], s["files"]["rti_stages.hex"]

    def get(k, n):
        if n in names["rti_inputs.hex"]:
            return ins[k, names["rti_inputs.hex"].index(n)]
        return st[k, names["rti_stages.hex"].index(n)]

    finite = sorted({v for v in map(_fp16, range(1 << 16)) if v is not None and not isinstance(v, tuple)})
    min_normal = F(1, 2 ** 14)

    def event(x, y, r, op):
        if x is None or y is None or r is None:
            return "NaN"
        if isinstance(x, tuple) or isinstance(y, tuple):
            return "exact"
        if isinstance(r, tuple):
            return "overflow"
        exact = x - y if op == "sub" else x * y
        if exact == r:
            return "exact"
        i = bisect.bisect_left(finite, exact)
        lo, hi = finite[i - 1], finite[i]
        if exact - lo == hi - exact:
            return "tie"
        return "underflow" if abs(exact) < min_normal else "inexact"

    # e1x = v1x - v0x (stage 1), pxa = dy * e2z (stage 2): datapath/src/rti.rs
    for name, op, a, b in [("e1x", "sub", "v1x", "v0x"), ("pxa", "mul", "dy", "e2z")]:
        want = Counter(event(_fp16(get(k, a)), _fp16(get(k, b)), _fp16(get(k, name)), op) for k in range(len(ins)))
        [p] = [p for p in j["coverpoints"] if p["kind"] == "rounding" and p["signal"] == f"{name} ({op})"]
        got = {b["name"]: b["count"] for b in p["bins"] if b["count"]}
        assert got == dict(want), (name, got, dict(want))
        assert got.get("tie", 0) > 0 and got.get("inexact", 0) > 0


def test_op_rounding_events_match_exact_rational_arithmetic(tmp_path):
    """The op unit's result, classified by the operation its opcode selects (fp16, divide
    mode), against exact rational arithmetic."""
    import bisect
    from collections import Counter
    from fractions import Fraction as F
    import raypipe

    e = exe()
    d = tmp_path / "op"
    subprocess.run([e, "vectors", "--unit", "op", "--format", "fp16:divide", "--out", str(d)], check=True,
                   capture_output=True)
    j = json.loads(subprocess.run([e, "cover", str(d), "--json"], check=True, capture_output=True,
                                  text=True).stdout)
    s = raypipe.read_set(str(d))
    ins, out = s["files"]["op_inputs.hex"], s["files"]["op_expected.hex"]
    finite = sorted({v for v in map(_fp16, range(1 << 16)) if v is not None and not isinstance(v, tuple)})
    # beyond the largest finite value, its next step (2^16): RNE's overflow midpoint is between
    finite = [-F(2 ** 16)] + finite + [F(2 ** 16)]
    min_normal = F(1, 2 ** 14)
    want = Counter()
    for k in range(len(ins)):
        opcode, a, b, r = int(ins[k, 1]), _fp16(ins[k, 2]), _fp16(ins[k, 3]), _fp16(out[k, 0])
        if opcode > 3:
            continue
        if a is None or b is None or r is None:
            want["NaN"] += 1
            continue
        if opcode == 3 and b == 0:
            want["exact"] += 1
            continue
        if isinstance(a, tuple) or isinstance(b, tuple):
            want["exact"] += 1
            continue
        if isinstance(r, tuple):
            want["overflow"] += 1
            continue
        exact = [a + b, a - b, a * b, a / b if b else None][opcode]
        if exact == r:
            want["exact"] += 1
            continue
        i = bisect.bisect_left(finite, exact)
        lo, hi = finite[i - 1], finite[i]
        if exact - lo == hi - exact:
            want["tie"] += 1
        else:
            want["underflow" if abs(exact) < min_normal else "inexact"] += 1
    [p] = [p for p in j["coverpoints"] if p["kind"] == "rounding"]
    got = {b["name"]: b["count"] for b in p["bins"] if b["count"]}
    assert got == dict(want), (got, dict(want))
