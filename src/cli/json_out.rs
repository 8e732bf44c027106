//! The JSON outputs (`--json FILE`, `-` for standard output): the text formed by the
//! serializer (module `export::indent`) streamed through a 64 KiB buffer into the file, written
//! atomically, or to standard output; never held whole (a result at 10,000 links is 10 MB).

/// `value` as pretty JSON into `w` (module `export::indent`), for [`write`].
pub(crate) fn pretty<T: serde::Serialize>(
    w: &mut dyn std::io::Write,
    value: &T,
) -> std::io::Result<()> {
    restpose::export::pretty_json_to(w, value).map_err(Into::into)
}

/// Writes the JSON text that `write` forms to `path` atomically, or to standard output for
/// `-` (with a line break after it), streamed as it comes instead of held whole.
pub(crate) fn write(
    path: &std::path::Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    use std::io::Write;
    if path.as_os_str() == "-" {
        // Buffered in blocks, not flushed at each of the text's line breaks.
        let mut stdout = std::io::BufWriter::with_capacity(64 * 1024, std::io::stdout().lock());
        let _ = write(&mut stdout)
            .and_then(|_| stdout.write_all(b"\n"))
            .and_then(|_| stdout.flush());
    } else {
        restpose::export::write_atomic_with(path, write)?;
    }
    Ok(())
}
