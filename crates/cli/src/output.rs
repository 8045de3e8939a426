//! A command's output files: checked before any computation, written
//! through temporary files in their folders, put in place together at the
//! end (all of a command's outputs or none), and removed when the run
//! fails, is dropped or is interrupted (SIGINT, SIGTERM).
//!
//! On Linux a file that already exists is *swapped* with its temporary
//! (`renameat2(RENAME_EXCHANGE)`, as atomic as a rename) and its old content,
//! now under the temporary's name, removed after: a plain rename over it
//! makes ext4 write the new file back at once (its `auto_da_alloc` guard for
//! programs that replace files without `fsync`), and removing the old file
//! then waits for that write-back when it is still under way, which cost a
//! millisecond on each `hydrocyl simulate` of a run written over the last.
//! Without `--fsync` the new content reaches the disk when the kernel writes
//! it back, as for any file written in place; with `--fsync` it is flushed
//! before the swap.
//!
//! An output path that is a symbolic link is written through it: the file it
//! points to is replaced, the link stays (the new file takes the old one's
//! permissions; being a new file, it does not keep the old one's hard links,
//! where a shell's `>`, writing in place, would). A path that is
//! a stream (`/dev/stdout`, a pipe, a terminal, a device) is written to
//! directly, as it is produced: there is no file to put in place, and what a
//! failed run has written to a stream cannot be taken back.

use crate::error::CliError;
use std::fs::File;
use std::io::{BufWriter, IoSlice, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files not yet renamed into place, removed by the signal handler.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Installs the SIGINT/SIGTERM handler that removes every pending temporary
/// file and exits with code 130 (once; later calls wait for the first).
/// [`Outputs::file`] calls it before it creates a temporary; `simulate`
/// calls it earlier, while its command file is read on another thread.
pub fn remove_temporaries_on_signal() {
    static HANDLER: std::sync::Once = std::sync::Once::new();
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if let Ok(mut p) = PENDING.lock() {
                for f in p.drain(..) {
                    let _ = std::fs::remove_file(f);
                }
            }
            crate::console::note(format_args!("hydrocyl: interrupted; no output written"));
            std::process::exit(130);
        });
    });
}

fn register(tmp: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.push(tmp.to_path_buf());
    }
}

fn unregister(tmp: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.retain(|f| f != tmp);
    }
}

