//! `analyze`'s outputs in other tools' files: the MuJoCo keyframe (`--write-mujoco-key`) and
//! the MoveIt SRDF named state (`--write-srdf`).

use super::args::AnalyzeArgs;
use super::print;
use anyhow::{bail, Context};
use restpose::{Model, State};
use std::path::{Path, PathBuf};

/// Writes the requested files of a converged rest pose.
pub(crate) fn write(a: &AnalyzeArgs, model: &Model, state: &State) -> anyhow::Result<()> {
    let f = &a.formats;
    if let Some(out) = &f.write_mujoco_key {
        // MuJoCo reads the URDF: the written one when there is one, else the input.
        let urdf = match &a.write_urdf {
            Some(p) if !print::is_stdout(Some(p)) => p.clone(),
            _ => a.file.clone(),
        };
        if urdf
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xacro"))
        {
            bail!(
                "--write-mujoco-key {}: MuJoCo reads URDF, not xacro: add --write-urdf OUT.urdf \
                 (the expanded URDF, which the keyframe then loads)",
                out.display()
            );
        }
        let text = restpose::export::mujoco::mujoco_key(model, state, &relative(&urdf, out))
            .map_err(|e| anyhow::anyhow!("--write-mujoco-key {}: {e}", out.display()))?;
        print::write_output(out, &text)?;
    }
    if let Some(out) = &f.write_srdf {
        let text = restpose::export::srdf::srdf(model, state, &f.group, &f.state)
            .map_err(|e| anyhow::anyhow!("--write-srdf {}: {e}", out.display()))
            .with_context(|| format!("{}", a.file.display()))?;
        print::write_output(out, &text)?;
    }
    Ok(())
}

/// `file` as MuJoCo should open it from the folder of `out`: its name when both are in the
/// same folder, a path below that folder, else absolute.
fn relative(file: &Path, out: &Path) -> String {
    let abs = |p: &Path| -> PathBuf {
        std::path::absolute(p)
            .ok()
            .and_then(|p| {
                let parent = p.parent()?.canonicalize().ok()?;
                Some(parent.join(p.file_name()?))
            })
            .unwrap_or_else(|| p.to_path_buf())
    };
    let file = abs(file);
    if print::is_stdout(Some(&out.to_path_buf())) {
        return file.display().to_string();
    }
    let dir = abs(out).parent().map(Path::to_path_buf).unwrap_or_default();
    match file.strip_prefix(&dir) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => file.display().to_string(),
    }
}
