"""cocotb testbench: a reference DUT of raypipe's HDL kit (rti or slab) driven with random
stimulus and scored by raypipe's Python model (`import raypipe`), every output and stage
signal, with the care rules of the set's manifest. Run by hdl/cocotb/run.py, which sets:

  RAYPIPE_SET      a set of the unit and format (its manifest gives the row layout and care rules)
  RAYPIPE_OPTIONS  the unit's CLI options      RAYPIPE_N  vectors     RAYPIPE_SEED  the seed

Stimulus per vector: stimulus.py (aimed, random, edge encodings, ties).
"""

import json
import os
import random
from collections import deque

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge

import raypipe
from stimulus import Stimulus, differs, fields, pack, unpack


@cocotb.test()
async def random_vectors(dut):
    set_dir = os.environ["RAYPIPE_SET"]
    manifest = json.load(open(os.path.join(set_dir, "manifest.json")))
    n = int(os.environ.get("RAYPIPE_N", "1000"))
    seed = int(os.environ.get("RAYPIPE_SEED", "1"))
    model = raypipe.Unit(manifest["unit"], manifest["format"], os.environ.get("RAYPIPE_OPTIONS", ""))
    # RAYPIPE_COVER: record the driven rows' functional coverage there (docs/coverage.md)
    cover_path = os.environ.get("RAYPIPE_COVER", "")
    cover = raypipe.Cover(manifest["unit"], manifest["format"], os.environ.get("RAYPIPE_OPTIONS", "")) if cover_path else None
    in_f, out_f, stg_f = fields(manifest, "_inputs.hex"), fields(manifest, "_expected.hex"), fields(manifest, "_stages.hex")
    in_w, out_w, stg_w = [f["width"] for f in in_f], [f["width"] for f in out_f], [f["width"] for f in stg_f]
    assert [f["name"] for f in stg_f] == model.stage_names, "the model's stage signals are not the set's"
    lat = int(manifest["latency"])
    stim = Stimulus(model, manifest, random.Random(seed))
    dut._log.info(f"raypipe {raypipe.version()}: unit {manifest['unit']}, format {manifest['format']}, "
                  f"{n} random vectors, seed {seed}, latency {lat}")

    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.rst_n.value = 0
    dut.in_valid.value = 0
    dut.in_row.value = 0
    for _ in range(2):
        await FallingEdge(dut.clk)
    dut.rst_n.value = 1

    pending = deque()
    results = {"passed": 0, "failed": 0}
    edge = 0

    async def monitor():
        nonlocal edge
        while True:
            await RisingEdge(dut.clk)
            edge += 1
            await FallingEdge(dut.clk)
            if pending and pending[0][0] == edge:
                _, kind, want_out, want_stg = pending.popleft()
                if not dut.out_valid.value:
                    why = "no out_valid"
                else:
                    got_out = unpack(int(dut.out_row.value), out_w)
                    got_stg = unpack(int(dut.stg_row.value), stg_w)
                    outs = {f["name"]: v for f, v in zip(out_f, want_out)}
                    why = differs(got_out, want_out, out_f, outs) or differs(got_stg, want_stg, stg_f, outs)
                if why:
                    results["failed"] += 1
                    if results["failed"] <= 10:
                        dut._log.error(f"FAIL ({kind} vector, edge {edge}): first field to differ: {why}")
                else:
                    results["passed"] += 1
            elif dut.out_valid.value:
                results["failed"] += 1
                dut._log.error(f"FAIL: out_valid at edge {edge}, where no vector is due")

    cocotb.start_soon(monitor())
    for _ in range(n):
        row, kind = stim.vector()
        r = model.eval(row, stages=True)
        if cover:
            cover.add(row)
        dut.in_row.value = pack([0] + row, in_w)
        dut.in_valid.value = 1
        # captured at the next rising edge, out LATENCY edges later
        pending.append((edge + 1 + lat, kind, [r[k] for k in model.outputs], list(r["stages"].values())))
        await FallingEdge(dut.clk)
    dut.in_valid.value = 0
    for _ in range(lat + 4):
        await FallingEdge(dut.clk)
    if pending:
        results["failed"] += len(pending)
        dut._log.error(f"FAIL: {len(pending)} vectors never came out")
    print(f"{results['passed']} passed, {results['failed']} failed", flush=True)
    if cover:
        cover.write(cover_path)
        print(f"coverage: {cover.rows} driven rows recorded in {cover_path} (raypipe cover {cover_path})", flush=True)
    assert results["failed"] == 0, f"{results['failed']} of {n} vectors failed"
