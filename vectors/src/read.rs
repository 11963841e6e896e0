//! Reading a written set back: its files parsed by the manifest's fields, and every row
//! recomputed by the models from the set's own inputs and options ([`crate::check`] runs it).

use crate::gen::*;
use crate::manifest::Manifest;
use crate::pack::unpack;
use crate::write::sha256_hex;
use datapath::fault::NoFault;
use datapath::rti::{Rti, RtiConfig};
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};
use std::path::Path;

/// Reads every data file the manifest lists, checking its hash, digit count and row count.
pub fn read_files(dir: &Path, m: &Manifest) -> Result<Vec<Vec<Vec<u64>>>, String> {
    let mut contents = Vec::new();
    for fm in &m.files {
        let c = std::fs::read_to_string(dir.join(&fm.name)).map_err(|e| format!("{}: {e}", fm.name))?;
        if sha256_hex(c.as_bytes()) != fm.sha256 {
            return Err(format!("{}: sha256 differs from the manifest", fm.name));
        }
        contents.push(parse_rows(fm, &c)?);
    }
    Ok(contents)
}

/// The rows of a generated set's files (in the manifest's order), unpacked into fields.
pub fn set_rows(set: &VectorSet) -> Result<Vec<Vec<Vec<u64>>>, String> {
    set.manifest
        .files
        .iter()
        .map(|fm| {
            let text = set.files.iter().find(|(n, _)| *n == fm.name).map(|(_, t)| t.as_str());
            parse_rows(fm, text.ok_or(format!("{}: not in the set", fm.name))?)
        })
        .collect()
}

/// One file's rows, each unpacked into its fields (widths from the manifest).
pub(crate) fn parse_rows(fm: &crate::manifest::File, c: &str) -> Result<Vec<Vec<u64>>, String> {
    let rows: Vec<Vec<u64>> = c
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if l.len() != fm.digits as usize {
                return Err(format!(
                    "{} line {}: {} hex digits, the manifest says {}",
                    fm.name,
                    i + 1,
                    l.len(),
                    fm.digits
                ));
            }
            unpack(l, &fm.fields.iter().map(|x| x.width).collect::<Vec<_>>())
                .map_err(|e| format!("{} line {}: {e}", fm.name, i + 1))
        })
        .collect::<Result<_, _>>()?;
    if rows.len() != fm.rows {
        return Err(format!("{}: {} rows, manifest says {}", fm.name, rows.len(), fm.rows));
    }
    Ok(rows)
}

/// Re-runs the model on every input row and compares every expected and stage row bit for
/// bit (the manifest already checked against this raypipe's). Returns the vectors checked.
pub(crate) fn check_rows(
    m: &Manifest,
    unit: Unit,
    any: AnyFormat,
    contents: &[Vec<Vec<u64>>],
) -> Result<usize, String> {
    // the inputs' class ids and the counts the manifest gives them
    if let Some(inputs) = contents.first() {
        for c in &m.classes {
            let n = inputs.iter().filter(|r| r.first() == Some(&(c.id as u64))).count();
            if n != c.count {
                return Err(format!(
                    "manifest.json: class {} ({}) has count {}, the inputs hold {n}",
                    c.id, c.name, c.count
                ));
            }
        }
        if let Some((i, r)) =
            inputs.iter().enumerate().find(|(_, r)| !m.classes.iter().any(|c| r.first() == Some(&(c.id as u64))))
        {
            return Err(format!(
                "{} line {}: class {} is not in the manifest",
                m.files[0].name,
                i + 1,
                r.first().copied().unwrap_or(0)
            ));
        }
    }
    if unit == Unit::Traverse {
        return with_format!(any, |f| check_traverse(f, m, contents));
    }
    with_format!(any, |f| {
        let n = contents[0].len();
        for (i, input) in contents[0].iter().enumerate() {
            let (class, bits) = (input[0], &input[1..]);
            let want: Vec<Vec<u64>> = match unit {
                Unit::Rti => {
                    let rti = Rti::new(f, rti_config_from(m)?);
                    rti_rows(&rti, class, bits)[1..].to_vec()
                }
                Unit::Slab => slab_rows(&Slab::new(f, slab_config_from(m)?), class, bits)[1..].to_vec(),
                Unit::Capture => crate::capture::out_rows(&capture_rti_from(f, m), bits, &NoFault).to_vec(),
                Unit::Op => {
                    let (res, cmp) = op_eval(&f, bits[0], f.from_bits(bits[1]), f.from_bits(bits[2]));
                    vec![vec![res, cmp]]
                }
                Unit::Traverse => unreachable!("checked above"),
            };
            for (k, w) in want.iter().enumerate() {
                if &contents[k + 1][i] != w {
                    let fm = &m.files[k + 1];
                    let bad = fm
                        .fields
                        .iter()
                        .zip(w.iter().zip(&contents[k + 1][i]))
                        .find(|(_, (a, b))| a != b)
                        .map(|(x, _)| x.name.clone());
                    return Err(format!(
                        "{} line {}: field {} differs from the model",
                        fm.name,
                        i + 1,
                        bad.unwrap_or_default()
                    ));
                }
            }
        }
        Ok(n)
    })
}

