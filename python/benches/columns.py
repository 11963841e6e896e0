"""The Python speed row of issue 19: f32 RTI on 1,048,576 pairs through `eval_columns` (columns,
outputs reused) and `eval_batch` (rows), against the Rust kernel's rows of `raypipe speed` in
the same run (one pass over 1 M-pair columns, and the same pairs streamed through L1 chunks).

    python3 python/benches/columns.py [RAYPIPE]      (RAYPIPE: the raypipe binary)
"""

import json
import os
import subprocess
import sys
import time

import numpy as np

import raypipe

n = 1 << 20
u = raypipe.Unit("rti", "f32")
rng = np.random.default_rng(1)
cols = rng.uniform(-1, 1, size=(17, n)).astype(np.float32)
cols[6], cols[7] = 0.0, 10.0
out = {k: np.zeros(n, dtype=bool) for k in ("valid", "hit")} | {k: np.zeros(n, dtype=np.float32) for k in "tuv"}
rows = np.ascontiguousarray(cols.T).view(np.uint32).astype(np.uint64)


def best(f, reps=7):
    b = float("inf")
    for _ in range(reps):
        t = time.perf_counter()
        f()
        b = min(b, time.perf_counter() - t)
    return n / b / 1e6


col_rate = best(lambda: u.eval_columns(cols, out=out))
row_rate = best(lambda: u.eval_batch(rows), 3)
exe = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..", "target", "release", "raypipe")
speed = json.loads(subprocess.run([exe, "speed", "--json"], check=True, capture_output=True, text=True).stdout)
rust = {r["name"]: r["mtests_per_s"] for r in speed["rows"]}
one = rust["rti f32 kernel, one pass over 1 M-pair columns"]
streamed = rust["rti f32 kernel, 1 M pairs streamed through L1 chunks"]
print(f"python eval_columns f32 rti, 1 M pairs: {col_rate:.1f} M tests/s "
      f"({col_rate / one:.2f} of the Rust kernel's one pass, {one:.1f}; {col_rate / streamed:.2f} of its L1-chunk stream, {streamed:.1f})")
print(f"python eval_batch f32 rti, 1 M rows: {row_rate:.1f} M tests/s")
