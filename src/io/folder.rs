//! Writing results without ever touching what fretsim did not write.
//!
//! A run's output folder is *claimed* before the solve ([`RunFolder::claim`]):
//! - the target must be absent, empty, or a previous fretsim output: a folder holding the
//!   manifest [`MANIFEST`] and nothing that the manifest does not list. Anything else is
//!   refused, and so are the current folder, its ancestors, `/`, the home folder, the
//!   scenario's own folder (and its ancestors), symbolic links and files;
//! - a lock file `.NAME.fretsim-lock` beside the target (an advisory `flock`, released by the
//!   kernel when the process dies) keeps a second run off the same target;
//! - the staging folder `.NAME.fretsim-new` is created beside the target, which proves that the
//!   parent can be written before any time is spent solving.
//!
//! The files are written into the staging folder, the manifest last. [`RunFolder::commit`]
//! then exchanges the staging folder with the old output in one `renameat2(RENAME_EXCHANGE)`
//! (or renames it into place when there is none) and removes the old output, which now sits at
//! `.NAME.fretsim-old`. A process killed at any instant leaves the complete old output or the
//! complete new one at the target; the hidden folders it may leave carry a marker file or a
//! manifest, and the next run on that target (under the lock) removes them.
//!
//! A sweep folder ([`SweepFolder`]) is shared by the shards of one sweep: it carries a
//! manifest of kind `sweep`, each shard replaces its own CSV file atomically, and every
//! variant's folder inside it is claimed as a run folder of its own.

#[cfg(not(any(target_os = "linux", target_os = "macos")))]
compile_error!(
    "fretsim's output folders need an atomic exchange of two folders and an advisory lock: \
     renameat2 (Linux) or renameatx_np (macOS) and flock"
);

use std::fs;
use std::io::{Read, Seek, Write};
use std::path::{Component, Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// The manifest that marks a folder as fretsim's and lists the files it wrote.
pub const MANIFEST: &str = "fretsim-manifest.json";

/// The marker inside a staging folder (removed just before the folder is swapped in).
const STAGING_MARKER: &str = ".fretsim-staging";

/// The checkpoint's folder inside a staging folder ([`super::checkpoint`]).
const CHECKPOINT: &str = "checkpoint";

/// What a fretsim folder holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FolderKind {
    /// The output of `fretsim run` (or of one variant of a sweep).
    Run,
    /// The output of `fretsim sweep`.
    Sweep,
}

/// The manifest's contents.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// What wrote the folder.
    pub kind: FolderKind,
    /// fretsim version that wrote it.
    pub fretsim_version: String,
    /// The files fretsim wrote, relative to the folder, `/`-separated (a sweep lists none:
    /// its files are recognised by their names).
    pub files: Vec<String>,
}

fn write_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::WriteOutput {
        path: path.to_path_buf(),
        source,
    }
}

