//! Partial results of sharded runs (`--shard K/N --partial FILE`) and their merge
//! (`raypipe merge`): a shard writes what it accumulated over its chunks with everything that
//! identifies the run; the merge checks that the partials belong to one run and that every
//! shard is there exactly once, then adds the accumulators up and reports as the unsharded run
//! would.
//!
//! A partial file is JSON: `raypipe_partial` (format version, [`FORMAT`]), `version` (raypipe's),
//! `command` (e.g. `verify`), `args` (every option that changes the results, canonical),
//! `scene_hash` (FNV-1a 64 over the scene's triangle coordinates' binary64 encodings, hex),
//! `chunk` (items per chunk: the shard split depends on it), `shard` (`k`, `n`), `data`
//! (the command's accumulators) and, written last, `digest`: the SHA-256 of the file's bytes
//! with the digest member removed (see [`seal`]).
//!
//! Before a partial is merged it is checked twice (docs/cluster.md, "Integrity"): its digest
//! must match its bytes (a file damaged in transit or edited by hand), and its data must be
//! consistent ([`Consistent`]: counts within their totals, a first-violation record exactly
//! when violations are counted, histogram totals equal to their counts, the test counts those
//! of the shard's share of the run). The digest is no signature: whoever edits a partial on
//! purpose can recompute it.

use engine::Shard;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use vectors::write::sha256_hex;

/// The partial file format's version (2: the `digest` member and the consistency rules; 3:
/// verify's counters by name).
pub const FORMAT: u32 = 3;

/// The member a partial file ends with: `,"digest":"` 64 lowercase hex digits `"}`.
const DIGEST_KEY: &str = ",\"digest\":\"";

/// What a command's partial data must satisfy before it is merged.
pub trait Consistent {
    /// Checks one shard's data; `share(lo, hi)` is how many of the run's items `lo..hi` the
    /// shard ran (the engine's chunk split of the partial's `chunk` and `shard`).
    fn check(&self, share: &dyn Fn(u64, u64) -> u64) -> Result<(), String>;
}

/// A command whose runs shard (`--shard K/N --partial FILE`, then `raypipe merge`): what a
/// shard accumulates (this type, a partial's `data`), how shards add up, and the report. A new
/// sharded command is one impl of this trait and of [`Consistent`].
pub trait Sharded: Serialize + DeserializeOwned + Consistent {
    /// The command (a partial's `command`).
    const COMMAND: &'static str;
    /// The report of the whole run.
    type Report: Serialize;
    /// Adds another shard's data of the same run (refused when it is not).
    fn add(&mut self, other: Self) -> Result<(), String>;
    /// The report of (merged) data.
    fn finish(self) -> Result<Self::Report, String>;
    /// The report as text.
    fn render(report: &Self::Report) -> String;
    /// The report's exit outcome.
    fn outcome(report: &Self::Report) -> crate::Outcome;
}

/// An error unless `ok`: the inconsistency `what`.
pub fn require(ok: bool, what: impl FnOnce() -> String) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(what())
    }
}

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
    /// The file it was read from (not part of the file).
    #[serde(skip)]
    pub file: PathBuf,
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
            file: PathBuf::new(),
        }
    }
}

/// The file text of a partial whose JSON (one object, no trailing newline) is `body`: the
/// body with the member `"digest":"<SHA-256 of body, hex>"` appended as its last member, then
/// a newline. The digest covers exactly the bytes of `body`.
pub fn seal(body: &str) -> String {
    let open = body.strip_suffix('}').expect("a JSON object");
    format!("{open}{DIGEST_KEY}{}\"}}\n", sha256_hex(body.as_bytes()))
}

/// The body of a sealed partial file after checking its digest: the text without its final
/// newline and without the last member `,"digest":"…"`, whose SHA-256 must be that digest.
pub fn unseal(text: &str) -> Result<String, String> {
    let t = text.strip_suffix('\n').unwrap_or(text);
    let at = t.rfind(DIGEST_KEY).ok_or("it has no digest (its last member must be \"digest\")")?;
    let hex = &t[at + DIGEST_KEY.len()..];
    let hex = hex.strip_suffix("\"}").ok_or("its digest is not its last member")?;
    if hex.len() != 64 || !hex.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)) {
        return Err("its digest is not 64 lowercase hex digits".into());
    }
    // the body is the text up to the digest member, closed again
    let body = format!("{}}}", &t[..at]);
    let got = sha256_hex(body.as_bytes());
    if got != hex {
        return Err(format!(
            "its digest does not match its content (damaged or edited after it was written): the file says {hex}, its content hashes to {got}"
        ));
    }
    Ok(body)
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
    let ours =
        |text: &str| serde_json::from_str::<serde_json::Value>(text).is_ok_and(|v| v.get("raypipe_partial").is_some());
    vectors::outdir::check_file_out("--partial", path, ours, "is not a raypipe partial")
}

/// Writes `p` to `path` atomically (a sibling temporary file renamed into place).
pub fn write<T: Serialize>(path: &Path, p: &Partial<T>) -> Result<(), String> {
    check_path(path)?;
    let text = seal(&serde_json::to_string(p).map_err(|e| e.to_string())?);
    let name = path.file_name().ok_or_else(|| format!("--partial {}: not a file name", path.display()))?;
    let tmp: PathBuf = path.with_file_name(format!(".{}.raypipe-partial", name.to_string_lossy()));
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
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
        // the format version first (an older partial has no digest), then the digest, then
        // the content
        let value: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a raypipe partial (corrupt or truncated?): {e}", p.display()))?;
        let Some(format) = value.get("raypipe_partial") else {
            return Err(format!("{}: not a raypipe partial (no raypipe_partial member)", p.display()));
        };
        if format.as_u64() != Some(FORMAT as u64) {
            return Err(format!(
                "{}: partial format {format}; this raypipe reads format {FORMAT} only (re-run the shard with this raypipe)",
                p.display()
            ));
        }
        unseal(&text).map_err(|e| format!("{}: refused: {e}", p.display()))?;
        // the digest member is not a field of Partial: the parsed file is its content
        let mut part: Partial<serde_json::Value> = serde_json::from_value(value)
            .map_err(|e| format!("{}: not a raypipe partial (corrupt or truncated?): {e}", p.display()))?;
        part.file = p.clone();
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

/// The typed data of a checked partial, refused (naming its file) when it is inconsistent.
pub fn data<T: DeserializeOwned + Consistent>(p: &Partial<serde_json::Value>) -> Result<T, String> {
    let d: T = serde_json::from_value(p.data.clone()).map_err(|e| {
        format!("{} (shard {}): its data is not a {} result: {e}", p.file.display(), p.shard, p.command)
    })?;
    let eng = engine::Engine::new(p.chunk.max(1)).with_shard(p.shard);
    let share = |lo: u64, hi: u64| eng.shard_items(hi) - eng.shard_items(lo.min(hi));
    d.check(&share)
        .map_err(|e| format!("{} (shard {}): refused: its content is inconsistent: {e}", p.file.display(), p.shard))?;
    Ok(d)
}

/// The checked partials' data, typed, each checked for consistency, and added up in shard
/// order by [`Sharded::add`].
pub fn merge_data<T: Sharded>(parts: &[Partial<serde_json::Value>]) -> Result<T, String> {
    let mut total: Option<T> = None;
    for p in parts {
        let d: T = data(p)?;
        match total.as_mut() {
            Some(t) => t.add(d)?,
            None => total = Some(d),
        }
    }
    total.ok_or_else(|| "name the partial files to merge".to_string())
}
