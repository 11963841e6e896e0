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
