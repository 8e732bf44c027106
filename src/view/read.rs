//! Reading a recording back (rerun's own decoder), for tests and for `restpose view` checks.

use crate::error::{Error, Result};
use std::collections::BTreeSet;
use std::path::Path;

/// What a recording holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecordingSummary {
    /// Entity paths with data.
    pub entities: BTreeSet<String>,
    /// Timeline names.
    pub timelines: BTreeSet<String>,
    /// Rows logged on the `iteration` timeline, per entity path.
    pub chunks: usize,
}

/// Decodes the `.rrd` file at `path`.
///
/// # Errors
/// [`Error::Io`] if it cannot be read or decoded.
pub fn read_recording(path: &Path) -> Result<RecordingSummary> {
    let err = |e: &dyn std::fmt::Display| Error::Io {
        path: path.display().to_string(),
        cause: std::io::Error::other(e.to_string()),
    };
    let file = std::fs::File::open(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    let decoder = re_log_encoding::Decoder::<re_log_types::LogMsg>::decode_eager(
        std::io::BufReader::new(file),
    )
    .map_err(|e| err(&e))?;
    let mut out = RecordingSummary::default();
    for msg in decoder {
        let msg = msg.map_err(|e| err(&e))?;
        if let re_log_types::LogMsg::ArrowMsg(_, arrow) = msg {
            let chunk = re_chunk::Chunk::from_arrow_msg(&arrow).map_err(|e| err(&e))?;
            out.entities.insert(
                chunk
                    .entity_path()
                    .to_string()
                    .trim_start_matches('/')
                    .to_string(),
            );
            out.timelines
                .extend(chunk.timelines().keys().map(|t| t.to_string()));
            out.chunks += 1;
        }
    }
    Ok(out)
}
