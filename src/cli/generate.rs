//! `restpose generate`: a generated benchmark mechanism as URDF on standard output.

use super::args::GenerateArgs;
use std::io::Write;

/// Writes the mechanism; a closed pipe is not an error.
pub(crate) fn run(a: &GenerateArgs) -> anyhow::Result<u8> {
    let text = restpose::generate::family(a.family.into(), a.size);
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    Ok(0)
}
