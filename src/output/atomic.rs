//! Files replaced whole: written to a temporary sibling (`NAME.part`) and renamed
//! over the target, so that a reader, or a run killed while writing, never leaves
//! a truncated file (a rename within a directory is atomic on POSIX file systems).
//! summary.json, particles_final.csv, the ParaView frames and `.pvd`, and the
//! checkpoints are written this way; history.csv and newton.csv grow row by row.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The temporary sibling of `path`.
fn part(path: &Path) -> PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".part");
    PathBuf::from(tmp)
}

/// Write `path` through a buffered writer on its temporary sibling, then rename.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    replace(path, |tmp| {
        let mut w = BufWriter::new(File::create(tmp)?);
        write(&mut w)?;
        w.flush()
    })
}

/// Let `create` write the temporary sibling of `path` (by its path), then rename
/// it over `path`; on an error the temporary file is removed.
pub fn replace(path: &Path, create: impl FnOnce(&Path) -> io::Result<()>) -> io::Result<()> {
    let tmp = part(path);
    match create(&tmp) {
        Ok(()) => fs::rename(&tmp, path),
        Err(e) => {
            fs::remove_file(&tmp).ok();
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_the_old_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.json");
        write_atomically(&path, |w| w.write_all(b"old")).unwrap();
        let e = write_atomically(&path, |w| {
            w.write_all(b"half of the new")?;
            Err(io::Error::other("disk full"))
        });
        assert!(e.is_err());
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert!(!part(&path).exists());
        write_atomically(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new");
        assert!(!part(&path).exists());
    }
}
