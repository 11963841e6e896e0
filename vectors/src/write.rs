//! Writing a vector set: atomically into its directory, with every file's SHA-256 and the
//! generating commit in the manifest; refusing a directory raypipe did not write.

use crate::gen::*;
use crate::manifest::Manifest;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// SHA-256 of `data` as 64 lowercase hex digits (a manifest's file digests, a partial's digest).
pub fn sha256_hex(data: &[u8]) -> String {
    Sha256::digest(data).iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks, before any work, that `dir` can take a vector set: it does not exist (nothing is
/// created yet), is empty, or is a set raypipe wrote — its `manifest.json` reads as a raypipe
/// manifest and every entry is a regular file that manifest names (its data files, the
/// manifest, `raypipe_pkg.sv`, `raypipe_pkg.vhd`, and the AXI4-Stream wrapper's `axis_map.json` and
/// `raypipe_axis_wrap.sv`). Anything else is refused and left untouched.
pub fn check_out(dir: &Path) -> Result<(), String> {
    if !dir.exists() {
        return crate::outdir::OutDir::check(dir, &[]).map(|_| ());
    }
    if !dir.is_dir() {
        return Err(format!("{} exists and is not a directory", dir.display()));
    }
    let entries: Vec<std::fs::DirEntry> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    if entries.is_empty() {
        return Ok(());
    }
    let refuse = |why: String| {
        Err(format!(
            "{} is not a vector set raypipe wrote ({why}); refusing to replace it: choose another --out",
            dir.display()
        ))
    };
    let Ok(text) = std::fs::read_to_string(dir.join("manifest.json")) else {
        return refuse("no manifest.json".into());
    };
    let Ok(m) = serde_json::from_str::<Manifest>(&text) else {
        return refuse("its manifest.json is not a raypipe manifest".into());
    };
    let mut allowed: Vec<&str> = m.files.iter().map(|f| f.name.as_str()).collect();
    allowed.extend([
        "manifest.json",
        "raypipe_pkg.sv",
        "raypipe_pkg.vhd",
        crate::axis::MAP_FILE,
        crate::axis::WRAP_FILE,
    ]);
    for e in &entries {
        let name = e.file_name();
        let name = name.to_string_lossy();
        let file = e.file_type().map(|t| t.is_file()).unwrap_or(false);
        if !file || !allowed.contains(&name.as_ref()) {
            return refuse(format!("it holds {name}, which its manifest does not list"));
        }
    }
    Ok(())
}

/// Writes the set into `dir` (see [`check_out`] for what may be replaced): built in the
/// temporary sibling `.<dir>.raypipe-partial` (removed on SIGINT, and by the next run if left),
/// then renamed into place, so that an interrupted run never leaves a half set that looks whole.
pub fn write_set(set: &VectorSet, dir: &Path) -> Result<PathBuf, String> {
    write_set_with(set, dir, &[])
}

/// [`write_set`] plus `extra` (name, contents) files the manifest does not list (the
/// AXI4-Stream wrapper's map and module), written into the set before it is renamed into place.
pub fn write_set_with(set: &VectorSet, dir: &Path, extra: &[(String, String)]) -> Result<PathBuf, String> {
    use crate::outdir::{create_partial, partial_of, unregister_partial};
    check_out(dir)?;
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let tmp = partial_of(dir)?;
    const OWN: &str = ".raypipe-partial";
    if tmp.exists() {
        // an interrupted run's leftover (it holds the mark raypipe writes first)
        if !tmp.join(OWN).is_file() {
            return Err(format!(
                "{} exists and was not left by raypipe; remove it or choose another --out",
                tmp.display()
            ));
        }
        std::fs::remove_dir_all(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    }
    if let Err(e) = create_partial(&tmp, |t| std::fs::create_dir(t)) {
        unregister_partial(&tmp);
        return Err(format!("{}: {e}", tmp.display()));
    }
    let result = (|| {
        std::fs::write(tmp.join(OWN), "").map_err(|e| format!("{}: {e}", tmp.display()))?;
        let mut manifest = set.manifest.clone();
        for (fname, content) in &set.files {
            std::fs::write(tmp.join(fname), content).map_err(|e| format!("{fname}: {e}"))?;
            if let Some(m) = manifest.files.iter_mut().find(|m| &m.name == fname) {
                m.sha256 = sha256_hex(content.as_bytes());
            }
        }
        std::fs::write(tmp.join("raypipe_pkg.sv"), crate::hdl::sv_package(&manifest))
            .map_err(|e| format!("raypipe_pkg.sv: {e}"))?;
        std::fs::write(tmp.join("raypipe_pkg.vhd"), crate::hdl::vhdl_package(&manifest))
            .map_err(|e| format!("raypipe_pkg.vhd: {e}"))?;
        for (fname, content) in extra {
            std::fs::write(tmp.join(fname), content).map_err(|e| format!("{fname}: {e}"))?;
        }
        let json = serde_json::to_string_pretty(&manifest).map_err(|e| e.to_string())? + "\n";
        std::fs::write(tmp.join("manifest.json"), json).map_err(|e| format!("manifest.json: {e}"))?;
        std::fs::remove_file(tmp.join(OWN)).map_err(|e| format!("{}: {e}", tmp.display()))?;
        // the earlier set (checked above) goes aside, the new one into place, then the old is removed
        let old = parent.join(format!(".{}.raypipe-old", dir.file_name().unwrap_or_default().to_string_lossy()));
        if dir.exists() {
            check_out(dir)?;
            let _ = std::fs::remove_dir_all(&old);
            std::fs::rename(dir, &old).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        std::fs::rename(&tmp, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        if old.exists() {
            std::fs::remove_dir_all(&old).map_err(|e| format!("{}: {e}", old.display()))?;
        }
        Ok(dir.to_path_buf())
    })();
    if result.is_err() && tmp.exists() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    unregister_partial(&tmp);
    result
}
