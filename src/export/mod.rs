//! Result writers: the result JSON ([`json`]), ROS joint states ([`joint_states`]), the pose
//! in other tools' terms ([`configuration`]: MuJoCo's `qpos`, Pinocchio's `q`; [`mujoco`]: a
//! MuJoCo keyframe; [`srdf`]: a MoveIt named state), the bodies resting inside a ground ([`buried`]), and atomic file output. The URDF write-back is [`crate::urdf::with_initial_pose`].

pub mod buried;
pub mod configuration;
pub mod joint_states;
pub mod json;
pub mod mujoco;
pub mod srdf;
pub mod summary;

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, then a rename,
/// so that a reader never sees a half-written file.
///
/// # Errors
/// [`Error::Io`] if the folder is not writable.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |cause| Error::Io {
        path: path.display().to_string(),
        cause,
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
    let mut f = std::fs::File::create(&tmp).map_err(io)?;
    f.write_all(bytes).and_then(|_| f.sync_all()).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}
