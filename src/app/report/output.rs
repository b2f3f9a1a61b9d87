//! File output that never leaves a half-written file and never replaces what is not a
//! regular file.
//!
//! A regular file (or a path that does not exist yet) is written to a hidden temporary
//! file beside it and renamed over it, so a reader sees the old file or the new one,
//! never a mix. A symbolic link is followed and its final target is replaced the same
//! way; the link stays. A character device (`/dev/null`) or a FIFO is written through,
//! never replaced. Anything else (a directory, a block device, a socket) is refused, as
//! is a path whose directory does not exist.
//!
//! Temporary files are registered while they exist: [`remove_partial_files`] deletes
//! them, and the command line calls it when it is interrupted (SIGINT, SIGTERM).
//!
//! While a command runs, its writes are staged ([`stage_writes`]): each file is
//! written whole to its temporary file, and only when the command has succeeded are
//! they all put in place ([`commit_writes`]); a command that fails after writing some
//! of its outputs (a plot it cannot draw after its CSV) changes no file
//! ([`discard_writes`]).

use crate::error::{Error, Result};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether each file written is announced on stderr ([`announce_writes`]).
static ANNOUNCE: AtomicBool = AtomicBool::new(false);

/// Announce every file [`write_with`] puts in place on stderr ("wrote PATH"), or not: a
/// command announces its outputs unless `--quiet`.
pub fn announce_writes(on: bool) {
    ANNOUNCE.store(on, Ordering::Relaxed);
}

/// Temporary files being written.
static PARTIAL: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A file written whole to its temporary file, to be put in place when the command
/// succeeds: the temporary file, how its target is written, and the path the user gave.
struct Staged {
    tmp: PathBuf,
    target: Target,
    shown: PathBuf,
}

/// The writes staged while a command runs (none: writes go in place at once).
static STAGED: Mutex<Option<Vec<Staged>>> = Mutex::new(None);

fn staged() -> std::sync::MutexGuard<'static, Option<Vec<Staged>>> {
    STAGED
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// From now on, hold every file written until [`commit_writes`] or [`discard_writes`].
pub fn stage_writes() {
    *staged() = Some(Vec::new());
}

/// Put every staged file in place, in the order written (each renamed over its target,
/// or copied into a device or FIFO), announcing each as [`write_with`] does; writes go
/// in place at once again.
pub fn commit_writes() -> Result<()> {
    let list = staged().take().unwrap_or_default();
    let mut result = Ok(());
    for s in list {
        let done = if result.is_ok() {
            place(&s.tmp, &s.target, &s.shown)
        } else {
            Ok(())
        };
        let _ = fs::remove_file(&s.tmp);
        partial_files().retain(|p| p != &s.tmp);
        match done {
            Ok(()) if ANNOUNCE.load(Ordering::Relaxed) => eprintln!("wrote {}", s.shown.display()),
            Ok(()) => {}
            Err(e) => result = Err(e),
        }
    }
    result
}

/// Drop every staged file (the command failed): no target is touched.
pub fn discard_writes() {
    for s in staged().take().unwrap_or_default() {
        let _ = fs::remove_file(&s.tmp);
        partial_files().retain(|p| p != &s.tmp);
    }
}

/// Put the temporary file `tmp` in place of `target` (`shown` names it in errors).
fn place(tmp: &Path, target: &Target, shown: &Path) -> Result<()> {
    match target {
        Target::Replace(target) => fs::rename(tmp, target).map_err(|e| io(shown, e)),
        Target::WriteThrough(target) => {
            let mut from = fs::File::open(tmp).map_err(|e| io(shown, e))?;
            let mut to = fs::OpenOptions::new()
                .write(true)
                .open(target)
                .map_err(|e| io(shown, e))?;
            std::io::copy(&mut from, &mut to).map_err(|e| io(shown, e))?;
            Ok(())
        }
    }
}

#[doc(hidden)]
pub fn partial_files() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    PARTIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Delete every temporary file still being written (for a signal handler).
pub fn remove_partial_files() {
    for path in partial_files().drain(..) {
        let _ = fs::remove_file(path);
    }
}

/// A temporary file, registered for [`remove_partial_files`] and deleted when dropped
/// unless it was renamed into place.
struct Partial {
    path: PathBuf,
}

impl Partial {
    /// A temporary path beside `target` with the same extension (some writers pick
    /// the format from it), or in the system's temporary directory if `beside` is
    /// false.
    fn new(target: &Path, beside: bool) -> Self {
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "output".into());
        let ext = target
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        let file = format!(".{name}.partial-{}{ext}", std::process::id());
        let path = if beside {
            target.with_file_name(file)
        } else {
            std::env::temp_dir().join(file)
        };
        partial_files().push(path.clone());
        Self { path }
    }

    fn forget(&self) {
        partial_files().retain(|p| p != &self.path);
    }
}

impl Drop for Partial {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.path);
        self.forget();
    }
}