/// `path` made absolute and resolved through symbolic links as far as it
/// exists (a file that does not exist yet, or a link to one: its folder's
/// canonical path and its name).
fn canonical(path: &Path) -> PathBuf {
    // a link that points nowhere yet: the file a write through it creates
    let linked = through_links(path);
    let path = linked.as_deref().unwrap_or(path);
    if let Ok(c) = path.canonicalize() {
        return c;
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (parent.canonicalize(), path.file_name()) {
        (Ok(p), Some(n)) => p.join(n),
        _ => path.to_path_buf(),
    }
}

/// One output file being written.
struct Pending {
    /// The path as given (for messages).
    path: PathBuf,
    /// Where it is put in place, with its temporary file beside it; `None`
    /// for a stream, written directly.
    place: Option<Place>,
    /// The open file; `None` for a file before its first write (its
    /// temporary is created then, [`Place::create`]).
    writer: Option<BufWriter<File>>,
}

/// A regular output file: `target` (the given path through its symbolic
/// links) and the temporary `tmp` in its folder.
struct Place {
    target: PathBuf,
    tmp: PathBuf,
}

impl Place {
    /// Creates the temporary (registered for removal on a signal), with
    /// the permissions of the file it replaces.
    fn create(&self) -> std::io::Result<BufWriter<File>> {
        remove_temporaries_on_signal();
        let f = File::create(&self.tmp)?;
        register(&self.tmp);
        if let Ok(m) = std::fs::metadata(&self.target) {
            let _ = f.set_permissions(m.permissions());
        }
        // small: a block of rows larger than this goes straight to the file
        Ok(BufWriter::with_capacity(1 << 16, f))
    }
}

/// Most symbolic links followed to an output's file (Linux's own limit).
const MAX_LINKS: usize = 40;

/// `path` through its symbolic links, to the file (existing or not) that a
/// write through it creates or replaces.
fn through_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match p.symlink_metadata() {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Whether `path` (through its links) is a stream: it exists and is neither
/// a regular file nor a folder (a pipe, a terminal, a device).
fn is_stream(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// The output files of one command (see the module doc).
pub struct Outputs {
    inputs: Vec<(String, PathBuf)>,
    files: Vec<Pending>,
}

/// A handle to one of [`Outputs`]'s files.
#[derive(Clone, Copy, Debug)]
pub struct OutputId(usize);

impl Outputs {
    /// No outputs yet; `inputs` are `(option, path)` of the command's input
    /// files, which no output may be.
    pub fn new(inputs: &[(&str, &Path)]) -> Self {
        Outputs {
            inputs: inputs
                .iter()
                .map(|(o, p)| (o.to_string(), canonical(p)))
                .collect(),
            files: Vec::new(),
        }
    }

    /// Checks that output `path` (given as `option`) is not an input or
    /// another output, and that its folder exists and takes a file.
    pub fn check(&self, option: &str, path: &Path) -> Result<PathBuf, CliError> {
        let bad = |why: String| CliError::Input(format!("{option} {}: {why}", path.display()));
        if path.file_name().is_none() {
            return Err(bad("not a file name".into()));
        }
        if path.is_dir() {
            return Err(bad("is a folder, not a file".into()));
        }
        let c = canonical(path);
        if let Some((o, _)) = self.inputs.iter().find(|(_, p)| *p == c) {
            return Err(bad(format!(
                "is the {o} input file; writing it would destroy the input"
            )));
        }
        if self.files.iter().any(|f| canonical(&f.path) == c) {
            return Err(bad("is already another output of this command".into()));
        }
        Ok(c)
    }

    /// Opens output `path` (option `option`): checks it, then creates and
    /// removes its temporary file `.<name>.tmp<pid>` next to the file it
    /// names (through its symbolic links), so that a missing or read-only
    /// folder is reported before any computation; the temporary is created
    /// again at the first write (a run killed before it, even by SIGKILL,
    /// leaves none: a `diagnose` report's exists only while it is written).
    /// A stream is opened for writing.
    pub fn file(&mut self, option: &str, path: &Path) -> Result<OutputId, CliError> {
        self.check(option, path)?;
        let io = |source| CliError::Io {
            path: format!("{option} {}", path.display()),
            source,
        };
        let (writer, place) = if is_stream(path) {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(io)?;
            (Some(BufWriter::with_capacity(1 << 16, f)), None)
        } else {
            let target = through_links(path).map_err(io)?;
            let name = target.file_name().unwrap_or_default().to_string_lossy();
            let tmp = target.with_file_name(format!(".{name}.tmp{}", std::process::id()));
            let place = Place { target, tmp };
            drop(place.create().map_err(io)?);
            let _ = std::fs::remove_file(&place.tmp);
            unregister(&place.tmp);
            (None, Some(place))
        };
        self.files.push(Pending {
            path: path.to_path_buf(),
            place,
            writer,
        });
        Ok(OutputId(self.files.len() - 1))
    }

    /// Checks that folder `dir` (option `option`) exists or can be created
    /// (its parent exists), takes files (a probe file is created in it, or
    /// in its parent, and removed), and is not a file, an input or another
    /// output of this command; the files in it are opened later with
    /// [`Outputs::file`].
    pub fn check_dir(&self, option: &str, dir: &Path) -> Result<(), CliError> {
        let bad = |why: &str| CliError::Input(format!("{option} {}: {why}", dir.display()));
        let c = canonical(dir);
        if let Some((o, _)) = self.inputs.iter().find(|(_, p)| *p == c) {
            return Err(bad(&format!("is the {o} input file, not a folder")));
        }
        if self.files.iter().any(|f| canonical(&f.path) == c) {
            return Err(bad("is already another output of this command"));
        }
        let io = |source| CliError::Io {
            path: format!("{option} {}", dir.display()),
            source,
        };
        if dir.is_dir() {
            return probe(dir).map_err(io);
        }
        if dir.exists() {
            return Err(bad("is a file, not a folder"));
        }
        match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() && !p.is_dir() => {
                Err(bad("its parent folder does not exist"))
            }
            Some(p) if !p.as_os_str().is_empty() => probe(p).map_err(io),
            _ => probe(Path::new(".")).map_err(io),
        }
    }

    /// Output `id`'s open file (its temporary created at the first call).
    fn writer(&mut self, id: OutputId) -> Result<&mut BufWriter<File>, CliError> {
        let f = &mut self.files[id.0];
        if f.writer.is_none() {
            let place = f.place.as_ref().ok_or_else(|| CliError::Io {
                path: f.path.display().to_string(),
                source: std::io::Error::other("written after it was closed"),
            })?;
            let w = place.create().map_err(|source| CliError::Io {
                path: f.path.display().to_string(),
                source,
            })?;
            f.writer = Some(w);
        }
        f.writer.as_mut().ok_or_else(|| CliError::Io {
            path: f.path.display().to_string(),
            source: std::io::Error::other("not open"),
        })
    }

    /// Appends `bytes` to output `id`.
    pub fn write(&mut self, id: OutputId, bytes: &[u8]) -> Result<(), CliError> {
        let path = self.files[id.0].path.display().to_string();
        self.writer(id)?
            .write_all(bytes)
            .map_err(|source| CliError::Io { path, source })
    }

    /// Appends `pieces`, one after the other, to output `id` (with as few
    /// system calls and copies as the buffer allows: pieces larger than it
    /// go straight to the file).
    pub fn write_all(&mut self, id: OutputId, pieces: &[Vec<u8>]) -> Result<(), CliError> {
        self.writer(id)?;
        let f = &mut self.files[id.0];
        let Some(w) = f.writer.as_mut() else {
            return Ok(());
        };
        let mut slices: Vec<IoSlice<'_>> = pieces.iter().map(|p| IoSlice::new(p)).collect();
        let mut left = &mut slices[..];
        IoSlice::advance_slices(&mut left, 0);
        while !left.is_empty() {
            match w.write_vectored(left) {
                Ok(0) => {
                    return Err(CliError::Io {
                        path: f.path.display().to_string(),
                        source: std::io::ErrorKind::WriteZero.into(),
                    })
                }
                Ok(n) => IoSlice::advance_slices(&mut left, n),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(CliError::Io {
                        path: f.path.display().to_string(),
                        source,
                    })
                }
            }
        }
        Ok(())
    }

    /// Flushes every output (with `fsync`, to the disk), then puts them all
    /// in place (see the module doc). On a failure nothing new is left: the
    /// temporaries go, a file already swapped in by this call gets its old
    /// content back, and one renamed in (it did not exist) is removed.
    pub fn commit(mut self, fsync: bool) -> Result<(), CliError> {
        for f in &mut self.files {
            let io = |source| CliError::Io {
                path: f.path.display().to_string(),
                source,
            };
            // an output never written is put in place empty
            let w = match (f.writer.take(), &f.place) {
                (Some(w), _) => w,
                (None, Some(p)) => p.create().map_err(io)?,
                (None, None) => continue,
            };
            let file = w.into_inner().map_err(|e| io(e.into_error()))?;
            // a stream (a pipe, a terminal) has no disk to flush to
            if fsync && f.place.is_some() {
                file.sync_all().map_err(io)?;
            }
        }
        // (file, swapped: its old content is now under its temporary's name)
        let mut done: Vec<(&Place, bool)> = Vec::new();
        for (f, p) in self
            .files
            .iter()
            .filter_map(|f| f.place.as_ref().map(|p| (f, p)))
        {
            match put_in_place(&p.tmp, &p.target) {
                Ok(swapped) => done.push((p, swapped)),
                Err(source) => {
                    for (g, swapped) in &done {
                        // a swap undone puts the new content back under the
                        // temporary's name, which the drop removes
                        if !(*swapped && exchange(&g.tmp, &g.target).is_ok()) {
                            let _ = std::fs::remove_file(&g.target);
                        }
                    }
                    return Err(CliError::Io {
                        path: f.path.display().to_string(),
                        source,
                    });
                }
            }
        }
        for (p, swapped) in done {
            if swapped {
                let _ = std::fs::remove_file(&p.tmp);
            }
            unregister(&p.tmp);
        }
        self.files.clear();
        Ok(())
    }
}

/// Creates and removes a probe file in folder `dir`: a folder that takes no
/// file (read-only, or not a real folder such as `/proc/self`) is an error
/// before any computation, not after it.
fn probe(dir: &Path) -> std::io::Result<()> {
    let tmp = dir.join(format!(".hydrocyl-probe.tmp{}", std::process::id()));
    remove_temporaries_on_signal();
    register(&tmp);
    let made = File::create(&tmp);
    if made.is_ok() {
        let _ = std::fs::remove_file(&tmp);
    }
    unregister(&tmp);
    made.map(drop)
}

/// Puts file `tmp` in place at `path`: swapped with an existing file
/// (`true`: the old content is now at `tmp`), else renamed.
fn put_in_place(tmp: &Path, path: &Path) -> std::io::Result<bool> {
    // only a file (or a link) is swapped: a folder put there since the check
    // makes the rename fail, as before
    let existing = path
        .symlink_metadata()
        .is_ok_and(|m| !m.file_type().is_dir());
    if existing && exchange(tmp, path).is_ok() {
        return Ok(true);
    }
    std::fs::rename(tmp, path).map(|()| false)
}

/// Swaps files `a` and `b` atomically.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{renameat_with, RenameFlags, CWD};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(std::io::Error::from)
}

