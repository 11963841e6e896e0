"""`raypipe equiv`: the HardFloat op unit (hdl/hardfloat/raypipe_op_hf.v, read by yosys) equals
raypipe's fp16 op model for every pair of encodings — add, sub, mul, lt and le each PROVEN — and
each injected RTL fault yields a counterexample the Icarus replay confirms. Needs yosys, Icarus
and bitwuzla (CI installs them)."""

import json
import os
import shutil
import subprocess

import pytest

pytest.importorskip("bitwuzla")
if not (shutil.which("yosys") and shutil.which("iverilog")):
    pytest.skip("needs yosys and iverilog", allow_module_level=True)

HERE = os.path.dirname(os.path.abspath(__file__))
EQUIV = os.path.join(HERE, "..", "..", "hdl", "hardfloat", "equiv")


def exe():
    e = os.environ.get("RAYPIPE") or shutil.which("raypipe")
    if e is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    return e


def equiv(*args):
    p = subprocess.run([EQUIV, "--raypipe", exe(), "--json", *args], capture_output=True, text=True)
    assert p.stdout, p.stderr
    return p.returncode, json.loads(p.stdout)


def test_hardfloat_op_fp16_is_equivalent():
    rc, j = equiv("--format", "fp16")
    assert (rc, j["status"]) == (0, "PROVEN"), j
    assert sorted(o["name"] for o in j["outputs"]) == ["add", "le", "lt", "mul", "sub"]
    assert all(o["result"] == "unsat" and o["solver"] == "bitwuzla" for o in j["outputs"]), j


@pytest.mark.parametrize("fault,output", [
    ("RAYPIPE_HF_FAULT_MUL_RUP", "mul"),
    ("RAYPIPE_HF_FAULT_SUB_SWAP", "sub"),
    ("RAYPIPE_HF_FAULT_LE_STRICT", "le"),
])
def test_each_fault_is_a_replayed_counterexample(fault, output):
    rc, j = equiv("--format", "fp16", "--define", fault, "--outputs", output)
    assert (rc, j["status"]) == (1, "COUNTEREXAMPLE"), j
    [o] = j["outputs"]
    cx = o["counterexample"]
    # the solver's DUT value is what Icarus computes, and it is not the model's
    assert cx["icarus"] == cx["dut"] != cx["model"], cx
    assert set(cx["inputs"]) == {"a", "b"}


def test_bad_requests_exit_2(tmp_path):
    e = exe()
    bad = [
        ["equiv", "--rtl", str(tmp_path / "none.v"), "--top", "x"],
        ["equiv", "--rtl", os.path.join(HERE, "..", "..", "hdl", "hardfloat", "raypipe_op_hf.v"), "--top", "no_such"],
    ]
    for args in bad:
        p = subprocess.run([e, *args], capture_output=True, text=True)
        assert p.returncode == 2 and p.stderr.strip(), (args, p.stderr)
    # a sequential module is refused (this version proves combinational DUTs)
    seq = tmp_path / "seq.v"
    seq.write_text("module seq(input clk, input [15:0] a, output reg [15:0] add);\n"
                   "always @(posedge clk) add <= a;\nendmodule\n")
    p = subprocess.run([e, "equiv", "--rtl", str(seq), "--top", "seq", "--unit", "op"], capture_output=True, text=True)
    assert p.returncode == 2 and "register" in p.stderr, p.stderr


# ---- the pipelined slab datapath (hdl/hardfloat/raypipe_slab_hf.sv), stage by stage

def slab_set(tmp_path):
    d = tmp_path / "slab_fp16"
    subprocess.run([exe(), "vectors", "--unit", "slab", "--format", "fp16", "--variant", "conservative",
                    "--count", "1", "--out", str(d)], check=True, capture_output=True)
    return str(d)


def f16(bits):
    import numpy as np
    return float(np.array([bits], dtype=np.uint16).view(np.float16)[0])


def f16_bits(x):
    import numpy as np
    return int(np.array([x], dtype=np.float16).view(np.uint16)[0])


def test_pipelined_slab_fp16_signals_and_faults(tmp_path):
    """Signals of four stages proven from the row registers (the division stage's read
    invariant by bounded model checking from reset); with two RTL faults, the stage-1 subtract
    and the stage-6 compare differ, and the subtract's witness is checked by float arithmetic."""
    s = slab_set(tmp_path)
    rc, j = equiv(s, "--outputs", "lox,tn_xyz,t_near,hit", "--timeout", "300")
    assert (rc, j["status"]) == (0, "PROVEN (the signals named)"), j
    assert [(x["stages"], x["goal"], x["result"]) for x in j["steps"]] == [
        ("1", "lox", "unsat"), ("4", "tn_xyz", "unsat"), ("5", "t_near", "unsat"), ("6", "hit", "unsat")]
    rc, j = equiv("--define", "RAYPIPE_HF_FAULT_LOX_SWAP", "--define", "RAYPIPE_HF_FAULT_HIT_STRICT", s,
                  "--outputs", "lox,hix,hit", "--timeout", "300")
    assert (rc, j["status"]) == (1, "COUNTEREXAMPLE"), j
    res = {x["goal"]: x for x in j["steps"]}
    assert res["hix"]["result"] == "unsat" and res["lox"]["result"] == "sat" and res["hit"]["result"] == "sat"
    cx = {k: int(v, 16) for k, v in res["lox"]["counterexample"].items()}
    minx, ox = f16(cx["in_minx"]), f16(cx["in_ox"])
    # fp16 differences are exact in binary64: one rounding to binary16
    assert cx["model lox"] == f16_bits(minx - ox), cx
    assert cx["dut lox"] == f16_bits(ox - minx) != cx["model lox"], cx
    cx = {k: int(v, 16) for k, v in res["hit"]["counterexample"].items()}
    assert cx["dut hit"] != cx["model hit"], cx