/// One level's left and right bank rows.
pub type BankImages<'a> = (&'a Vec<Vec<u64>>, &'a Vec<Vec<u64>>);

/// A traverse set's BRAM images: the root entry row and each level's two banks, by file name.
pub fn tree_images<'a>(
    m: &Manifest,
    contents: &'a [Vec<Vec<u64>>],
) -> Result<(&'a [u64], Vec<BankImages<'a>>), String> {
    let idx = |name: &str| m.files.iter().position(|x| x.name == name);
    let levels = m.params.get("levels").copied().ok_or("manifest.json: params has no levels")? as usize;
    let root = idx("tree_root.hex").and_then(|i| contents.get(i)?.first()).ok_or("the set has no tree_root.hex row")?;
    let mut banks = Vec::new();
    for l in 0..levels {
        let (Some(a), Some(b)) = (idx(&format!("tree_l{l}_left.hex")), idx(&format!("tree_l{l}_right.hex"))) else {
            return Err(format!("the set lacks the level {l} bank images"));
        };
        banks.push((&contents[a], &contents[b]));
    }
    Ok((root, banks))
}

/// The traverse unit's check: the tree comes from the set's own BRAM images.
pub(crate) fn check_traverse<F: Format>(f: F, m: &Manifest, contents: &[Vec<Vec<u64>>]) -> Result<usize, String> {
    let n = m.params.get("leaves").copied().ok_or("manifest has no leaves parameter")? as usize;
    let (root, images) = tree_images(m, contents)?;
    let banks: Vec<_> = images.into_iter().map(|(a, b)| (a.clone(), b.clone())).collect();
    let variant = m.options.get("variant").map_or("plain", |s| s.as_str());
    let want = crate::traverse::recheck(f, variant, n, root, &banks, &contents[0])?;
    for (i, w) in want.iter().enumerate() {
        if &contents[1][i] != w {
            let fm = &m.files[1];
            let bad = fm
                .fields
                .iter()
                .zip(w.iter().zip(&contents[1][i]))
                .find(|(_, (a, b))| a != b)
                .map(|(x, _)| x.name.clone());
            return Err(format!(
                "{} line {}: field {} differs from the model",
                fm.name,
                i + 1,
                bad.unwrap_or_default()
            ));
        }
    }
    Ok(want.len())
}

/// The slab variant a set's manifest names (`plain` when it names none).
pub fn slab_config_from(m: &Manifest) -> Result<SlabConfig, String> {
    SlabConfig::named(m.options.get("variant").map_or("plain", |s| s.as_str()))
}

/// The min-capture tie rule a set's manifest names (`first` when it names none).
pub(crate) fn tie_from(m: &Manifest) -> datapath::rti::TieRule {
    match m.options.get("tie").map(String::as_str) {
        Some("Last") => datapath::rti::TieRule::Last,
        _ => datapath::rti::TieRule::First,
    }
}

/// The unit a capture set's manifest names: an RTI unit of format `f` with its tie rule (the
/// min-capture unit reads nothing else of it).
pub fn capture_rti_from<F: Format>(f: F, m: &Manifest) -> Rti<F> {
    Rti::new(f, RtiConfig { tie: tie_from(m), ..RtiConfig::default() })
}

/// The RTI unit's configuration a set's manifest names (cull, det threshold, tie rule).
pub fn rti_config_from(m: &Manifest) -> Result<RtiConfig, String> {
    use datapath::rti::Cull;
    let cull = match m.options.get("cull").map(String::as_str) {
        Some("Backface") => Cull::Backface,
        _ => Cull::TwoSided,
    };
    let tie = tie_from(m);
    let det_threshold = m
        .options
        .get("det_threshold")
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .ok_or("manifest has no det_threshold")?;
    Ok(RtiConfig { cull, det_threshold, tie })
}
