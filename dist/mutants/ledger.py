"""Mutation ledgers: every mutant's latest outcome for one source file, at one commit.

A ledger is DIR/<file-slug>/ledger.json ({mutant name: outcome}) with the commit its names
belong to in ledger.commit. A mutant's name holds its line and column, so a ledger read at
another commit is *remapped*: each line moves as `git diff -U0` between the two commits moves
it, and a mutant on a line the diff changed is dropped (its code changed: it must be judged
again). Ledgers written before ledger.commit existed take the commit that was HEAD when they
were last written.
"""
import json
import os
import re
import subprocess

OUTCOMES = ("caught", "missed", "timeout", "unviable")


def score(n):
    """The detected share of the viable mutants in percent, one decimal ("" when none is
    viable), from counts by outcome: a timeout (a test run that hangs fails CI) is detected."""
    viable = n["caught"] + n["missed"] + n["timeout"]
    return f"{100 * (n['caught'] + n['timeout']) / viable:.1f}" if viable else ""


def git(*args):
    return subprocess.run(["git", *args], check=True, capture_output=True, text=True).stdout


def line_map(frm, to, path):
    """old line -> new line (None: changed) from commit `frm` to commit `to` (None: the
    working tree) for one file."""
    diff = git("diff", "-U0", frm, *([to] if to else []), "--", path)
    hunks = []
    for m in re.finditer(r"^@@ -(\d+)(?:,(\d+))? \+(\d+)(?:,(\d+))? @@", diff, re.M):
        a, b = int(m.group(1)), int(m.group(2) or 1)
        c, d = int(m.group(3)), int(m.group(4) or 1)
        # with a count of 0 the start is the line before the insertion / deletion
        hunks.append((a if b else a + 1, b, c if d else c + 1, d))

    def f(line):
        shift = 0
        for a, b, c, d in hunks:
            if line < a:
                break
            if line < a + b:
                return None
            shift = (c + d) - (a + b)
        return line + shift

    return f


def remap(led, frm, to, path):
    """A ledger's names moved from commit `frm` to `to` (None: the working tree)."""
    if frm == to:
        return dict(led)
    f = line_map(frm, to, path)
    out = {}
    for name, outcome in led.items():
        p, line, col, rest = name.split(":", 3)
        new = f(int(line))
        if new is not None:
            out[f"{p}:{new}:{col}:{rest}"] = outcome
    return out


def head():
    return git("rev-parse", "HEAD").strip()


def read(d):
    """(commit, time written, {name: outcome}) of the results in one file's directory: its
    ledger, or (runs from before ledgers) the outcome lists of cargo-mutants' last run."""
    p = os.path.join(d, "ledger.json")
    if os.path.exists(p):
        led, t = json.load(open(p)), os.path.getmtime(p)
    else:
        led, t = {}, 0.0
        # cargo-mutants' --iterate lists the mutants an earlier run caught as previously caught
        for outcome, name in [("caught", "previously_caught")] + [(o, o) for o in OUTCOMES]:
            q = os.path.join(d, "mutants.out", name + ".txt")
            if os.path.exists(q):
                t = max(t, os.path.getmtime(q))
                led.update((m, outcome) for m in open(q).read().splitlines() if m.strip())
    c = os.path.join(d, "ledger.commit")
    if os.path.exists(c):
        commit = open(c).read().strip()
    elif led:
        commit = git("rev-list", "-1", f"--before=@{int(t)}", "HEAD").strip()
    else:
        commit = None
    return commit, t, led


def write(d, commit, led):
    """Writes the ledger and its commit atomically."""
    for name, text in (("ledger.json", json.dumps(led, indent=0, sort_keys=True)), ("ledger.commit", commit + "\n")):
        tmp = os.path.join(d, name + ".tmp")
        with open(tmp, "w") as fh:
            fh.write(text)
        os.replace(tmp, os.path.join(d, name))
