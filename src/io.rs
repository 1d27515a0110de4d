//! Files in and out at the byte level: reads capped in size (devices and
//! pipes included), and atomic writes (a temporary file renamed into place,
//! so a failure never leaves a partial output). The size limits of every
//! canvas live here too.

use crate::error::{Error, Result};
use std::io::Write as _;
use std::path::Path;
use std::sync::Mutex;

/// Held while output files are written: whoever ends the process early
/// takes it first ([`exit_between_writes`]).
static WRITES: Mutex<()> = Mutex::new(());

/// A handle that cancels a run from another thread (a newer request
/// superseding it): clones share one flag; a mode checks it between its
/// stages and queries and then ends with [`Error::Cancelled`]. Two
/// handles are equal when they share the flag.
#[derive(Clone, Debug, Default)]
pub struct Cancel(std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Cancel {
    /// A handle not cancelled yet.
    pub fn new() -> Cancel {
        Cancel::default()
    }

    /// Cancels every run holding this handle or a clone of it.
    pub fn cancel(&self) {
        self.0.store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether [`Self::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// `Err(Error::Cancelled)` once cancelled, for `?` between stages.
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }
}

impl PartialEq for Cancel {
    fn eq(&self, other: &Cancel) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Checks an optional [`Cancel`] handle (none: never cancelled).
pub(crate) fn check(cancel: &Option<Cancel>) -> Result<()> {
    cancel.as_ref().map_or(Ok(()), Cancel::check)
}

/// What the run is doing now, for a progress line ([`stage`]).
static STAGE: Mutex<String> = Mutex::new(String::new());

/// Ends the process with exit status `code` once no output is being
/// written, and lets no write begin after: every output file is whole or
/// absent, and no temporary file is left behind (for `--timeout`).
pub fn exit_between_writes(code: i32) -> ! {
    let _writes = WRITES.lock().unwrap_or_else(|p| p.into_inner());
    std::process::exit(code)
}

/// The stage the library is in, in a few words (e.g. "fill: 3 regions"):
/// what a progress line shows. Empty before the first stage.
pub fn stage() -> String {
    STAGE.lock().map(|s| s.clone()).unwrap_or_default()
}

/// Calls `f` with the stage, without allocating and without waiting: not
/// at all while another thread is setting it (for last-resort messages).
pub fn with_stage(f: impl FnOnce(&str)) {
    if let Ok(s) = STAGE.try_lock() {
        f(&s);
    }
}

/// Sets the stage [`stage`] reports.
pub(crate) fn set_stage(what: impl Into<String>) {
    if let Ok(mut s) = STAGE.lock() {
        *s = what.into();
    }
}

/// A stage made of `total` items done in any order (e.g. the strokes of a
/// brush run, in parallel): the stage reads "WHAT: K of TOTAL".
pub(crate) struct Tally {
    what: String,
    total: usize,
    done: std::sync::atomic::AtomicUsize,
}

impl Tally {
    /// Starts the stage at 0 of `total`.
    pub(crate) fn new(what: impl Into<String>, total: usize) -> Tally {
        let what = what.into();
        set_stage(format!("{what}: 0 of {total}"));
        Tally {
            what,
            total,
            done: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// Counts one more item done.
    pub(crate) fn tick(&self) {
        let k = self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        set_stage(format!("{}: {k} of {}", self.what, self.total));
    }
}

/// Largest input file read, in bytes (256 MiB).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Largest raster side in pixels, for inputs and canvases.
pub(crate) const MAX_SIDE: u64 = 16_384;

/// Largest raster area in pixels (64 Mpx), for inputs and canvases.
pub(crate) const MAX_PIXELS: u64 = 64 << 20;

/// Checks a raster size against [`MAX_SIDE`] and [`MAX_PIXELS`] before
/// anything is allocated.
pub(crate) fn check_canvas(width: u64, height: u64) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::invalid(format!(
            "empty canvas ({width}×{height} px)"
        )));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_PIXELS {
        return Err(Error::TooLarge {
            width,
            height,
            limit: format!("{MAX_SIDE} px per side, {} Mpx in all", MAX_PIXELS >> 20),
        });
    }
    Ok(())
}

/// Reads a whole file, refusing files over [`MAX_FILE_BYTES`]: by their
/// size when they have one, and for devices and pipes (whose size reads 0,
/// such as `/dev/zero`) by stopping there.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::invalid("is a directory, not a file").in_file(path));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(Error::invalid(format!(
            "file of {} bytes exceeds the limit of {MAX_FILE_BYTES} bytes",
            meta.len()
        ))
        .in_file(path));
    }
    read_capped(path, MAX_FILE_BYTES)
}

/// Reads an input of the command line: `-` is standard input, read to its
/// end (refused past [`MAX_FILE_BYTES`]); anything else [`read_file`].
pub fn read_input(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read as _;
    if path.as_os_str() != "-" {
        return read_file(path);
    }
    let mut out = Vec::new();
    std::io::stdin()
        .lock()
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| Error::io("<stdin>", e))?;
    if out.len() as u64 > MAX_FILE_BYTES {
        return Err(
            Error::invalid(format!("more than the limit of {MAX_FILE_BYTES} bytes"))
                .in_file("<stdin>"),
        );
    }
    Ok(out)
}

/// Reads `path` to its end or to `cap` + 1 bytes, whichever comes first;
/// more than `cap` bytes is an error.
fn read_capped(path: &Path, cap: u64) -> Result<Vec<u8>> {
    use std::io::Read as _;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut out = Vec::new();
    file.take(cap + 1)
        .read_to_end(&mut out)
        .map_err(|e| Error::io(path, e))?;
    if out.len() as u64 > cap {
        return Err(Error::invalid(format!("file exceeds the limit of {cap} bytes")).in_file(path));
    }
    Ok(out)
}

/// Writes `bytes` to `path` atomically: into a temporary file in the same
/// folder, then renamed over `path`. `-` writes to standard output.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files all or nothing (as far as the file system allows):
/// every temporary file is written first, and only then are they renamed
/// into place, so a missing folder or a full disk leaves no output behind.
/// A path of `-` writes to standard output.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let _writes = WRITES.lock().unwrap_or_else(|p| p.into_inner());
    let mut staged = Vec::new();
    for &(path, bytes) in files {
        if path.as_os_str() == "-" {
            continue;
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        // tempfile's own errors name the temporary file; report the output.
        let plain = |e: std::io::Error| Error::io(path, std::io::Error::from(e.kind()));
        let mut tmp = tempfile::Builder::new()
            .prefix(".flourish-")
            .suffix(".tmp")
            .tempfile_in(dir)
            .map_err(plain)?;
        tmp.write_all(bytes).map_err(plain)?;
        tmp.flush().map_err(plain)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // Temporary files are private (0600); outputs are ordinary files.
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(plain)?;
        }
        staged.push((path, tmp));
    }
    for &(path, bytes) in files {
        if path.as_os_str() == "-" {
            let fail = |e| Error::io("<stdout>", e);
            let mut out = stdout()?;
            out.write_all(bytes).map_err(fail)?;
            out.flush().map_err(fail)?;
        }
    }
    for (path, tmp) in staged {
        tmp.persist(path)
            .map_err(|e| Error::io(path, std::io::Error::from(e.error.kind())))?;
    }
    Ok(())
}

/// Standard output to write a result to, or an error when the command was
/// started with standard output closed (`flourish … -o - >&-`): the Rust
/// runtime then opens `/dev/null` read-write in its place before `main`,
/// where a shell's `> /dev/null` opens it write-only, so the result would
/// vanish with a success.
fn stdout() -> Result<std::io::StdoutLock<'static>> {
    #[cfg(target_os = "linux")]
    {
        let target = std::fs::read_link("/proc/self/fd/1").ok();
        let flags = std::fs::read_to_string("/proc/self/fdinfo/1")
            .ok()
            .and_then(|t| {
                t.lines()
                    .find_map(|l| l.strip_prefix("flags:"))
                    .and_then(|f| u32::from_str_radix(f.trim(), 8).ok())
            });
        const O_ACCMODE: u32 = 0o3;
        const O_RDWR: u32 = 0o2;
        if target.as_deref() == Some(Path::new("/dev/null"))
            && flags.is_some_and(|f| f & O_ACCMODE == O_RDWR)
        {
            return Err(Error::io(
                "<stdout>",
                std::io::Error::new(std::io::ErrorKind::BrokenPipe, "standard output is closed"),
            ));
        }
    }
    Ok(std::io::stdout().lock())
}

/// Whether `path` is a regular file, following symbolic links (a FIFO or a
/// device would block or never end when opened; a folder is not a file).
pub(crate) fn is_regular_file(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| m.is_file())
}

/// True when `a` and `b` name the same existing file (or the same path).
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file is read up to the cap and refused past it, named in the
    /// error (a device such as /dev/zero has no size to check first).
    #[test]
    fn reads_stop_at_the_cap() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("big.svg");
        std::fs::write(&path, vec![b' '; 100]).expect("writes");
        assert_eq!(read_capped(&path, 100).expect("at the cap").len(), 100);
        let e = read_capped(&path, 99).expect_err("over the cap");
        assert!(
            e.to_string().contains("big.svg") && e.to_string().contains("limit"),
            "{e}"
        );
    }
}
