"""Shared by raypipe's cocotb testbenches (test_raypipe.py, test_axis.py): the row layouts of a
set's manifest, packing and unpacking rows, the random stimulus, and the first field that
differs under the manifest's care rules.

Stimulus per vector: aimed rays (45 %), random geometry (15 %), aimed rays with one to three
inputs replaced by an edge encoding (30 %: ±0, ±inf, NaNs with random sign and payload,
subnormals, ±min normal, ±max), ties (10 %: rti dy·e2z exactly halfway between neighbours).
"""


def fields(manifest, suffix):
    f = next(f for f in manifest["files"] if f["name"].endswith(suffix))
    return f["fields"]


def pack(values, widths):
    word = 0
    for v, w in zip(values, widths):
        word = (word << w) | (int(v) & ((1 << w) - 1))
    return word


def unpack(word, widths):
    out = []
    for w in reversed(widths):
        out.append(word & ((1 << w) - 1))
        word >>= w
    return out[::-1]


class Stimulus:
    def __init__(self, model, manifest, rng):
        self.m, self.rng = model, rng
        p = manifest["params"]
        self.exp, self.man, self.w = int(p["exp"]), int(p["man"]), model.width
        self.rti = len(model.inputs) == 17

    def edge(self):
        r, e, m, w = self.rng, self.exp, self.man, self.w
        s = r.randrange(2) << (w - 1)
        top = (1 << e) - 1
        frac = r.getrandbits(m) | 1
        return s | r.choice([
            0, top << m, (top << m) | frac, frac, ((top - 1) << m) | ((1 << m) - 1), 1 << m, 1, (1 << m) - 1,
            (r.randrange(1, top) << m) | r.getrandbits(m),
        ])

    def vector(self):
        r = self.rng
        u = lambda a, b: r.uniform(a, b)
        mode = r.randrange(100)
        kind = "aimed" if mode < 45 else "random" if mode < 60 else "edge" if mode < 90 else "tie"
        o = [u(-2, 2) for _ in range(3)]
        if self.rti:
            v = [u(-1, 1) for _ in range(9)]
            a = u(0, 1)
            b = u(0, 1 - a)
            p = [v[i] + a * (v[3 + i] - v[i]) + b * (v[6 + i] - v[i]) for i in range(3)]
            d = [u(-1, 1) for _ in range(3)] if kind == "random" else [p[i] - o[i] for i in range(3)]
            x = o + d + [0.0, u(0.5, 4.0)] + v
            if kind == "tie":
                k = r.randrange(1, self.man + 1)
                x[4], x[10], x[16] = 1 + 2.0**-k, 0.0, 1 + 2.0 ** -(self.man + 1 - k)
        else:
            c = [u(-1, 1) for _ in range(3)]
            h = [u(0.01, 0.5) for _ in range(3)]
            p = [c[i] + u(-1, 1) * h[i] for i in range(3)]
            d = [u(-1, 1) for _ in range(3)] if kind == "random" else [p[i] - o[i] for i in range(3)]
            x = o + d + [0.0, u(0.5, 4.0)] + [c[i] - h[i] for i in range(3)] + [c[i] + h[i] for i in range(3)]
        row = [self.m.encode(t) for t in x]
        if kind == "edge":
            for _ in range(r.randrange(1, 4)):
                row[r.randrange(len(row))] = self.edge()
        return row, kind


def differs(got, want, flds, outs):
    """The first field that differs (the manifest's order), skipping fields whose care_when flag
    is 0 in the expected outputs; None if none."""
    for g, w, f in zip(got, want, flds):
        cw = f.get("care_when")
        if cw is not None and not outs[cw]:
            continue
        if g != w:
            return f"{f['name']} (stage {f.get('stage')})"
    return None
