"""pytest for the raypipe Python package: hand-worked results, the batch against single tests,
a written vector set reproduced row by row, the format parser, and every bad-input path."""

import os
import shutil
import subprocess
import tempfile
import threading

import numpy as np
import pytest

import raypipe

HIT = (0.25, 0.25, -1, 0, 0, 1, 0, 10, 0, 0, 0, 1, 0, 0, 0, 1, 0)


def f32(x):
    return int(np.array([x], dtype=np.float32).view(np.uint32)[0])


def test_rti_by_hand():
    # a ray from (0.25, 0.25, -1) along +z against (0,0,0) (1,0,0) (0,1,0): det = -1,
    # t = 1, u = v = 0.25 exactly
    u = raypipe.Unit("rti", "f32")
    row = [f32(x) for x in HIT]
    assert [u.encode(x) for x in HIT] == row
    r = u.eval(row, stages=True)
    assert (r["valid"], r["hit"], r["t"], r["u"], r["v"]) == (1, 1, f32(1.0), f32(0.25), f32(0.25))
    assert r["stages"]["det"] == f32(-1.0)
    assert list(r["stages"]) == u.stage_names
    culled = raypipe.Unit("rti", "f32", "--cull").eval(row)
    assert (culled["valid"], culled["hit"]) == (0, 0)


def test_op_and_conversions():
    u = raypipe.Unit("op", "fp16")
    assert u.eval([0, 0x3C00, 0x1000]) == {"result": 0x3C00, "cmp": 0}  # 1 + 2^-11: a tie, to even
    assert u.eval([4, 0x3C00, 0x4000])["cmp"] == 1
    assert u.encode(1.0 / 3.0) == 0x3555
    assert u.decode(0x0001) == 2.0**-24
    assert raypipe.Unit("op", "q16.16").encode(-0.5) == 0xFFFF8000


@pytest.mark.parametrize("fmt", ["f32", "fp16", "bf16", "e8m16", "q16.16", "q8.24:divide", "e5m10:ftz"])
@pytest.mark.parametrize("unit", ["rti", "slab", "op"])
def test_batch_equals_single_tests(unit, fmt):
    u = raypipe.Unit(unit, fmt)
    rng = np.random.default_rng(5)
    n = 600
    rows = rng.integers(0, 2**u.width, size=(n, len(u.inputs)), dtype=np.uint64)
    if unit == "op":
        rows[:, 0] %= 6
    out = u.eval_batch(rows)
    assert out.shape == (n, len(u.outputs)) and out.dtype == np.uint64
    for k in range(0, n, 7):
        single = u.eval([int(x) for x in rows[k]])
        assert [single[name] for name in u.outputs] == [int(x) for x in out[k]]
    # a non-contiguous view gives the same rows
    assert np.array_equal(u.eval_batch(rows[::2]), out[::2])


def test_batch_releases_the_gil():
    # this thread counts while the other is inside eval_batch: with the GIL held for the whole
    # call it could not run at all then (a switch needs the GIL)
    u = raypipe.Unit("rti", "f32")
    rows = np.tile(np.array([u.encode(x) for x in HIT], dtype=np.uint64), (400_000, 1))
    state = {"started": False, "done": False, "out": None}

    def work():
        state["started"] = True
        state["out"] = u.eval_batch(rows)
        state["done"] = True

    t = threading.Thread(target=work)
    t.start()
    ticks = 0
    while not state["done"]:
        if state["started"]:
            ticks += 1
    t.join()
    assert state["out"].shape == (400_000, 5) and (state["out"][:, 2] == f32(1.0)).all()
    assert ticks > 10_000, ticks


def raypipe_binary():
    here = os.path.dirname(os.path.abspath(__file__))
    cand = os.environ.get("RAYPIPE") or os.path.join(here, "..", "..", "target", "release", "raypipe")
    return cand if os.path.exists(cand) else shutil.which("raypipe")


