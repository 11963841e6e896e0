//! Output directories that never lose a user's data: checked before the work starts, written
//! file by file through a temporary sibling and a rename, and never over a file raypipe did not
//! write. What raypipe wrote into a directory is listed in its `.raypipe-output` file; a
//! temporary file or directory of an interrupted run is named `.<name>.raypipe-partial`, is
//! removed on SIGINT (see [`remove_partials`]) and, if one is left, by the next run into the
//! same place.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The list of the files raypipe wrote into a directory (one name a line).
pub const MARKER: &str = ".raypipe-output";

/// Temporary paths of the runs in progress, for [`remove_partials`].
static PARTIALS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The temporary sibling of `path` (same directory, so that the final rename is atomic).
pub fn partial_of(path: &Path) -> Result<PathBuf, String> {
    let name = path.file_name().ok_or_else(|| format!("{}: not a file or directory name", path.display()))?;
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    Ok(parent.join(format!(".{}.raypipe-partial", name.to_string_lossy())))
}

/// Records the temporary path `p` for [`remove_partials`] and creates it with `create`, both
/// under the registry's lock, so that an interrupt finds `p` either recorded or not yet created
/// (never created after the handler looked). On an error `p` stays recorded: the caller
/// removes what was made and calls [`unregister_partial`].
pub fn create_partial(p: &Path, create: impl FnOnce(&Path) -> std::io::Result<()>) -> std::io::Result<()> {
    let mut v = PARTIALS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    v.push(p.to_path_buf());
    create(p)
}

/// Forgets a temporary path (it was renamed into place).
pub fn unregister_partial(p: &Path) {
    if let Ok(mut v) = PARTIALS.lock() {
        v.retain(|x| x != p);
    }
}

/// Deletes every registered temporary path; for the SIGINT handler, which exits right after:
/// the registry stays locked, so no run creates a temporary path afterwards.
pub fn remove_partials() {
    let paths = PARTIALS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    for p in paths.iter() {
        if p.is_dir() {
            // A run's thread may still be writing into the directory: a file it creates
            // between the listing and the final `rmdir` makes that fail, so try again (a run
            // writes a handful of files; once the directory is gone its writes fail).
            for _ in 0..64 {
                if std::fs::remove_dir_all(p).is_ok() || !p.exists() {
                    break;
                }
            }
        } else {
            let _ = std::fs::remove_file(p);
        }
    }
    std::mem::forget(paths);
}

/// The nearest existing ancestor of `path` must be a directory (so that it can be created).
fn check_creatable(path: &Path) -> Result<(), String> {
    let mut p = path.parent();
    while let Some(a) = p {
        if a.as_os_str().is_empty() {
            return Ok(());
        }
        if a.exists() {
            return if a.is_dir() {
                Ok(())
            } else {
                Err(format!("{}: {} is not a directory", path.display(), a.display()))
            };
        }
        p = a.parent();
    }
    Ok(())
}

/// A directory raypipe may write the named files into.
#[derive(Clone, Debug)]
pub struct OutDir {
    dir: PathBuf,
}

