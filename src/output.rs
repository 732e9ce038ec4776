//! Writing results: a staging folder that replaces the target only when every file is written,
//! so a run never leaves half-written files or stale files from an older run.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::Error;

/// A folder being filled; [`Staging::commit`] swaps it into place.
#[derive(Debug)]
pub struct Staging {
    target: PathBuf,
    dir: PathBuf,
}

fn write_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::WriteOutput {
        path: path.to_path_buf(),
        source,
    }
}

impl Staging {
    /// Start filling a staging folder beside `target`.
    pub fn new(target: &Path) -> Result<Self, Error> {
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let parent = target
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        fs::create_dir_all(parent).map_err(write_err(parent))?;
        let dir = parent.join(format!(".{name}.partial-{}", std::process::id()));
        if dir.exists() {
            fs::remove_dir_all(&dir).map_err(write_err(&dir))?;
        }
        fs::create_dir_all(&dir).map_err(write_err(&dir))?;
        Ok(Self {
            target: target.to_path_buf(),
            dir,
        })
    }

    /// Write one file (relative path) into the staging folder.
    pub fn write(&self, relative: &str, bytes: &[u8]) -> Result<(), Error> {
        let path = self.dir.join(relative);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent).map_err(write_err(parent))?;
        }
        let mut f = fs::File::create(&path).map_err(write_err(&path))?;
        f.write_all(bytes).map_err(write_err(&path))?;
        Ok(())
    }

    /// Replace the target folder by the staging folder.
    pub fn commit(self) -> Result<PathBuf, Error> {
        if self.target.exists() {
            fs::remove_dir_all(&self.target).map_err(write_err(&self.target))?;
        }
        fs::rename(&self.dir, &self.target).map_err(write_err(&self.target))?;
        Ok(self.target.clone())
    }

    /// Drop the staging folder (after a failure).
    pub fn abandon(self) {
        let _ = fs::remove_dir_all(&self.dir);
    }
}

/// Serialise rows as CSV with a header line.
pub fn csv_bytes(header: &[&str], rows: &[Vec<f64>]) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header).expect("in-memory write");
    for row in rows {
        w.write_record(row.iter().map(|v| format!("{v:.10e}")))
            .expect("in-memory write");
    }
    w.into_inner().expect("in-memory write")
}

/// Write one file atomically (temporary file beside it, then rename), creating its folder.
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
    let tmp = parent.join(format!(".{name}.partial-{}", std::process::id()));
    let result = fs::write(&tmp, bytes).and_then(|()| fs::rename(&tmp, path));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(write_err(path))
}