@pytest.mark.parametrize("unit,fmt,opts", [("rti", "fp16", []), ("slab", "f32", ["--variant", "conservative"]), ("op", "e8m16", [])])
def test_a_written_set_is_reproduced(unit, fmt, opts):
    exe = raypipe_binary()
    if exe is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "set")
        subprocess.run([exe, "vectors", "--unit", unit, "--format", fmt, *opts, "--count", "4", "--out", out], check=True,
                       capture_output=True)
        s = raypipe.read_set(out)
        assert s["manifest"]["unit"] == unit and s["manifest"]["format"] == fmt
        names = [f["name"] for f in s["manifest"]["files"]]
        ins, want = s["files"][names[0]], s["files"][names[1]]
        u = raypipe.Unit(unit, fmt, " ".join(opts))
        got = u.eval_batch(np.ascontiguousarray(ins[:, 1:]))  # the class column first
        assert np.array_equal(got, want)
        if len(names) > 2:
            stg = s["files"][names[2]]
            for k in range(len(ins)):
                r = u.eval([int(x) for x in ins[k, 1:]], stages=True)
                assert list(r["stages"].values()) == [int(x) for x in stg[k]]
        # a file changed after writing is refused
        with open(os.path.join(out, names[1]), "a") as f:
            f.write("0\n")
        with pytest.raises(ValueError, match="sha256"):
            raypipe.read_set(out)


def test_parse_format():
    f = raypipe.parse_format("e8m16:ftz")
    assert (f["name"], f["width"], f["kind"], f["exp_bits"], f["man_bits"]) == ("e8m16:ftz", 25, "float", 8, 16)
    assert "flush to zero" in f["contract"]["subnormals"]
    q = raypipe.parse_format("q8.24:divide")
    assert (q["kind"], q["int_bits"], q["frac_bits"], q["width"]) == ("fixed", 8, 24, 32)


def test_bad_input_raises_clear_errors():
    with pytest.raises(ValueError, match="f33"):
        raypipe.Unit("rti", "f33")
    with pytest.raises(ValueError, match="unknown unit"):
        raypipe.Unit("bvh", "f32")
    with pytest.raises(ValueError, match="--frobnicate"):
        raypipe.Unit("rti", "f32", "--frobnicate")
    with pytest.raises(ValueError):
        raypipe.parse_format("e99m1")
    u = raypipe.Unit("rti", "f32")
    with pytest.raises(ValueError, match="17"):
        u.eval([0] * 16)
    with pytest.raises(ValueError, match="bits above"):
        u.eval([1 << 32] + [0] * 16)
    with pytest.raises(ValueError, match="columns"):
        u.eval_batch(np.zeros((3, 16), dtype=np.uint64))
    with pytest.raises(TypeError):
        u.eval_batch(np.zeros((3, 17), dtype=np.float64))
    with pytest.raises(ValueError, match="op code"):
        raypipe.Unit("op", "f32").eval([9, 0, 0])
    with pytest.raises(ValueError, match="stage signals"):
        raypipe.Unit("slab", "f32", "--variant directed").eval([0] * 14, stages=True)
    with pytest.raises(OSError):
        raypipe.read_set("/nonexistent/raypipe-set")


def test_traverse_over_a_written_sets_tree():
    exe = raypipe_binary()
    if exe is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "set")
        subprocess.run([exe, "vectors", "--unit", "traverse", "--format", "fp16", "--count", "4", "--out", out], check=True,
                       capture_output=True)
        u = raypipe.Unit.traverse(out)
        s = raypipe.read_set(out)
        rays, want = s["files"]["traverse_rays.hex"], s["files"]["traverse_expected.hex"]
        assert u.inputs == ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax"]
        assert u.outputs == [f["name"] for f in s["manifest"]["files"][1]["fields"]]
        assert np.array_equal(u.eval_batch(np.ascontiguousarray(rays[:, 1:])), want)
        r = u.eval([int(x) for x in rays[0, 1:]])
        assert [r[k] for k in u.outputs] == [int(x) for x in want[0]]
        with open(os.path.join(out, "tree_root.hex"), "a") as f:
            f.write("\n")
        with pytest.raises(ValueError, match="tree_root.hex"):
            raypipe.Unit.traverse(out)
    with pytest.raises(ValueError, match="manifest.json"):
        raypipe.Unit.traverse("/nonexistent/raypipe-set")


