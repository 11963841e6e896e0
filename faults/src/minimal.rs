//! Minimal vector sets: the fewest vectors of a set, found by greedy set cover over the fault
//! bank, that still detect every fault the whole set detects from the outputs.
//!
//! Greedy cover: start with no vector; repeatedly keep the vector that detects the most faults
//! not yet detected by the kept ones (on a tie, the lowest row), until every fault the set
//! detects is detected. The kept rows stay in their original order. Greedy is within a factor
//! ln(faults) + 1 of the smallest cover; the set is "the smallest found", not proven smallest.

use crate::campaign::{run, Campaign};
use vectors::gen::VectorSet;
use vectors::manifest::Minimal;
use vectors::read::set_rows;

/// A minimal set cut from `set`, and the campaign over it (every fault the whole set detects
/// from the outputs is detected by it). `command` is recorded in its manifest.
pub fn minimal(set: &VectorSet, command: &str) -> Result<(VectorSet, Campaign), String> {
    let rows = set_rows(set)?;
    let m = &set.manifest;
    let full = run(m, &rows, true)?;
    let n = rows.first().map_or(0, |r| r.len());
    // per vector, the faults it detects
    let mut catches: Vec<Vec<usize>> = vec![Vec::new(); n];
    let target: Vec<usize> = (0..full.faults.len()).filter(|&k| full.faults[k].detected).collect();
    for &k in &target {
        for &v in &full.faults[k].catching {
            catches[v].push(k);
        }
    }
    let mut covered = vec![false; full.faults.len()];
    let mut left = target.len();
    let mut keep = Vec::new();
    while left > 0 {
        let gain = |v: usize| catches[v].iter().filter(|&&k| !covered[k]).count();
        let best = (0..n).max_by_key(|&v| (gain(v), std::cmp::Reverse(v))).ok_or("the set is empty")?;
        if gain(best) == 0 {
            return Err("internal: a detected fault has no catching vector".into());
        }
        for &k in &catches[best] {
            if !covered[k] {
                covered[k] = true;
                left -= 1;
            }
        }
        keep.push(best);
    }
    keep.sort_unstable();
    let mut cut = subset(set, &rows[0], &keep, command)?;
    cut.manifest.minimal = Some(Minimal {
        from_vectors: n,
        detects: target.iter().map(|&k| full.faults[k].name.to_string()).collect(),
        outputs_only: true,
    });
    // the cut set must detect what the whole set detects
    let c = run(&cut.manifest, &set_rows(&cut)?, true)?;
    let missed: Vec<&str> = c
        .faults
        .iter()
        .filter(|o| !o.detected)
        .map(|o| o.name)
        .filter(|name| target.iter().any(|&k| full.faults[k].name == *name))
        .collect();
    if !missed.is_empty() {
        return Err(format!("internal: the minimal set misses {}", missed.join(", ")));
    }
    Ok((cut, c))
}

/// The rows `keep` (ascending) of `set`'s per-vector files (inputs, expected outputs, stage
/// signals), the other files (a traverse set's tree images) whole; class counts recounted from
/// `inputs` (the set's input rows, unpacked).
fn subset(set: &VectorSet, inputs: &[Vec<u64>], keep: &[usize], command: &str) -> Result<VectorSet, String> {
    let mut out = set.clone();
    let m = &mut out.manifest;
    m.command = command.to_string();
    let per_vector: Vec<usize> = m
        .files
        .iter()
        .enumerate()
        .filter(|(i, f)| *i < 2 || f.role == vectors::hdl::STAGE_ROLE)
        .map(|(i, _)| i)
        .collect();
    for &i in &per_vector {
        let name = m.files[i].name.clone();
        let (_, text) = out.files.iter_mut().find(|(n, _)| *n == name).ok_or(format!("{name}: not in the set"))?;
        let lines: Vec<&str> = text.lines().collect();
        let kept: Vec<&str> = keep.iter().map(|&k| lines[k]).collect();
        *text = kept.join("\n") + "\n";
        m.files[i].rows = keep.len();
    }
    for c in m.classes.iter_mut() {
        c.count = keep.iter().filter(|&&k| inputs[k].first() == Some(&(c.id as u64))).count();
    }
    Ok(out)
}
