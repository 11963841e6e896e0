//! Partial results of sharded runs (`--shard K/N --partial FILE`) and their merge
//! (`raypipe merge`): a shard writes what it accumulated over its chunks with everything that
//! identifies the run; the merge checks that the partials belong to one run and that every
//! shard is there exactly once, then adds the accumulators up and reports as the unsharded run
//! would.
//!
//! A partial file is JSON: `raypipe_partial` (format version 1), `version` (raypipe's),
//! `command` (e.g. `verify`), `args` (every option that changes the results, canonical),
//! `scene_hash` (FNV-1a 64 over the scene's triangle coordinates' binary64 encodings, hex),
//! `chunk` (items per chunk: the shard split depends on it), `shard` (`k`, `n`) and `data`
//! (the command's accumulators).

use engine::Shard;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The partial file format's version.
pub const FORMAT: u32 = 1;

/// One shard's partial result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Partial<T> {
    /// The partial file format's version ([`FORMAT`]).
    pub raypipe_partial: u32,
    /// The raypipe version that wrote it.
    pub version: String,
    /// The command (`verify`, …).
    pub command: String,
    /// Every option that changes the results.
    pub args: serde_json::Value,
    /// The scene's hash ([`scene_hash`]).
    pub scene_hash: String,
    /// Items per chunk.
    pub chunk: u64,
    /// Which shard.
    pub shard: Shard,
    /// The command's accumulators.
    pub data: T,
}

impl<T> Partial<T> {
    /// One shard's result of `command`, stamped with this partial format and raypipe version.
    pub fn new(command: &str, args: serde_json::Value, scene_hash: String, chunk: u64, shard: Shard, data: T) -> Self {
        Partial {
            raypipe_partial: FORMAT,
            version: env!("CARGO_PKG_VERSION").to_string(),
            command: command.into(),
            args,
            scene_hash,
            chunk,
            shard,
            data,
        }
    }
}

/// FNV-1a 64 over the binary64 encodings of every triangle coordinate, in order, as 16 hex
/// digits.
pub fn scene_hash(scene: &crate::scene::Scene) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for t in &scene.tris {
        for p in &t.v {
            for x in p {
                for b in x.to_bits().to_le_bytes() {
                    h ^= b as u64;
                    h = h.wrapping_mul(0x0000_0100_0000_01b3);
                }
            }
        }
    }
    format!("{h:016x}")
}

/// Refuses an output path raypipe may not write, before any work: a directory, a missing
/// parent directory, or an existing file that is not a raypipe partial.
pub fn check_path(path: &Path) -> Result<(), String> {
    let shown = path.display();
    if path.is_dir() {
        return Err(format!("--partial {shown} is a directory"));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(format!("--partial {shown}: no directory {}", parent.display()));
    }
    if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| format!("--partial {shown}: {e}"))?;
        let ours = serde_json::from_str::<serde_json::Value>(&text).is_ok_and(|v| v.get("raypipe_partial").is_some());
        if !ours {
            return Err(format!("--partial {shown} exists and is not a raypipe partial: not replacing it"));
        }
    }
    Ok(())
}

/// Writes `p` to `path` atomically (a sibling temporary file renamed into place).
pub fn write<T: Serialize>(path: &Path, p: &Partial<T>) -> Result<(), String> {
    check_path(path)?;
    let text = serde_json::to_string(p).map_err(|e| e.to_string())?;
    let name = path.file_name().ok_or_else(|| format!("--partial {}: not a file name", path.display()))?;
    let tmp: PathBuf = path.with_file_name(format!(".{}.raypipe-partial", name.to_string_lossy()));
    std::fs::write(&tmp, text + "\n").map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}

/// Reads partial files and checks that they are the shards of one run, each exactly once:
/// same format version, raypipe version, command, options, scene and chunk size, one shard
/// count N and every shard 0..N present once. Returns them in shard order.
pub fn read_all(paths: &[PathBuf]) -> Result<Vec<Partial<serde_json::Value>>, String> {
    if paths.is_empty() {
        return Err("name the partial files to merge".into());
    }
    let mut parts = Vec::new();
    for p in paths {
        let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
        let part: Partial<serde_json::Value> = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a raypipe partial (corrupt or truncated?): {e}", p.display()))?;
        if part.raypipe_partial != FORMAT {
            return Err(format!(
                "{}: partial format {} (this raypipe reads {FORMAT})",
                p.display(),
                part.raypipe_partial
            ));
        }
        parts.push((p.clone(), part));
    }
    let (p0, first) = &parts[0];
    let version = env!("CARGO_PKG_VERSION");
    if first.version != version {
        return Err(format!("{}: written by raypipe {}, this is {version}", p0.display(), first.version));
    }
    for (p, q) in &parts[1..] {
        let differs = |what: &str| {
            Err(format!("{} is not a shard of the same run as {}: its {what} differs", p.display(), p0.display()))
        };
        if q.version != first.version {
            return differs("raypipe version");
        }
        if q.command != first.command {
            return differs("command");
        }
        if q.args != first.args {
            return differs("options");
        }
        if q.scene_hash != first.scene_hash {
            return differs("scene");
        }
        if q.chunk != first.chunk {
            return differs("chunk size");
        }
        if q.shard.n != first.shard.n {
            return differs("shard count");
        }
    }
    let n = first.shard.n;
    let mut seen: Vec<Option<&PathBuf>> = vec![None; n as usize];
    for (p, q) in &parts {
        if q.shard.k >= n {
            return Err(format!("{}: shard {} of {n} does not exist", p.display(), q.shard));
        }
        if let Some(other) = seen[q.shard.k as usize] {
            return Err(format!("shard {} given twice: {} and {}", q.shard, other.display(), p.display()));
        }
        seen[q.shard.k as usize] = Some(p);
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, s)| s.is_none()).map(|(k, _)| format!("{k}/{n}")).collect();
    if !missing.is_empty() {
        return Err(format!("missing shard(s) {} of the run", missing.join(", ")));
    }
    parts.sort_by_key(|(_, q)| q.shard.k);
    Ok(parts.into_iter().map(|(_, q)| q).collect())
}

/// The typed data of a checked partial.
pub fn data<T: DeserializeOwned>(p: &Partial<serde_json::Value>) -> Result<T, String> {
    serde_json::from_value(p.data.clone())
        .map_err(|e| format!("shard {}: its data is not a {} result: {e}", p.shard, p.command))
}

/// The checked partials' data, typed and added up in shard order by `add`.
pub fn merge_data<T: DeserializeOwned>(
    parts: &[Partial<serde_json::Value>],
    add: impl Fn(&mut T, T) -> Result<(), String>,
) -> Result<T, String> {
    let mut total: Option<T> = None;
    for p in parts {
        let d: T = data(p)?;
        match total.as_mut() {
            Some(t) => add(t, d)?,
            None => total = Some(d),
        }
    }
    total.ok_or_else(|| "name the partial files to merge".to_string())
}
