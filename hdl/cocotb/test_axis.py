"""cocotb testbench for a DUT with AXI4-Stream ports (aclk, aresetn, s_axis_tdata / tvalid /
tready [/ tid], m_axis_tdata / tvalid / tready [/ tuser / tid]), driven by cocotbext-axi's
AxiStreamSource and AxiStreamSink with random stimulus (stimulus.py) and scored by raypipe's
Python model (`import raypipe`). Run by hdl/cocotb/run.py --axis, which sets:

  RAYPIPE_SET      a set of the unit and format written with --wrapper axis: its axis_map.json
                   says where each field sits on s_axis_tdata / m_axis_tdata (bit b of tdata is
                   bit b % 8 of byte lane b / 8, cocotbext-axi's order), its manifest the stage
                   row on m_axis_tuser and the care rules
  RAYPIPE_OPTIONS  the unit's CLI options      RAYPIPE_N  vectors     RAYPIPE_SEED  the seed
  RAYPIPE_STALL    percent of cycles the sink holds m_axis_tready low (seeded), default 0
  RAYPIPE_IDS      W > 0: vector k goes in with tid = k mod 2^W, results are matched by tid in
                   any order, at most 2^W vectors outstanding; 0 (default): results in order
  RAYPIPE_PROBES   1: compare every stage signal on m_axis_tuser; 0: outputs only
  RAYPIPE_LATENCY  the DUT's latency in clocks at full rate (the timeout's base), default the
                   manifest's

Checks: every result against the model (the first field to differ named, earliest stage first);
results in order (or by tid); no result without an outstanding vector; the AXI4-Stream rule on
the DUT's output (m_axis_tvalid, once 1 without tready, stays 1 with m_axis_tdata, tuser and tid
unchanged until the transfer); a timeout naming the oldest vector still outstanding after
4 x latency + 64 cycles with tready high. Prints latency min / median / max, throughput and
`N passed, M failed`.
"""

import json
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

import raypipe
from stimulus import Stimulus, differs, fields, unpack


def bus_word(values, bus):
    """The tdata word with each named value at its map position."""
    word = 0
    for f in bus["fields"]:
        word |= (int(values[f["name"]]) & ((1 << f["width"]) - 1)) << f["lsb"]
    return word


def bus_fields(word, bus):
    """name -> value of each field of the map on a tdata word."""
    return {f["name"]: (word >> f["lsb"]) & ((1 << f["width"]) - 1) for f in bus["fields"]}


