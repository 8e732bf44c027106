//! Result writers: the result JSON ([`json`]), ROS joint states ([`joint_states`]), the pose
//! in other tools' terms ([`configuration`]: MuJoCo's `qpos`, Pinocchio's `q`; [`mujoco`]: a
//! MuJoCo keyframe; [`srdf`]: a MoveIt named state), the bodies resting inside a ground ([`buried`]), and atomic file output. The URDF write-back is [`crate::urdf::with_initial_pose`].

pub mod buried;
pub mod configuration;
mod indent;
pub mod joint_states;
pub mod json;
pub mod mujoco;
pub mod srdf;
pub mod summary;

pub use indent::{pretty_json, pretty_json_to};

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// The buffer between a streamed writer and its file [bytes].
const BUFFER: usize = 64 * 1024;

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, then a rename,
/// so that a reader never sees a half-written file. A symbolic link is followed (its target
/// is replaced, not the link). A path that is not a file (`/dev/null`, `/dev/stdout`, a
/// named pipe) is written in place: a rename would replace the device or pipe itself.
///
/// # Errors
/// [`Error::Io`] if the folder is not writable.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// [`write_atomic`] of the bytes that `write` writes, passed on through a small buffer as
/// they come (a large result is never held whole in memory).
///
/// # Errors
/// [`Error::Io`] if the folder is not writable or `write` fails.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let io = |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    };
    let resolved;
    let path = match (std::fs::metadata(path), std::fs::symlink_metadata(path)) {
        (Ok(target), _) if !target.is_file() && !target.is_dir() => {
            return std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .and_then(|f| {
                    let mut w = std::io::BufWriter::with_capacity(BUFFER, f);
                    write(&mut w)?;
                    w.flush()
                })
                .map_err(io);
        }
        (Ok(_), Ok(link)) if link.file_type().is_symlink() => {
            resolved = std::fs::canonicalize(path).map_err(io)?;
            resolved.as_path()
        }
        _ => path,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let f = std::fs::File::create(&tmp).map_err(io)?;
    let mut w = std::io::BufWriter::with_capacity(BUFFER, f);
    let written = write(&mut w)
        .and_then(|_| w.into_inner().map_err(std::io::IntoInnerError::into_error))
        .and_then(|f| f.sync_all());
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

#[cfg(test)]
mod tests {
    use super::write_atomic;

    #[test]
    fn a_device_is_written_in_place_and_a_link_through() {
        let dir = std::env::temp_dir().join(format!("restpose-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A named pipe stays the pipe and its reader gets the bytes (as `/dev/null` stays the
        // device: a rename would have put a file in its place).
        let fifo = dir.join("pipe.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let reader = {
                let fifo = fifo.clone();
                std::thread::spawn(move || std::fs::read(fifo).unwrap())
            };
            write_atomic(&fifo, b"{}").unwrap();
            let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
            assert!(!kind.is_file(), "the pipe was replaced by a file");
            assert_eq!(reader.join().unwrap(), b"{}");
        }
        let file = dir.join("pose.json");
        write_atomic(&file, b"one").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"one");
        #[cfg(unix)]
        {
            let link = dir.join("link.json");
            std::os::unix::fs::symlink(&file, &link).unwrap();
            write_atomic(&link, b"two").unwrap();
            assert!(std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink());
            assert_eq!(std::fs::read(&file).unwrap(), b"two");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A text streamed in small pieces, several times the buffer, arrives whole and in
    /// order; a writer that fails leaves no file and names the path.
    #[test]
    fn a_streamed_text_arrives_whole_and_a_failure_leaves_nothing() {
        use super::{write_atomic_with, BUFFER};
        let dir = std::env::temp_dir().join(format!("restpose-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("result.json");
        let piece = |k: usize| format!("{k:07},").into_bytes();
        let pieces = 3 * BUFFER / 8 + 5;
        write_atomic_with(&file, |w| {
            (0..pieces).try_for_each(|k| w.write_all(&piece(k)))
        })
        .unwrap();
        let want: Vec<u8> = (0..pieces).flat_map(piece).collect();
        assert!(want.len() > 3 * BUFFER);
        assert_eq!(std::fs::read(&file).unwrap(), want);
        let failed = dir.join("failed.json");
        let err = write_atomic_with(&failed, |w| {
            w.write_all(&vec![b'x'; 2 * BUFFER])?;
            Err(std::io::Error::other("serializer gave up"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("failed.json"), "{err}");
        let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(left.len(), 1, "only the first file is left");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