fn refuse(path: &Path, reason: impl Into<String>) -> Error {
    Error::OutputRefused {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// A test hook for fault injection: when the environment variable `FRETSIM_PAUSE_AT` names
/// `stage` (`solve`, `write`, `swap`, `cleanup`), the process says so on stderr and sleeps, so
/// that a test can kill it exactly there.
pub fn pause_point(stage: &str) {
    if std::env::var_os("FRETSIM_PAUSE_AT").is_some_and(|s| s == stage) {
        eprintln!("fretsim: paused at {stage}");
        std::thread::sleep(std::time::Duration::from_secs(120));
    }
}

/// Folders no run may write into: the current folder and its ancestors, the home folder, and
/// the folder of the scenario file with its ancestors.
#[derive(Debug, Clone, Default)]
pub struct Protected {
    cwd: Option<PathBuf>,
    home: Option<PathBuf>,
    scenario_dir: Option<PathBuf>,
}

impl Protected {
    /// The protected folders for a run of the scenario file `scenario` (none for the built-in).
    pub fn new(scenario: Option<&Path>) -> Self {
        let canonical = |p: &Path| fs::canonicalize(p).ok();
        Self {
            cwd: std::env::current_dir().ok().and_then(|p| canonical(&p)),
            home: std::env::var_os("HOME").and_then(|h| canonical(Path::new(&h))),
            scenario_dir: scenario.and_then(|s| {
                let parent = s.parent().filter(|p| !p.as_os_str().is_empty());
                canonical(parent.unwrap_or(Path::new(".")))
            }),
        }
    }

    /// Why `target` (canonical) may not be written, if it may not.
    fn check(&self, shown: &Path, target: &Path) -> Result<(), Error> {
        if self.cwd.as_deref().is_some_and(|c| c.starts_with(target)) {
            return Err(refuse(
                shown,
                "it is the current folder or one of its ancestors",
            ));
        }
        if self.home.as_deref() == Some(target) {
            return Err(refuse(shown, "it is the home folder"));
        }
        if self
            .scenario_dir
            .as_deref()
            .is_some_and(|s| s.starts_with(target))
        {
            return Err(refuse(
                shown,
                "it holds the scenario file (the scenario's own folder or an ancestor)",
            ));
        }
        Ok(())
    }
}

/// The target's canonical parent and file name. An existing folder is resolved as it is
/// (`.`, `..`, links in its parents); a new one must end in a plain name, and its parent is
/// created if missing. `/` has no parent and is refused.
fn resolve(target: &Path) -> Result<(PathBuf, String), Error> {
    let is_dir = fs::symlink_metadata(target).is_ok_and(|m| m.is_dir());
    let (parent, name) = if is_dir {
        let canonical = fs::canonicalize(target).map_err(write_err(target))?;
        match (canonical.parent(), canonical.file_name()) {
            (Some(p), Some(n)) => (p.to_path_buf(), n.to_string_lossy().into_owned()),
            _ => return Err(refuse(target, "it is the root folder")),
        }
    } else {
        let Some(Component::Normal(name)) = target.components().next_back() else {
            return Err(refuse(target, "it must end in a folder name"));
        };
        let parent = target
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        fs::create_dir_all(parent).map_err(write_err(parent))?;
        let parent = fs::canonicalize(parent).map_err(write_err(parent))?;
        (parent, name.to_string_lossy().into_owned())
    };
    Ok((parent, name))
}

/// Every file and folder under `dir`, relative, `/`-separated; folders end in `/`.
fn entries(dir: &Path) -> std::io::Result<Vec<String>> {
    fn walk(root: &Path, rel: &str, out: &mut Vec<String>) -> std::io::Result<()> {
        for entry in fs::read_dir(root.join(rel))? {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = if rel.is_empty() {
                name
            } else {
                format!("{rel}/{name}")
            };
            if entry.file_type()?.is_dir() {
                out.push(format!("{path}/"));
                walk(root, &path, out)?;
            } else {
                out.push(path);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    walk(dir, "", &mut out)?;
    out.sort();
    Ok(out)
}

fn read_manifest(dir: &Path) -> Option<Manifest> {
    let text = fs::read_to_string(dir.join(MANIFEST)).ok()?;
    serde_json::from_str(&text).ok()
}

/// The first entry of `dir` that its manifest does not account for (`Ok(None)`: all are), or
/// why the folder is not a fretsim folder of `kind`.
fn foreign_entry(dir: &Path, kind: FolderKind) -> Result<Option<String>, String> {
    let all = entries(dir).map_err(|e| format!("it cannot be read ({e})"))?;
    // A sweep folder that another shard is creating holds only fretsim's hidden files until
    // its manifest is in place: it counts as empty.
    if all
        .iter()
        .all(|e| kind == FolderKind::Sweep && hidden_ours(e))
    {
        return Ok(None);
    }
    let Some(manifest) = read_manifest(dir) else {
        return Err(format!(
            "it exists and is not a fretsim output (it has no readable {MANIFEST})"
        ));
    };
    if manifest.kind != kind {
        return Err(format!(
            "it is the output of another fretsim command (a {} folder)",
            match manifest.kind {
                FolderKind::Run => "run",
                FolderKind::Sweep => "sweep",
            }
        ));
    }
    let known = |e: &str| match kind {
        FolderKind::Run => {
            e == MANIFEST
                || manifest
                    .files
                    .iter()
                    .any(|f| f == e || (e.ends_with('/') && f.starts_with(e)))
        }
        FolderKind::Sweep => sweep_entry(e),
    };
    Ok(all.into_iter().find(|e| !known(e)))
}

/// Whether the top-level name of entry `e` is one of fretsim's hidden lock, staging or
/// temporary files.
fn hidden_ours(e: &str) -> bool {
    let top = e.split('/').next().unwrap_or(e);
    top.starts_with('.')
        && [
            ".fretsim-lock",
            ".fretsim-new",
            ".fretsim-old",
            ".fretsim-tmp",
        ]
        .iter()
        .any(|s| top.ends_with(s))
}

/// The names a sweep folder may hold: its manifest, index, CSV files, plots, the
/// variants' folders (each checked as a run folder when it is written) and fretsim's hidden
/// staging, lock and temporary files.
fn sweep_entry(e: &str) -> bool {
    let top = e.split('/').next().unwrap_or(e);
    hidden_ours(e)
        || e == MANIFEST
        || e == "index.html"
        || e == "sweep.csv"
        || (e.starts_with("sweep-") && e.ends_with(".csv") && !e.contains('/'))
        || top.starts_with("variant_")
        || e == "plots/"
        || sweep_plot(e)
}

/// A sweep's plot: `plots/{compare,sweep,map}_<name>.{svg,png}`.
fn sweep_plot(e: &str) -> bool {
    e.strip_prefix("plots/").is_some_and(|name| {
        !name.contains('/')
            && ["compare_", "sweep_", "map_"]
                .iter()
                .any(|p| name.starts_with(p))
            && (name.ends_with(".svg") || name.ends_with(".png"))
    })
}

/// Whether `dir` is a leftover of fretsim's own: a staging folder with its marker, or an
/// output with a manifest that accounts for every entry.
fn is_ours(dir: &Path, kind: FolderKind) -> bool {
    dir.join(STAGING_MARKER).is_file() || matches!(foreign_entry(dir, kind), Ok(None))
}

/// Remove `dir` if it exists and is fretsim's own leftover; refuse otherwise.
fn clear_leftover(dir: &Path, kind: FolderKind, shown: &Path) -> Result<(), Error> {
    match fs::symlink_metadata(dir) {
        Err(_) => Ok(()),
        Ok(m) if m.is_dir() && is_ours(dir, kind) => {
            fs::remove_dir_all(dir).map_err(write_err(dir))
        }
        Ok(_) => Err(refuse(
            shown,
            format!(
                "`{}` is in the way and fretsim did not write it",
                dir.display()
            ),
        )),
    }
}

/// An exclusive advisory lock on a file, removed when released.
#[derive(Debug)]
struct Lock {
    path: PathBuf,
    file: fs::File,
}

impl Lock {
    /// Take the lock at `path` or refuse `shown` (another process holds it). The lock file is
    /// re-checked after locking: a holder that finished may have removed it meanwhile.
    fn take(path: PathBuf, shown: &Path) -> Result<Self, Error> {
        use std::os::unix::fs::MetadataExt;
        loop {
            let file = fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)
                .map_err(write_err(&path))?;
            if rustix::fs::flock(&file, rustix::fs::FlockOperation::NonBlockingLockExclusive)
                .is_err()
            {
                return Err(refuse(
                    shown,
                    format!(
                        "another fretsim process is writing it (lock `{}`); wait for it to finish or choose another --out",
                        path.display()
                    ),
                ));
            }
            let held = file.metadata().map_err(write_err(&path))?;
            match fs::metadata(&path) {
                Ok(now) if now.ino() == held.ino() && now.dev() == held.dev() => {
                    return Ok(Self { path, file });
                }
                _ => continue,
            }
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Removed while still held, so no other process can hold a lock on this file.
        let _ = fs::remove_file(&self.path);
        let _ = &self.file;
    }
}

/// A run's output folder, claimed before the solve and swapped into place by
/// [`RunFolder::commit`]. Dropped without a commit, it removes its staging folder and leaves
/// the target as it was.
#[derive(Debug)]
pub struct RunFolder {
    target: PathBuf,
    staging: PathBuf,
    old: PathBuf,
    files: Vec<String>,
    committed: bool,
    _lock: Lock,
}

impl RunFolder {
    /// Check that `target` may be written (see the module docs), lock it and create its
    /// staging folder. Nothing is solved yet and nothing of the user's is touched.
    pub fn claim(target: &Path, protected: &Protected) -> Result<Self, Error> {
        let (parent, name) = allowed(target, protected, FolderKind::Run)?;
        let lock = Lock::take(parent.join(format!(".{name}.fretsim-lock")), target)?;
        Self::claim_locked(target, (parent, name), lock)
    }

    /// [`Self::claim`] of `target` (canonical parent and name) under the lock `lock`.
    fn claim_locked(
        target: &Path,
        (parent, name): (PathBuf, String),
        lock: Lock,
    ) -> Result<Self, Error> {
        let canonical = parent.join(&name);
        let staging = parent.join(format!(".{name}.fretsim-new"));
        let old = parent.join(format!(".{name}.fretsim-old"));
        clear_leftover(&staging, FolderKind::Run, target)?;
        clear_leftover(&old, FolderKind::Run, target)?;
        // Checked again under the lock: a run that held it may have just replaced the target.
        check_target(target, &canonical, FolderKind::Run)?;
        fs::create_dir(&staging).map_err(write_err(&staging))?;
        fs::write(staging.join(STAGING_MARKER), b"").map_err(write_err(&staging))?;
        Ok(Self {
            target: target.to_path_buf(),
            staging,
            old,
            files: Vec::new(),
            committed: false,
            _lock: lock,
        })
    }

    /// Check, without claiming it, that `target` could be claimed now (a sweep checks its
    /// variants' folders before it solves any).
    pub fn check(target: &Path, protected: &Protected) -> Result<(), Error> {
        allowed(target, protected, FolderKind::Run).map(|_| ())
    }

    /// Write one file (relative, `/`-separated) into the staging folder.
    pub fn write(&mut self, relative: &str, bytes: &[u8]) -> Result<(), Error> {
        let path = self.staging.join(relative);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent).map_err(write_err(parent))?;
        }
        let mut f = fs::File::create(&path).map_err(write_err(&path))?;
        f.write_all(bytes).map_err(write_err(&path))?;
        self.files.push(relative.to_string());
        Ok(())
    }

    /// Create one file (relative, `/`-separated) in the staging folder, to be written through
    /// the buffered writer returned with its path (`steps.csv`, written as the steps are taken).
    pub fn create(&mut self, relative: &str) -> Result<(PathBuf, std::io::BufWriter<fs::File>), Error> {
        let path = self.staging.join(relative);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent).map_err(write_err(parent))?;
        }
        let file = fs::File::create(&path).map_err(write_err(&path))?;
        self.files.push(relative.to_string());
        Ok((path, std::io::BufWriter::new(file)))
    }

    /// Save a checkpoint in the staging folder (`checkpoint/`, [`super::checkpoint`]):
    /// append `records` to `records.jsonl`, then replace `state.json` by `state` (written
    /// aside and renamed, so that it is always whole).
    pub fn save_checkpoint(&mut self, state: &[u8], records: &[u8]) -> Result<(), Error> {
        let dir = self.staging.join(CHECKPOINT);
        fs::create_dir_all(&dir).map_err(write_err(&dir))?;
        let path = dir.join("records.jsonl");
        let mut f = fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(write_err(&path))?;
        f.write_all(records).map_err(write_err(&path))?;
        let aside = dir.join("state.json.new");
        fs::write(&aside, state).map_err(write_err(&aside))?;
        let path = dir.join("state.json");
        fs::rename(&aside, &path).map_err(write_err(&path))
    }

    /// Claim `target` as [`Self::claim`] does, taking over the checkpoint that an
    /// interrupted run on it left in its staging folder: its `state.json` (the bytes) and
    /// `records.jsonl` (the open file, read by `read` a line at a time, and still readable
    /// after the claim replaced it), read by `read` (`None` when there is none), which also
    /// says how many bytes of `records.jsonl` belong to the checkpoint. Those are kept in the
    /// new staging folder with the state until the next checkpoint replaces it. When `read`
    /// refuses them, nothing is touched.
    pub fn claim_resuming<T>(
        target: &Path,
        protected: &Protected,
        read: impl FnOnce(&[u8], &mut fs::File) -> Result<(T, u64), Error>,
    ) -> Result<(Self, Option<T>), Error> {
        let (parent, name) = allowed(target, protected, FolderKind::Run)?;
        let staging = parent.join(format!(".{name}.fretsim-new"));
        // Read under the lock that the claim takes; the claim then clears the old staging
        // folder.
        let lock = Lock::take(parent.join(format!(".{name}.fretsim-lock")), target)?;
        let dir = staging.join(CHECKPOINT);
        let found = if staging.join(STAGING_MARKER).is_file() {
            match (
                fs::read(dir.join("state.json")),
                fs::File::open(dir.join("records.jsonl")),
            ) {
                (Ok(state), Ok(records)) => Some((state, records)),
                _ => None,
            }
        } else {
            None
        };
        let (state, mut records, resume, bytes) = match found {
            Some((state, mut records)) => {
                let (resume, bytes) = read(&state, &mut records)?;
                (state, records, resume, bytes)
            }
            None => {
                let folder = Self::claim_locked(target, (parent, name), lock)?;
                return Ok((folder, None));
            }
        };
        let mut folder = Self::claim_locked(target, (parent, name), lock)?;
        // The checkpoint's lines of the old `records.jsonl`, copied from the open file.
        let dir = folder.staging.join(CHECKPOINT);
        fs::create_dir_all(&dir).map_err(write_err(&dir))?;
        let path = dir.join("records.jsonl");
        let mut copy = fs::File::create(&path).map_err(write_err(&path))?;
        records
            .seek(std::io::SeekFrom::Start(0))
            .and_then(|_| std::io::copy(&mut (&records).take(bytes), &mut copy))
            .map_err(write_err(&path))?;
        folder.save_checkpoint(&state, b"")?;
        Ok((folder, Some(resume)))
    }

    /// The files written so far.
    pub fn files(&self) -> &[String] {
        &self.files
    }

    /// Write the manifest and swap the staging folder in for the target.
    pub fn commit(mut self) -> Result<PathBuf, Error> {
        pause_point("write");
        let checkpoint = self.staging.join(CHECKPOINT);
        if checkpoint.exists() {
            fs::remove_dir_all(&checkpoint).map_err(write_err(&checkpoint))?;
        }
        let mut files = self.files.clone();
        files.sort();
        let manifest = Manifest {
            kind: FolderKind::Run,
            fretsim_version: env!("CARGO_PKG_VERSION").into(),
            files,
        };
        let bytes = serde_json::to_vec_pretty(&manifest).expect("a manifest serialises");
        let path = self.staging.join(MANIFEST);
        fs::write(&path, bytes).map_err(write_err(&path))?;
        fs::remove_file(self.staging.join(STAGING_MARKER)).map_err(write_err(&self.staging))?;
        pause_point("swap");
        swap_in(&self.staging, &self.target, &self.old)?;
        self.committed = true;
        pause_point("cleanup");
        if self.old.exists() {
            // The old output is fretsim's (checked under the lock); marked, then removed.
            fs::write(self.old.join(STAGING_MARKER), b"").map_err(write_err(&self.old))?;
            fs::remove_dir_all(&self.old).map_err(write_err(&self.old))?;
        }
        Ok(self.target.clone())
    }
}

impl Drop for RunFolder {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

/// The target's canonical parent and name, once it is known to be neither protected nor
/// anything but a fretsim folder of `kind` (or absent, or empty).
fn allowed(
    target: &Path,
    protected: &Protected,
    kind: FolderKind,
) -> Result<(PathBuf, String), Error> {
    let (parent, name) = resolve(target)?;
    let canonical = parent.join(&name);
    protected.check(target, &canonical)?;
    check_target(target, &canonical, kind)?;
    Ok((parent, name))
}

/// Refuse an existing target that is not a fretsim folder of `kind` (an empty folder is
/// accepted: it holds nothing to lose).
fn check_target(shown: &Path, canonical: &Path, kind: FolderKind) -> Result<(), Error> {
    let meta = match fs::symlink_metadata(canonical) {
        Err(_) => return Ok(()),
        Ok(m) => m,
    };
    if meta.file_type().is_symlink() {
        return Err(refuse(shown, "it is a symbolic link"));
    }
    if !meta.is_dir() {
        return Err(refuse(shown, "it is a file, not a folder"));
    }
    match foreign_entry(canonical, kind) {
        Ok(None) => Ok(()),
        Ok(Some(e)) => Err(refuse(
            shown,
            format!(
                "it holds `{e}`, which fretsim did not write; fretsim replaces only its own output"
            ),
        )),
        Err(reason) => Err(refuse(
            shown,
            format!("{reason}; fretsim writes only into a new folder or one it wrote before"),
        )),
    }
}

/// Put `staging` at `target`: exchanged with the existing target in one rename (which then
/// sits at `old`), or renamed into place when there is none.
fn swap_in(staging: &Path, target: &Path, old: &Path) -> Result<(), Error> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    let exchanged = renameat_with(CWD, staging, CWD, target, RenameFlags::EXCHANGE);
    match exchanged {
        Ok(()) => renameat_with(CWD, staging, CWD, old, RenameFlags::NOREPLACE)
            .map_err(|e| write_err(old)(e.into())),
        Err(rustix::io::Errno::NOENT) => {
            renameat_with(CWD, staging, CWD, target, RenameFlags::NOREPLACE)
                .map_err(|e| write_err(target)(e.into()))
        }
        Err(e) => Err(write_err(target)(e.into())),
    }
}

/// A sweep's output folder: created with a `sweep` manifest, or an existing one of fretsim's;
/// each shard locks its own CSV file's name.
#[derive(Debug)]
pub struct SweepFolder {
    dir: PathBuf,
    _lock: Lock,
}

impl SweepFolder {
    /// Check, create and lock the sweep folder `target` for the CSV file `csv_name`.
    pub fn claim(target: &Path, csv_name: &str, protected: &Protected) -> Result<Self, Error> {
        let (parent, name) = allowed(target, protected, FolderKind::Sweep)?;
        let canonical = parent.join(&name);
        if read_manifest(&canonical).is_none() {
            fs::create_dir_all(&canonical).map_err(write_err(target))?;
            let manifest = Manifest {
                kind: FolderKind::Sweep,
                fretsim_version: env!("CARGO_PKG_VERSION").into(),
                files: Vec::new(),
            };
            let bytes = serde_json::to_vec_pretty(&manifest).expect("a manifest serialises");
            write_atomic(&canonical.join(MANIFEST), &bytes)?;
        }
        let lock = Lock::take(canonical.join(format!(".{csv_name}.fretsim-lock")), target)?;
        Ok(Self {
            dir: target.to_path_buf(),
            _lock: lock,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// Write one file of a claimed folder atomically (a temporary file beside it, then a rename),
/// creating its folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    fs::create_dir_all(parent).map_err(write_err(parent))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = parent.join(format!(".{name}.{}.fretsim-tmp", std::process::id()));
    let result = fs::write(&tmp, bytes).and_then(|()| fs::rename(&tmp, path));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(write_err(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn protected_none() -> Protected {
        Protected::default()
    }

    fn run_once(target: &Path, files: &[(&str, &str)]) {
        let mut folder = RunFolder::claim(target, &protected_none()).unwrap();
        for (name, text) in files {
            folder.write(name, text.as_bytes()).unwrap();
        }
        folder.commit().unwrap();
    }

    fn hidden_entries(parent: &Path) -> Vec<String> {
        fs::read_dir(parent)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect()
    }

    #[test]
    fn a_new_folder_is_written_with_its_manifest_and_nothing_hidden_is_left() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        run_once(&target, &[("a.csv", "1"), ("fields/b.csv", "2")]);
        let manifest = read_manifest(&target).unwrap();
        assert_eq!(manifest.files, vec!["a.csv", "fields/b.csv"]);
        assert_eq!(
            fs::read_to_string(target.join("fields/b.csv")).unwrap(),
            "2"
        );
        assert!(hidden_entries(tmp.path()).is_empty());
    }

    #[test]
    fn a_previous_output_is_replaced_as_a_whole() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        run_once(&target, &[("a.csv", "old"), ("stale.csv", "old")]);
        run_once(&target, &[("a.csv", "new")]);
        assert_eq!(fs::read_to_string(target.join("a.csv")).unwrap(), "new");
        assert!(!target.join("stale.csv").exists());
        assert!(hidden_entries(tmp.path()).is_empty());
    }

    #[test]
    fn a_folder_with_a_users_file_is_refused_and_left_alone() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("notes.txt"), "mine").unwrap();
        let err = RunFolder::claim(&target, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("not a fretsim output"), "{err}");
        assert_eq!(err.exit_code(), 2);
        assert_eq!(
            fs::read_to_string(target.join("notes.txt")).unwrap(),
            "mine"
        );
        assert!(hidden_entries(tmp.path()).is_empty());
    }

    #[test]
    fn a_users_file_added_to_a_previous_output_makes_it_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        run_once(&target, &[("a.csv", "old")]);
        fs::write(target.join("fields.txt"), "mine").unwrap();
        let err = RunFolder::claim(&target, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("`fields.txt`"), "{err}");
        assert!(target.join("fields.txt").exists());
    }

    #[test]
    fn a_file_a_link_and_a_dot_name_are_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("file");
        fs::write(&file, "x").unwrap();
        let err = RunFolder::claim(&file, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("is a file"), "{err}");
        let link = tmp.path().join("link");
        std::os::unix::fs::symlink(tmp.path(), &link).unwrap();
        let err = RunFolder::claim(&link, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        let err = RunFolder::claim(Path::new("/"), &protected_none()).unwrap_err();
        assert!(err.to_string().contains("root folder"), "{err}");
        let err = RunFolder::claim(&file.join(".."), &protected_none()).unwrap_err();
        assert!(err.to_string().contains("folder name"), "{err}");
        assert_eq!(fs::read_to_string(&file).unwrap(), "x");
        assert!(hidden_entries(tmp.path()).is_empty());
    }

    #[test]
    fn the_scenario_folder_and_its_ancestors_are_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("study");
        fs::create_dir(&dir).unwrap();
        let protected = Protected::new(Some(&dir.join("s.json")));
        for p in [dir.clone(), tmp.path().to_path_buf()] {
            let err = RunFolder::claim(&p, &protected).unwrap_err();
            assert!(err.to_string().contains("scenario"), "{err}");
        }
        assert!(RunFolder::claim(&dir.join("out"), &protected).is_ok());
    }

    #[test]
    fn a_second_claim_of_a_locked_folder_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        let first = RunFolder::claim(&target, &protected_none()).unwrap();
        let err = RunFolder::claim(&target, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("another fretsim process"), "{err}");
        drop(first);
        assert!(hidden_entries(tmp.path()).is_empty());
        assert!(!target.exists());
    }

    #[test]
    fn leftovers_of_a_killed_run_are_removed_by_the_next_run() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("out");
        run_once(&target, &[("a.csv", "old")]);
        // A staging folder killed mid-write and an old output killed mid-removal.
        let staging = tmp.path().join(".out.fretsim-new");
        fs::create_dir(&staging).unwrap();
        fs::write(staging.join(STAGING_MARKER), "").unwrap();
        fs::write(staging.join("half.csv"), "x").unwrap();
        let old = tmp.path().join(".out.fretsim-old");
        fs::create_dir(&old).unwrap();
        fs::write(old.join(STAGING_MARKER), "").unwrap();
        fs::write(tmp.path().join(".out.fretsim-lock"), "").unwrap();
        run_once(&target, &[("a.csv", "new")]);
        assert!(hidden_entries(tmp.path()).is_empty());
    }

    #[test]
    fn a_hidden_folder_in_the_way_that_fretsim_did_not_write_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let staging = tmp.path().join(".out.fretsim-new");
        fs::create_dir(&staging).unwrap();
        fs::write(staging.join("mine.txt"), "x").unwrap();
        let err = RunFolder::claim(&tmp.path().join("out"), &protected_none()).unwrap_err();
        assert!(err.to_string().contains("in the way"), "{err}");
        assert!(staging.join("mine.txt").exists());
    }

    /// Two shards start at once: the second finds the folder with only the first one's
    /// temporary manifest in it, which is no reason to refuse it.
    #[test]
    fn a_sweep_folder_being_created_by_another_shard_is_accepted() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("sw");
        fs::create_dir(&target).unwrap();
        fs::write(target.join(".fretsim-manifest.json.1.fretsim-tmp"), "{").unwrap();
        assert!(SweepFolder::claim(&target, "sweep-2-of-2.csv", &protected_none()).is_ok());
        assert!(read_manifest(&target).is_some());
        // A run folder is never shared: the same leftover inside it is not its own.
        let run = tmp.path().join("run");
        fs::create_dir(&run).unwrap();
        fs::write(run.join(".x.fretsim-tmp"), "").unwrap();
        assert!(RunFolder::claim(&run, &protected_none()).is_err());
    }

    #[test]
    fn a_sweep_folder_accepts_its_own_files_and_refuses_others() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("sw");
        let folder = SweepFolder::claim(&target, "sweep.csv", &protected_none()).unwrap();
        write_atomic(&folder.dir().join("sweep.csv"), b"x").unwrap();
        run_once(&folder.dir().join("variant_0000"), &[("a.csv", "1")]);
        drop(folder);
        assert!(SweepFolder::claim(&target, "sweep.csv", &protected_none()).is_ok());
        // A run folder is not a sweep folder, nor the reverse.
        let err = RunFolder::claim(&target, &protected_none()).unwrap_err();
        assert!(err.to_string().contains("another fretsim command"), "{err}");
        fs::write(target.join("notes.txt"), "mine").unwrap();
        let err = SweepFolder::claim(&target, "sweep.csv", &protected_none()).unwrap_err();
        assert!(err.to_string().contains("`notes.txt`"), "{err}");
    }
}
