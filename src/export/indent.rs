//! Pretty JSON, byte for byte as `serde_json`'s `PrettyFormatter` writes it (a value or key
//! per line, two spaces a level, `": "` after a key, `[]` and `{}` when empty), with each
//! separator, line break and indentation written at once from one static run of spaces
//! instead of a write per level.

use serde_json::ser::Formatter;
use std::io;

/// `,`, a line break and the indentation of [`MAX_LEVEL`] levels: the line break before a
/// first entry at level `l` is `BREAK[1..2 + 2 l]`, before a later one `BREAK[..2 + 2 l]`.
const BREAK: &[u8; 2 + 2 * MAX_LEVEL] = &{
    let mut b = [b' '; 2 + 2 * MAX_LEVEL];
    b[0] = b',';
    b[1] = b'\n';
    b
};

/// The deepest level indented from [`BREAK`] (deeper ones are written level by level).
const MAX_LEVEL: usize = 31;

/// The formatter: the current level and whether the innermost array or object has an entry.
#[derive(Debug, Default)]
pub(super) struct Indented {
    level: usize,
    has_value: bool,
}

impl Indented {
    /// A line break at the current level, after `,` unless `first`.
    fn line<W: ?Sized + io::Write>(&self, w: &mut W, first: bool) -> io::Result<()> {
        let from = usize::from(first);
        match BREAK.get(from..2 + 2 * self.level) {
            Some(run) => w.write_all(run),
            None => {
                w.write_all(&BREAK[from..2])?;
                for _ in 0..self.level {
                    w.write_all(b"  ")?;
                }
                Ok(())
            }
        }
    }
}

impl Formatter for Indented {
    fn begin_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.level += 1;
        self.has_value = false;
        w.write_all(b"[")
    }

    fn end_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.level -= 1;
        if self.has_value {
            self.line(w, true)?;
        }
        w.write_all(b"]")
    }

    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.line(w, first)
    }

    fn end_array_value<W: ?Sized + io::Write>(&mut self, _w: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }

    fn begin_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.level += 1;
        self.has_value = false;
        w.write_all(b"{")
    }

    fn end_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.level -= 1;
        if self.has_value {
            self.line(w, true)?;
        }
        w.write_all(b"}")
    }

    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.line(w, first)
    }

    fn begin_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b": ")
    }

    fn end_object_value<W: ?Sized + io::Write>(&mut self, _w: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }
}

/// `value` as pretty JSON text, as `serde_json::to_string_pretty` writes it.
///
/// # Errors
/// The serializer's error (a map key that is not a string).
pub fn pretty_json<T: serde::Serialize + ?Sized>(value: &T) -> serde_json::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(4096);
    let mut ser = serde_json::Serializer::with_formatter(&mut out, Indented::default());
    value.serialize(&mut ser)?;
    Ok(out)
}

/// [`pretty_json`] written to `out` as it is formed (the same bytes, without the whole text in
/// memory: a result file is streamed through a small buffer).
///
/// # Errors
/// The serializer's error (a map key that is not a string) or the writer's.
pub fn pretty_json_to<W: io::Write, T: serde::Serialize + ?Sized>(
    out: W,
    value: &T,
) -> serde_json::Result<()> {
    let mut chunks = Chunks {
        buf: Vec::with_capacity(CHUNK),
        out,
    };
    let mut ser = serde_json::Serializer::with_formatter(&mut chunks, Indented::default());
    value.serialize(&mut ser)?;
    chunks.pass_on().map_err(serde_json::Error::io)
}

/// The bytes gathered before they are passed on.
const CHUNK: usize = 64 * 1024;

/// The serializer's many small writes (a separator, a number, a key: half a million for a
/// ladder of 1,000 rungs) gathered in a buffer of its own, whose test and copy inline into the
/// formatter, and passed on to the writer (possibly behind `dyn Write`) in chunks of
/// [`CHUNK`] bytes: the same bytes in the same order.
struct Chunks<W: io::Write> {
    buf: Vec<u8>,
    out: W,
}

impl<W: io::Write> Chunks<W> {
    /// Passes on the bytes gathered.
    fn pass_on(&mut self) -> io::Result<()> {
        let r = self.out.write_all(&self.buf);
        self.buf.clear();
        r
    }
}

impl<W: io::Write> io::Write for Chunks<W> {
    #[inline]
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.write_all(data).map(|()| data.len())
    }

    #[inline]
    fn write_all(&mut self, data: &[u8]) -> io::Result<()> {
        if self.buf.len() + data.len() > CHUNK {
            self.pass_on()?;
            if data.len() > CHUNK {
                return self.out.write_all(data);
            }
        }
        self.buf.extend_from_slice(data);
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        self.pass_on()?;
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same bytes as `serde_json`'s pretty printer, on empty and nested arrays and
    /// objects, non-finite numbers, escapes and levels deeper than the static run.
    #[test]
    fn same_bytes_as_serde_json_pretty() {
        let mut deep = serde_json::json!([1, {"k": []}]);
        for k in 0..40 {
            deep = serde_json::json!({ format!("level{k}"): [deep, {}, [], k] });
        }
        let values = [
            serde_json::json!(null),
            serde_json::json!([]),
            serde_json::json!({}),
            serde_json::json!({"a": [], "b": {}, "c": [[], [{}]], "d": "q\"\n\u{1}é"}),
            serde_json::json!([1.5, -0.0, 1e300, 2.2250738585072014e-308, 7, -3]),
            deep,
        ];
        for v in &values {
            let ours = String::from_utf8(pretty_json(v).unwrap()).unwrap();
            assert_eq!(ours, serde_json::to_string_pretty(v).unwrap());
        }
        let floats = [f64::NAN, f64::INFINITY, 0.1, 1.0 / 3.0];
        let ours = String::from_utf8(pretty_json(&floats).unwrap()).unwrap();
        assert_eq!(ours, serde_json::to_string_pretty(&floats).unwrap());
    }

    /// Streamed through the chunks: the same bytes across chunk boundaries, with a string
    /// longer than a chunk among them, into a writer that takes a few bytes at a time.
    #[test]
    fn streamed_text_is_the_same_bytes() {
        /// A writer that takes at most 7 bytes a call.
        struct Trickle(Vec<u8>);
        impl io::Write for Trickle {
            fn write(&mut self, data: &[u8]) -> io::Result<usize> {
                let n = data.len().min(7);
                self.0.extend_from_slice(&data[..n]);
                Ok(n)
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let rows: Vec<serde_json::Value> = (0..20_000)
            .map(|k| serde_json::json!({"k": k, "x": [k as f64 / 7.0, -0.5], "n": format!("j{k}")}))
            .collect();
        let long = "é".repeat(3 * CHUNK / 2);
        let value = serde_json::json!({"rows": rows, "long": long, "tail": [1, 2, 3]});
        let mut out = Trickle(Vec::new());
        pretty_json_to(&mut out, &value).unwrap();
        assert!(out.0.len() > 10 * CHUNK);
        assert_eq!(out.0, serde_json::to_vec_pretty(&value).unwrap());
        let mut plain = Vec::new();
        pretty_json_to(&mut plain, &value).unwrap();
        assert_eq!(plain, out.0);
    }
}