@cocotb.test()
async def axis_vectors(dut):
    set_dir = os.environ["RAYPIPE_SET"]
    manifest = json.load(open(os.path.join(set_dir, "manifest.json")))
    amap = json.load(open(os.path.join(set_dir, "axis_map.json")))
    n = int(os.environ.get("RAYPIPE_N", "1000"))
    seed = int(os.environ.get("RAYPIPE_SEED", "1"))
    stall = int(os.environ.get("RAYPIPE_STALL", "0"))
    ids = int(os.environ.get("RAYPIPE_IDS", "0"))
    probes = os.environ.get("RAYPIPE_PROBES", "1") == "1"
    lat = int(os.environ.get("RAYPIPE_LATENCY") or manifest["latency"])
    model = raypipe.Unit(manifest["unit"], manifest["format"], os.environ.get("RAYPIPE_OPTIONS", ""))
    # RAYPIPE_COVER: record the driven rows' functional coverage there (docs/coverage.md)
    cover_path = os.environ.get("RAYPIPE_COVER", "")
    cover = raypipe.Cover(manifest["unit"], manifest["format"], os.environ.get("RAYPIPE_OPTIONS", "")) if cover_path else None
    in_f, out_f, stg_f = fields(manifest, "_inputs.hex"), fields(manifest, "_expected.hex"), fields(manifest, "_stages.hex")
    stg_w = [f["width"] for f in stg_f]
    in_names = [f["name"] for f in in_f if f["name"] != "class"]
    stim = Stimulus(model, manifest, random.Random(seed))
    timeout = 4 * lat + 64
    dut._log.info(f"raypipe {raypipe.version()}: unit {manifest['unit']}, format {manifest['format']}, {n} random "
                  f"vectors, seed {seed}, AXI4-Stream, stall {stall} %, ids {ids} bits, probes {'on' if probes else 'off'}, "
                  f"timeout {timeout} ready cycles")

    cocotb.start_soon(Clock(dut.aclk, 10, unit="ns").start())
    dut.aresetn.value = 0
    source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.aclk, dut.aresetn, reset_active_level=False)
    sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.aclk, dut.aresetn, reset_active_level=False)
    for x in (source, sink):
        x.log.setLevel("WARNING")
    stall_rng = random.Random(seed * 7919 + 1)

    def pauses():
        while True:
            yield stall > 0 and stall_rng.randrange(100) < stall

    sink.set_pause_generator(pauses())
    for _ in range(2):
        await FallingEdge(dut.aclk)
    dut.aresetn.value = 1

    s_bytes = amap["s_axis_tdata"]["width"] // 8
    idn = 1 << ids if ids else 0
    want = {}  # vector -> (kind, outputs, stages)
    outstanding = []  # vectors in, not yet out, oldest first
    in_edges, out_edges, pairs = [], [], []  # pairs: (output transfer j, vector k)
    state = {"passed": 0, "failed": 0, "proto": 0, "waited": 0, "edge": 0, "done": False, "reorder": 0, "got": 0}

    def fail(msg):
        state["failed"] += 1
        if state["failed"] <= 10:
            dut._log.error(msg)

    async def handshakes():
        """Edge numbers of the transfers, the protocol rule on the output, the timeout."""
        held = None
        while not state["done"]:
            await RisingEdge(dut.aclk)
            state["edge"] += 1
            if not dut.aresetn.value:
                continue
            sv, sr = int(dut.s_axis_tvalid.value), int(dut.s_axis_tready.value)
            mv, mr = int(dut.m_axis_tvalid.value), int(dut.m_axis_tready.value)
            now = (int(dut.m_axis_tdata.value) if mv else None,
                   int(dut.m_axis_tuser.value) if mv and probes else None,
                   int(dut.m_axis_tid.value) if mv and ids else None)
            if held is not None and (not mv or now != held):
                state["proto"] += 1
                if state["proto"] <= 10:
                    dut._log.error(f"FAIL: protocol at edge {state['edge']}: the result offered at the edge before "
                                   f"(m_axis_tvalid without tready) {'was withdrawn' if not mv else 'changed'} before its transfer")
            held = now if mv and not mr else None
            if sv and sr:
                in_edges.append(state["edge"])
            if mv and mr:
                out_edges.append(state["edge"])
                state["waited"] = 0
            elif outstanding and mr:
                state["waited"] += 1
                if state["waited"] > timeout:
                    k = outstanding[0]
                    fail(f"FAIL vector {k} ({want[k][0]}): never came out: no result for {timeout} ready cycles")
                    state["done"] = True

    async def receiver():
        while state["got"] < n and not state["done"]:
            if sink.empty():
                await RisingEdge(dut.aclk)
                continue
            frame = sink.recv_nowait()
            j = state["got"]
            state["got"] += 1
            word = int.from_bytes(bytes(frame.tdata), "little")
            tid = frame.tid if isinstance(frame.tid, int) else (frame.tid[0] if frame.tid else 0)
            if idn:
                match = [k for k in outstanding if k % idn == tid]
            else:
                match = outstanding[:1]
            if not match:
                fail(f"FAIL: extra result (transfer {j}, tid {tid}): no outstanding vector " +
                     (f"has id {tid}" if idn else "is waiting"))
                continue
            k = match[0]
            state["reorder"] = max(state["reorder"], outstanding.index(k))
            outstanding.remove(k)
            kind, want_out, want_stg = want.pop(k)
            pairs.append((j, k))
            got = bus_fields(word, amap["m_axis_tdata"])
            got_out = [got[f["name"]] for f in out_f]
            outs = {f["name"]: v for f, v in zip(out_f, want_out)}
            why = differs(got_out, want_out, out_f, outs)
            if not why and probes:
                tuser = frame.tuser if isinstance(frame.tuser, int) else frame.tuser[0]
                why = differs(unpack(tuser, stg_w), want_stg, stg_f, outs)
            if why:
                fail(f"FAIL vector {k} ({kind} vector, output transfer {j}): first field to differ: {why}")
            else:
                state["passed"] += 1

    hs = cocotb.start_soon(handshakes())
    rx = cocotb.start_soon(receiver())
    for k in range(n):
        row, kind = stim.vector()
        r = model.eval(row, stages=True)
        if cover:
            cover.add(row)
        want[k] = (kind, [r[x] for x in model.outputs], list(r["stages"].values()))
        while idn and len(outstanding) >= idn and not state["done"]:
            await RisingEdge(dut.aclk)
        if state["done"]:
            break
        outstanding.append(k)
        word = bus_word(dict(zip(in_names, row)), amap["s_axis_tdata"])
        await source.send(AxiStreamFrame(word.to_bytes(s_bytes, "little"), tid=(k % idn) if idn else 0))
    await rx
    state["done"] = True
    await hs
    if state["got"] < n and outstanding:
        fail(f"FAIL: {len(outstanding)} vectors never came out (the first: vector {outstanding[0]})")
    lats = [out_edges[j] - in_edges[k] for j, k in pairs if j < len(out_edges) and k < len(in_edges)]
    if lats:
        s = sorted(lats)
        print(f"latency (edges from input to output transfer): min {s[0]}, median {s[len(s) // 2]}, max {s[-1]} "
              f"over {len(s)} results", flush=True)
        span = out_edges[-1] - in_edges[0] + 1
        print(f"throughput: {len(lats)} results in {span} edges ({len(lats) / span:.3f} per clock)", flush=True)
    if idn:
        print(f"out of order: ids of {ids} bits; at most {state['reorder']} earlier vector(s) still waiting when one came out",
              flush=True)
    print(f"{state['passed']} passed, {state['failed']} failed", flush=True)
    if cover:
        cover.write(cover_path)
        print(f"coverage: {cover.rows} driven rows recorded in {cover_path} (raypipe cover {cover_path})", flush=True)
    assert state["proto"] == 0, f"{state['proto']} protocol violations"
    assert state["failed"] == 0, f"{state['failed']} of {n} vectors failed"