def test_eval_columns_equals_eval_batch_and_reuses_out():
    u = raypipe.Unit("rti", "f32", "--det-threshold 0.001")
    rng = np.random.default_rng(9)
    n = 5000
    cols = rng.uniform(-2, 2, size=(17, n)).astype(np.float32)
    cols[6], cols[7] = 0.0, 3.0
    cols[:, :50] = np.float32(np.nan)  # NaNs in every input of the first 50 tests
    rows = np.ascontiguousarray(cols.T).view(np.uint32).astype(np.uint64)
    want = u.eval_batch(rows)
    out = {k: np.zeros(n, dtype=bool) for k in ("valid", "hit")}
    out.update({k: np.zeros(n, dtype=np.float32) for k in "tuv"})
    got = u.eval_columns(cols, out=out)
    assert got["t"] is out["t"]
    assert np.array_equal(got["valid"], want[:, 0] == 1) and np.array_equal(got["hit"], want[:, 1] == 1)
    for k, c in (("t", 2), ("u", 3), ("v", 4)):
        assert np.array_equal(got[k].view(np.uint32), want[:, c].astype(np.uint32)), k
    assert got["hit"].sum() > 0
    fresh = u.eval_columns(cols)
    assert np.array_equal(fresh["t"].view(np.uint32), want[:, 2].astype(np.uint32))
    with pytest.raises(ValueError, match="f32"):
        raypipe.Unit("rti", "fp16").eval_columns(cols)
    with pytest.raises(ValueError, match="17"):
        u.eval_columns(cols[:16].copy())
    with pytest.raises(ValueError, match="not 5000"):
        u.eval_columns(cols, out={"t": np.zeros(10, dtype=np.float32)})
    with pytest.raises(ValueError, match="float32"):
        u.eval_columns(cols, out={"t": np.zeros(n, dtype=np.float64)})
    # a Fortran-ordered array is read in its logical order (copied), not its memory order
    f = u.eval_columns(np.asfortranarray(cols))
    assert np.array_equal(f["t"].view(np.uint32), want[:, 2].astype(np.uint32))
    assert np.array_equal(u.eval_batch(np.asfortranarray(rows)), want)


@pytest.mark.parametrize("unit,fmt,opts", [("rti", "fp16", []), ("slab", "bf16", ["--variant", "conservative"]), ("op", "f32", [])])
def test_cover_records_a_sets_rows_as_the_set_measures(unit, fmt, opts):
    """raypipe.Cover over a written set's input rows: `raypipe cover` of the file equals its
    coverage of the set, bin for bin, apart from the class bins (the file's hold `live`)."""
    import json
    exe = raypipe_binary()
    if exe is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "set")
        subprocess.run([exe, "vectors", "--unit", unit, "--format", fmt, *opts, "--count", "3", "--out", out], check=True,
                       capture_output=True)
        s = raypipe.read_set(out)
        ins = s["files"][s["manifest"]["files"][0]["name"]]
        c = raypipe.Cover(unit, fmt, " ".join(opts))
        for r in ins:
            c.add([int(x) for x in r[1:]])
        assert c.rows == len(ins)
        path = os.path.join(d, "live.json")
        c.write(path)

        def cov(p):
            j = json.loads(subprocess.run([exe, "cover", p, "--json"], check=True, capture_output=True, text=True).stdout)
            return {(p["role"], p["signal"]): [b["count"] for b in p["bins"]] for p in j["coverpoints"] if p["kind"] != "class"}, j

        live, jl = cov(path)
        want, jw = cov(out)
        assert live == want
        assert jl["vectors"] == jw["vectors"] == len(ins)
        with pytest.raises(ValueError):
            c.add([0])
        with pytest.raises(ValueError):
            raypipe.Cover("slab", fmt, "--variant directed")
        mine = os.path.join(d, "mine.json")
        with open(mine, "w") as f:
            f.write("mine")
        with pytest.raises(OSError):
            c.write(mine)
        assert open(mine).read() == "mine"