/// Swapping is Linux's (`renameat2`): elsewhere a file is renamed over.
#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

impl Drop for Outputs {
    /// Removes the temporaries of outputs never committed.
    fn drop(&mut self) {
        for f in self.files.drain(..) {
            drop(f.writer);
            if let Some(p) = f.place {
                let _ = std::fs::remove_file(&p.tmp);
                unregister(&p.tmp);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The temporaries in folder `dir`.
    fn temporaries(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| n.contains(".tmp"))
            .collect()
    }

    /// An output's temporary exists only from its first write to the
    /// commit: a run killed before it writes (SIGKILL during a `diagnose`
    /// fit) leaves none behind (tester t38d C1); a bad folder is still
    /// refused up front; an output never written is put in place empty.
    #[test]
    fn the_temporary_exists_only_while_written() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let mut outputs = Outputs::new(&[]);
        let report = outputs.file("--report", &d.join("r.json")).unwrap();
        let _never_written = outputs.file("--out", &d.join("e.csv")).unwrap();
        assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
        outputs.write(report, b"{}").unwrap();
        assert_eq!(temporaries(d).len(), 1, "{:?}", temporaries(d));
        outputs.commit(false).unwrap();
        assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
        assert_eq!(std::fs::read(d.join("r.json")).unwrap(), b"{}");
        assert_eq!(std::fs::read(d.join("e.csv")).unwrap(), b"");
        let mut outputs = Outputs::new(&[]);
        let e = outputs
            .file("--report", &d.join("no-such-folder").join("r.json"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("--report"), "{e}");
    }
}
