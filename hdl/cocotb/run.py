#!/usr/bin/env python3
"""Runs hdl/cocotb/test_raypipe.py on a reference DUT of raypipe's HDL kit in Icarus Verilog,
through cocotb 2's Python runner:

    python3 hdl/cocotb/run.py [--unit rti|slab] [--format F] [--options "O"] [--n N] [--seed S]
                              [--define NAME]...

Needs `pip install cocotb ./python` and Icarus Verilog 11+. Writes the format's set (`raypipe
vectors --count 1`, for its package and manifest) and prints the testbench's `N passed, M
failed`; exit status 0 only when every vector passed (e.g. --define RAYPIPE_INJECT_FAULT makes
the rti DUT's detx multiplier truncate: the run must fail). RAYPIPE: the raypipe binary
(default target/release/raypipe).
"""

import argparse
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
    a = ap.parse_args()
    exe = os.environ.get("RAYPIPE") or os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "raypipe")
    with tempfile.TemporaryDirectory() as work:
        set_dir = os.path.join(work, "set")
        subprocess.run([exe, "vectors", "--unit", a.unit, "--format", a.format, *a.options.split(), "--count", "1",
                        "--out", set_dir], check=True, stdout=subprocess.DEVNULL)
        sources = [os.path.join(ROOT, "hdl/sv/raypipe_fp.sv"), os.path.join(set_dir, "raypipe_pkg.sv")]
        if a.unit == "slab":
            sources.append(os.path.join(ROOT, "hdl/sv/raypipe_box.sv"))
        sources.append(os.path.join(ROOT, f"hdl/sv/ref/{a.unit}_ref.sv"))
        top = f"raypipe_{a.unit}_ref"
        runner = get_runner("icarus")
        runner.build(sources=sources, hdl_toplevel=top, build_args=["-g2012"], defines={d: 1 for d in a.define},
                     build_dir=os.path.join(work, "build"), always=True, timescale=("1ns", "1ps"))
        here = os.path.dirname(os.path.abspath(__file__))
        env = {"RAYPIPE_SET": set_dir, "RAYPIPE_OPTIONS": a.options, "RAYPIPE_N": str(a.n), "RAYPIPE_SEED": str(a.seed),
               "PYTHONPATH": os.pathsep.join([here] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])}
        # everything the run writes (results.xml, the simulator's files) stays in the temporary directory
        results = runner.test(hdl_toplevel=top, test_module="test_raypipe", test_dir=work,
                              build_dir=os.path.join(work, "build"), extra_env=env,
                              results_xml=os.path.join(work, "results.xml"))
        from cocotb_tools.runner import get_results

        tests, fails = get_results(results)
        sys.exit(1 if fails or not tests else 0)


if __name__ == "__main__":
    main()
