"""`raypipe cover --ucis FILE`: the coverage as UCIS 1.0 XML that pyucis reads back with the
same totals as raypipe's own JSON (reachable bins, bins hit, unreachable bins as ignore bins),
also for several sets merged."""

import json
import os
import shutil
import subprocess

import pytest

pytest.importorskip("ucis")
from ucis.cover_type_t import CoverTypeT  # noqa: E402
from ucis.scope_type_t import ScopeTypeT  # noqa: E402
from ucis.xml.xml_factory import XmlFactory  # noqa: E402


def exe():
    e = os.environ.get("RAYPIPE") or shutil.which("raypipe")
    if e is None:
        pytest.skip("no raypipe binary (cargo build --release, or set RAYPIPE)")
    return e


def ucis_totals(path):
    """(bins hit, bins, ignore bins, coverpoints) as pyucis reads the file."""
    db = XmlFactory.read(str(path))
    hit = total = ignored = points = 0
    for inst in db.scopes(ScopeTypeT.INSTANCE):
        for cg in inst.scopes(ScopeTypeT.COVERGROUP):
            for cgi in cg.scopes(ScopeTypeT.COVERINSTANCE):
                for cp in cgi.scopes(ScopeTypeT.COVERPOINT):
                    points += 1
                    for ci in cp.coverItems(CoverTypeT.CVGBIN):
                        total += 1
                        hit += ci.getCoverData().data > 0
                    for ci in cp.coverItems(CoverTypeT.IGNOREBIN):
                        ignored += 1
    return hit, total, ignored, points


@pytest.mark.parametrize("unit,fmt,opts", [
    ("rti", "fp16", []),
    ("slab", "f32:ftz", ["--variant", "plain"]),
    ("op", "bf16", []),
])
def test_pyucis_reads_the_totals_raypipe_reports(unit, fmt, opts, tmp_path):
    e = exe()
    sets = []
    for seed in ("1", "2"):
        d = tmp_path / f"set{seed}"
        subprocess.run([e, "vectors", "--unit", unit, "--format", fmt, *opts, "--count", "2", "--seed", seed,
                        "--out", str(d)], check=True, capture_output=True)
        sets.append(str(d))
    for chosen in (sets[:1], sets):
        xml = tmp_path / f"cov{len(chosen)}.xml"
        p = subprocess.run([e, "cover", *chosen, "--ucis", str(xml), "--json"], check=True, capture_output=True,
                           text=True)
        j = json.loads(p.stdout)
        hit, total, ignored, points = ucis_totals(xml)
        assert (hit, total, ignored) == (j["bins_hit"], j["bins"], j["bins_unreachable"]), (unit, fmt, chosen)
        assert points == len(j["coverpoints"])
        assert 0 < hit <= total
