#!/usr/bin/env python3
"""Runs hdl/cocotb/test_raypipe.py on a reference DUT of raypipe's HDL kit in Icarus Verilog,
through cocotb 2's Python runner:

    python3 hdl/cocotb/run.py [--unit rti|slab] [--format F] [--options "O"] [--n N] [--seed S]
                              [--define NAME]... [--cover FILE]

or hdl/cocotb/test_axis.py on a DUT with AXI4-Stream ports (cocotbext-axi's AxiStreamSource and
AxiStreamSink, valid/ready on both sides, seeded output stalls, results in order or by tid):

    python3 hdl/cocotb/run.py --axis MODULE --rtl FILE... [--incdir DIR]... [--latency L]
                              [--stall P] [--ids W] [--no-probes] [--axis-map FILE] [as above]
    python3 hdl/cocotb/run.py --hardfloat [--stall P] [--ids W] [as above]

--hardfloat is --axis raypipe_<unit>_hf_axis with the HardFloat datapath's sources
(hdl/hardfloat/sources.txt) and its latency. --axis-map: the tdata layout of your DUT (an edited
axis_map.json; default: the documented default map). --no-probes: your DUT has no m_axis_tuser
(outputs only). --cover FILE: record the functional coverage of the rows driven into the DUT
(raypipe.Cover) and write it to FILE for `raypipe cover` (docs/coverage.md).

Needs `pip install cocotb ./python` and Icarus Verilog 11+. Writes the format's set (`raypipe
vectors --count 1`, for its package and manifest) and prints the testbench's `N passed, M
failed`; exit status 0 only when every vector passed (e.g. --define RAYPIPE_INJECT_FAULT makes
the rti DUT's detx multiplier truncate: the run must fail). RAYPIPE: the raypipe binary
(default target/release/raypipe).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

from cocotb_tools.runner import get_runner

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--unit", default="rti", choices=["rti", "slab"])
    ap.add_argument("--format", default="f32")
    ap.add_argument("--options", default="")
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--define", action="append", default=[])
    ap.add_argument("--axis", help="your DUT module with AXI4-Stream ports")
    ap.add_argument("--hardfloat", action="store_true", help="the HardFloat datapath (AXI4-Stream)")
    ap.add_argument("--rtl", action="append", default=[], help="a source file of your DUT")
    ap.add_argument("--incdir", action="append", default=[], help="an include directory of your DUT")
    ap.add_argument("--latency", type=int, help="your DUT's latency (the timeout's base)")
    ap.add_argument("--stall", type=int, default=0, help="percent of cycles with m_axis_tready low")
    ap.add_argument("--ids", type=int, default=0, help="tid width: results matched by id, in any order")
    ap.add_argument("--no-probes", action="store_true", help="the DUT has no m_axis_tuser stage probes")
    ap.add_argument("--axis-map", help="your tdata layout (an edited axis_map.json)")
    ap.add_argument("--cover", help="record the driven rows' functional coverage in this file (docs/coverage.md)")
    a = ap.parse_args()
    if a.hardfloat and a.axis:
        ap.error("--hardfloat names the DUT; drop --axis")
    if not 0 <= a.stall <= 99:
        ap.error("--stall takes a percentage from 0 to 99")
    if not 0 <= a.ids <= 16:
        ap.error("--ids takes an id width of 0 to 16 bits")
    if a.axis and not a.rtl:
        ap.error("--axis needs your DUT's sources (--rtl FILE)")
    axis = a.axis or (f"raypipe_{a.unit}_hf_axis" if a.hardfloat else None)
    if a.cover and os.path.exists(a.cover):
        # before the work: a file raypipe did not write is never replaced
        with open(a.cover, errors="replace") as f:
            if "raypipe coverage" not in f.read(4096):
                ap.error(f"--cover {a.cover} exists and raypipe did not write it: not replacing it")
    exe = os.environ.get("RAYPIPE") or os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "raypipe")
    with tempfile.TemporaryDirectory() as work:
        set_dir = os.path.join(work, "set")
        wrap = ["--wrapper", "axis"] + (["--axis-map", a.axis_map] if a.axis_map else []) if axis else []
        subprocess.run([exe, "vectors", "--unit", a.unit, "--format", a.format, *a.options.split(), "--count", "1",
                        *wrap, "--out", set_dir], check=True, stdout=subprocess.DEVNULL)
        manifest = json.load(open(os.path.join(set_dir, "manifest.json")))
        sources = [os.path.join(ROOT, "hdl/sv/raypipe_fp.sv"), os.path.join(set_dir, "raypipe_pkg.sv")]
        includes = [os.path.abspath(d) for d in a.incdir]
        latency = a.latency or int(manifest["latency"])
        if axis:
            sources.append(os.path.join(ROOT, "hdl/sv/raypipe_stream.sv"))
            if a.hardfloat:
                hdl = os.path.join(ROOT, "hdl")
                for line in open(os.path.join(hdl, "hardfloat/sources.txt")):
                    line = line.strip()
                    if line and not line.startswith("#"):
                        sources.append(os.path.join(hdl, line.replace("UNIT", a.unit)))
                sources.append(os.path.join(hdl, f"hardfloat/raypipe_{a.unit}_hf_axis.sv"))
                hf = os.path.join(hdl, "third_party/hardfloat/source")
                includes += [hf, os.path.join(hf, "RISCV")]
                latency = int(manifest["latency"]) + int(manifest["params"]["man"]) + 3
            sources += [os.path.abspath(f) for f in a.rtl]
            top, test_module = axis, "test_axis"
        else:
            if a.unit == "slab":
                sources.append(os.path.join(ROOT, "hdl/sv/raypipe_box.sv"))
            sources.append(os.path.join(ROOT, f"hdl/sv/ref/{a.unit}_ref.sv"))
            top, test_module = f"raypipe_{a.unit}_ref", "test_raypipe"
        defines = {d: 1 for d in a.define}
        if a.ids:
            defines["RAYPIPE_ID_W"] = a.ids
        runner = get_runner("icarus")
        runner.build(sources=sources, hdl_toplevel=top, build_args=["-g2012"], defines=defines, includes=includes,
                     build_dir=os.path.join(work, "build"), always=True, timescale=("1ns", "1ps"))
        here = os.path.dirname(os.path.abspath(__file__))
        env = {"RAYPIPE_SET": set_dir, "RAYPIPE_OPTIONS": a.options, "RAYPIPE_N": str(a.n), "RAYPIPE_SEED": str(a.seed),
               "RAYPIPE_STALL": str(a.stall), "RAYPIPE_IDS": str(a.ids), "RAYPIPE_LATENCY": str(latency),
               "RAYPIPE_PROBES": "0" if a.no_probes else "1",
               "RAYPIPE_COVER": os.path.abspath(a.cover) if a.cover else "",
               "PYTHONPATH": os.pathsep.join([here] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])}
        # everything the run writes (results.xml, the simulator's files) stays in the temporary directory
        results = runner.test(hdl_toplevel=top, test_module=test_module, test_dir=work,
                              build_dir=os.path.join(work, "build"), extra_env=env,
                              results_xml=os.path.join(work, "results.xml"))
        from cocotb_tools.runner import get_results

        tests, fails = get_results(results)
        sys.exit(1 if fails or not tests else 0)


if __name__ == "__main__":
    main()
