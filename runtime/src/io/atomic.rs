//! Files written all or nothing: every writer of the crate writes to a temporary file beside
//! the target (`NAME.partial`), flushes and syncs it, and renames it over the target only when
//! everything was written. A failure (a full disk, an error of the writer itself) removes the
//! temporary file and leaves whatever was under the target's name before, never a truncated
//! file under the real name.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::RuntimeError;

/// The temporary file beside `path` that [`write_atomically`] writes first.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(".partial");
    path.with_file_name(name)
}

/// Write `path` through `write`, all or nothing (the module's documentation).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), RuntimeError>,
) -> Result<(), RuntimeError> {
    let io = |source| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    };
    let partial = partial_path(path);
    let result = File::create(&partial).map_err(io).and_then(|file| {
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&partial, path).map_err(io)
    });
    if result.is_err() {
        // Best effort: the error that matters is the one returned.
        let _ = std::fs::remove_file(&partial);
    }
    result
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("subtess-atomic-{}-{name}", std::process::id()))
    }

    /// A writer that fails half way leaves the old file in place and no temporary file; one
    /// that succeeds replaces it.
    #[test]
    fn a_failed_write_leaves_the_old_file() {
        let path = temp("out.obj");
        std::fs::write(&path, b"old").expect("a file");
        let failed = write_atomically(&path, |w| {
            w.write_all(&[b'x'; 100_000])
                .map_err(|source| RuntimeError::Io {
                    path: "test".to_string(),
                    source,
                })?;
            Err(RuntimeError::Unsupported("the disk is full".to_string()))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&path).expect("still there"), b"old");
        assert!(
            !partial_path(&path).exists(),
            "the temporary file is removed"
        );
        write_atomically(&path, |w| {
            w.write_all(b"new").map_err(|source| RuntimeError::Io {
                path: "test".to_string(),
                source,
            })
        })
        .expect("written");
        assert_eq!(std::fs::read(&path).expect("replaced"), b"new");
        assert!(!partial_path(&path).exists());
        std::fs::remove_file(&path).ok();
    }

    /// Where the temporary file cannot be made, the error names the target and nothing is
    /// left behind.
    #[test]
    fn an_unwritable_folder_is_an_error_naming_the_target() {
        let path = temp("no-such-folder").join("out.ply");
        let e = write_atomically(&path, |_| Ok(())).expect_err("refused");
        assert!(e.to_string().contains("out.ply"), "{e}");
        assert!(!path.exists());
    }
}