impl OutDir {
    /// Checks, before any work, that `files` can be written into `dir`: `dir` is a directory
    /// or does not exist (nothing is created yet), and every one of `files` that exists there
    /// is a regular file raypipe wrote (listed in its [`MARKER`]). Leftovers of an interrupted
    /// run (`.<file>.raypipe-partial`) are removed.
    pub fn check(dir: &Path, files: &[&str]) -> Result<Self, String> {
        if dir.exists() {
            if !dir.is_dir() {
                return Err(format!("{} exists and is not a directory", dir.display()));
            }
            let ours = written_by_raypipe(dir);
            for f in files {
                let p = dir.join(f);
                let partial = partial_of(&p)?;
                if partial.is_file() {
                    let _ = std::fs::remove_file(&partial);
                }
                if p.exists() && !(p.is_file() && ours.iter().any(|o| o == f)) {
                    return Err(format!(
                        "{} exists and was not written by raypipe (not listed in {}); refusing to overwrite it: choose another directory",
                        p.display(),
                        dir.join(MARKER).display()
                    ));
                }
            }
        } else {
            check_creatable(dir)?;
        }
        Ok(Self { dir: dir.to_path_buf() })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Writes one file atomically (a temporary sibling, then a rename) and lists it in the
    /// directory's [`MARKER`]; creates the directory if needed.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf, String> {
        std::fs::create_dir_all(&self.dir).map_err(|e| format!("{}: {e}", self.dir.display()))?;
        let mut ours = written_by_raypipe(&self.dir);
        if !ours.iter().any(|o| o == name) {
            ours.push(name.to_string());
            atomic_write(&self.dir.join(MARKER), (ours.join("\n") + "\n").as_bytes())?;
        }
        let p = self.dir.join(name);
        atomic_write(&p, bytes)?;
        Ok(p)
    }
}

/// The names listed in `dir`'s [`MARKER`].
fn written_by_raypipe(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join(MARKER))
        .map(|s| s.lines().filter(|l| !l.is_empty()).map(str::to_string).collect())
        .unwrap_or_default()
}

/// Refuses an output file `path` (given as option `flag`) raypipe may not write, before any
/// work: a directory, a missing parent directory, or an existing file whose text `ours` does
/// not recognise ("{flag} {path} exists and {not_ours}: not replacing it").
pub fn check_file_out(flag: &str, path: &Path, ours: impl Fn(&str) -> bool, not_ours: &str) -> Result<(), String> {
    let shown = path.display();
    if path.is_dir() {
        return Err(format!("{flag} {shown} is a directory"));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(format!("{flag} {shown}: no directory {}", parent.display()));
    }
    if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{flag} {shown}: {e}"))?;
        if !ours(&text) {
            return Err(format!("{flag} {shown} exists and {not_ours}: not replacing it"));
        }
    }
    Ok(())
}

/// Writes `path` through its temporary sibling and a rename.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = partial_of(path)?;
    let r = create_partial(&tmp, |t| std::fs::write(t, bytes))
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| format!("{}: {e}", path.display()));
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    unregister_partial(&tmp);
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("raypipe-outdir-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn writes_are_atomic_listed_and_never_over_a_stranger() {
        let d = scratch("a");
        let o = OutDir::check(&d, &["x.txt"]).unwrap();
        assert!(!d.exists(), "checking creates nothing");
        o.write("x.txt", b"one").unwrap();
        assert_eq!(std::fs::read(d.join("x.txt")).unwrap(), b"one");
        // raypipe's own file may be replaced
        OutDir::check(&d, &["x.txt"]).unwrap().write("x.txt", b"two").unwrap();
        assert_eq!(std::fs::read(d.join("x.txt")).unwrap(), b"two");
        // a file of the user's is never replaced
        std::fs::write(d.join("y.txt"), b"mine").unwrap();
        let e = OutDir::check(&d, &["x.txt", "y.txt"]).unwrap_err();
        assert!(e.contains("not written by raypipe"), "{e}");
        assert_eq!(std::fs::read(d.join("y.txt")).unwrap(), b"mine");
        // a file where a directory is wanted, and a directory below a file
        let f = d.join("y.txt");
        assert!(OutDir::check(&f, &["x.txt"]).unwrap_err().contains("not a directory"));
        assert!(OutDir::check(&f.join("sub"), &["x.txt"]).unwrap_err().contains("not a directory"));
        // an interrupted write's leftover is cleaned by the next run
        std::fs::write(partial_of(&d.join("x.txt")).unwrap(), b"half").unwrap();
        OutDir::check(&d, &["x.txt"]).unwrap();
        assert!(!partial_of(&d.join("x.txt")).unwrap().exists());
        let _ = std::fs::remove_dir_all(&d);
    }
}
