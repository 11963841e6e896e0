#!/usr/bin/env python3
"""Checks dist/mutants/ledger.py's remapping on a throwaway repository: lines moved by an
insertion, a deletion and a change above them keep their outcomes at their new lines; mutants on
changed or deleted lines drop out. Run: python3 dist/mutants/ledger_test.py (exit 0 = pass)."""
import os
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ledger  # noqa: E402


def main():
    with tempfile.TemporaryDirectory() as d:
        os.chdir(d)

        def run(*a):
            subprocess.run(a, check=True, capture_output=True)

        run("git", "init", "-q")
        run("git", "config", "user.email", "t@example.com")
        run("git", "config", "user.name", "t")
        old = [f"line {i}" for i in range(1, 21)]
        open("f.rs", "w").write("\n".join(old) + "\n")
        run("git", "add", "f.rs")
        run("git", "commit", "-qm", "a")
        a = ledger.head()
        new = list(old)
        new[2:2] = ["inserted 1", "inserted 2"]  # two lines before old line 3
        new.remove("line 8")  # old line 8 deleted
        new[new.index("line 12")] = "changed 12"  # old line 12 changed
        new[new.index("line 15"):new.index("line 15") + 1] = ["split 15a", "split 15b", "split 15c"]
        open("f.rs", "w").write("\n".join(new) + "\n")
        run("git", "commit", "-qam", "b")
        b = ledger.head()
        led = {f"f.rs:{n}:5: replace + with - in f": "caught" for n in (1, 2, 3, 7, 8, 9, 12, 13, 15, 16, 20)}
        got = ledger.remap(led, a, b, "f.rs")
        want = {}
        for n, o in ((1, 1), (2, 2), (3, 5), (7, 9), (9, 10), (13, 14), (16, 19), (20, 23)):
            assert new[o - 1] == f"line {n}", (n, o, new[o - 1])
            want[f"f.rs:{o}:5: replace + with - in f"] = "caught"
        assert got == want, (got, want)
        # the working tree (to = None) and an unchanged commit
        assert ledger.remap(led, b, None, "f.rs") == led
        assert ledger.remap(led, a, a, "f.rs") == led
    print("ledger_test: ok")


if __name__ == "__main__":
    main()