/// How a target is written.
enum Target {
    /// Write a temporary file beside this path, rename it over it.
    Replace(PathBuf),
    /// Open this path and write into it (a character device or a FIFO).
    WriteThrough(PathBuf),
}

#[doc(hidden)]
pub fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn refuse(path: &Path, reason: impl Into<String>) -> Error {
    Error::Output {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// The final target of `path` after following symbolic links (at most 40, as the
/// kernel does).
fn follow_links(path: &Path) -> Result<PathBuf> {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        match fs::symlink_metadata(&path) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = fs::read_link(&path).map_err(|e| io(&path, e))?;
                path = match path.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(path),
        }
    }
    Err(refuse(&path, "too many levels of symbolic links"))
}

/// Decide how to write `path`.
fn target(path: &Path) -> Result<Target> {
    if path.as_os_str().is_empty() {
        return Err(refuse(path, "the file name is empty"));
    }
    let resolved = follow_links(path)?;
    let dir = match resolved.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match fs::metadata(&dir) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => {
            return Err(refuse(
                path,
                format!("{} is not a directory", dir.display()),
            ));
        }
        Err(_) => {
            return Err(refuse(
                path,
                format!(
                    "the directory {} does not exist (create it first)",
                    dir.display()
                ),
            ));
        }
    }
    let Ok(meta) = fs::metadata(&resolved) else {
        return Ok(Target::Replace(resolved));
    };
    use std::os::unix::fs::FileTypeExt;
    let kind = meta.file_type();
    if kind.is_file() {
        Ok(Target::Replace(resolved))
    } else if kind.is_char_device() || kind.is_fifo() {
        Ok(Target::WriteThrough(resolved))
    } else if kind.is_dir() {
        Err(refuse(path, "it is a directory; give a file name"))
    } else {
        Err(refuse(
            path,
            "it is neither a regular file, a character device nor a FIFO",
        ))
    }
}

/// Refuse `path` as an output if it cannot be written: its directory missing or not a
/// directory, or the path a directory, a block device or a socket (what a write would
/// refuse, checked before any work).
pub fn check_target(path: &Path) -> Result<()> {
    target(path).map(|_| ())
}

/// An error about the temporary file told about `path` instead.
fn about(path: &Path, tmp: &Path, e: Error) -> Error {
    match e {
        Error::Io { path: p, source } if p == tmp => Error::Io {
            path: path.to_path_buf(),
            source,
        },
        Error::Output { path: p, reason } if p == tmp => Error::Output {
            path: path.to_path_buf(),
            reason,
        },
        other => other,
    }
}

/// Write `path` by letting `write` produce a temporary file, then putting it in place
/// (see the module documentation). On any failure the temporary file is removed and
/// `path` is left untouched; errors name `path`, never the temporary file.
pub fn write_with(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    // (A staged file is announced when it is put in place.)
    if put(path, write)? && ANNOUNCE.load(Ordering::Relaxed) {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Write `bytes` to `path` as [`write_bytes`] does, never announced: a file the user
/// did not ask for (the on-disk cache).
/// Never staged either: the cache is read back within the run that fills it.
pub fn write_unannounced(path: &Path, bytes: &[u8]) -> Result<()> {
    put_now(
        path,
        |tmp| fs::write(tmp, bytes).map_err(|e| io(tmp, e)),
        false,
    )
    .map(|_| ())
}

/// [`write_with`] without the announcement: whether the file is in place now (false:
/// staged until the command succeeds).
fn put(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<bool> {
    put_now(path, write, true)
}

/// [`put`], staged only if `stage` (and staging is on).
fn put_now(path: &Path, write: impl FnOnce(&Path) -> Result<()>, stage: bool) -> Result<bool> {
    let target = target(path)?;
    let (beside, at) = match &target {
        Target::Replace(t) => (true, t),
        Target::WriteThrough(t) => (false, t),
    };
    let tmp = Partial::new(at, beside);
    write(&tmp.path).map_err(|e| about(path, &tmp.path, e))?;
    if let Some(list) = staged().as_mut().filter(|_| stage) {
        // Kept (and still registered for an interrupt) until the command ends.
        list.push(Staged {
            tmp: tmp.path.clone(),
            target,
            shown: path.to_path_buf(),
        });
        std::mem::forget(tmp);
        return Ok(false);
    }
    place(&tmp.path, &target, path)?;
    if beside {
        tmp.forget();
    }
    Ok(true)
}

/// Write `bytes` to `path` (see [`write_with`]).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |tmp| fs::write(tmp, bytes).map_err(|e| io(tmp, e)))
}

/// Create the directory `dir` if it does not exist; its parent must.
pub fn ensure_dir(dir: &Path) -> Result<()> {
    if dir.is_dir() {
        return Ok(());
    }
    fs::create_dir(dir).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => {
            refuse(dir, "its parent directory does not exist (create it first)")
        }
        _ => io(dir, source),
    })
}
