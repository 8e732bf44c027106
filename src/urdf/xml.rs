//! XML reading helpers that turn every problem into an [`Error::Input`] naming the file,
//! line, column and element.

use super::dom::{Document, Node};
use crate::error::{Error, Result};
use crate::model::LARGEST_LENGTH;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The namespace URI of restpose's extension elements.
pub(crate) const MECH_NS: &str = "urn:urdf-mech:1";

/// Source document with its file name, for error positions.
pub(crate) struct Source<'a> {
    pub(crate) file: &'a str,
    pub(crate) doc: &'a Document<'a>,
    /// Byte offset of the start of each line: positions by binary search, where roxmltree's
    /// `text_pos_at` scans the document from its start (quadratic over a file's warnings).
    line_starts: Vec<usize>,
}

impl<'a> Source<'a> {
    /// The source of `doc`, read from `file`.
    pub(crate) fn new(file: &'a str, doc: &'a Document<'a>) -> Self {
        Source {
            file,
            doc,
            line_starts: super::lines::line_starts(doc.input_text()),
        }
    }

    /// Where element `node` starts, with its tag as written (`mech:loop_joint`).
    pub(crate) fn location(&self, node: Node) -> crate::error::SourceLocation {
        let (line, col) = self.pos(node);
        let tag = node.tag_name();
        let element = match tag.namespace().and_then(|uri| node.lookup_prefix(uri)) {
            Some(prefix) if !prefix.is_empty() => format!("{prefix}:{}", tag.name()),
            _ => tag.name().to_string(),
        };
        crate::error::SourceLocation {
            file: self.file.to_string(),
            line,
            col,
            element,
        }
    }

    /// Line and column (from 1, column in characters) of `node`.
    pub(crate) fn pos(&self, node: Node) -> (u32, u32) {
        let at = node.range().start;
        let line = self.line_starts.partition_point(|&s| s <= at).max(1);
        let start = self.line_starts[line - 1];
        let text = self.doc.input_text();
        let col = text
            .get(start..at)
            .map_or(at - start, |t| t.chars().count())
            + 1;
        (line as u32, col as u32)
    }

    /// An input error at `node`.
    pub(crate) fn error(&self, node: Node, message: impl Into<String>) -> Error {
        let at = self.location(node);
        Error::Input {
            file: at.file,
            line: at.line,
            col: at.col,
            message: message.into(),
            element: at.element,
        }
    }

    /// A warning at `node`: `FILE:LINE:COLUMN: message`.
    pub(crate) fn warning(&self, node: Node, message: impl std::fmt::Display) -> String {
        let (line, col) = self.pos(node);
        format!("{}:{line}:{col}: {message}", self.file)
    }

    /// Short description of an element for messages: ``joint `elbow` `` or `<origin>`.
    pub(crate) fn describe(&self, node: Node) -> String {
        let tag = node.tag_name().name();
        match node.attribute("name") {
            Some(n) => format!("{tag} `{n}`"),
            None => match node
                .ancestors()
                .skip(1)
                .find(|a| a.attribute("name").is_some())
            {
                Some(a) if a.tag_name().name() != "robot" => {
                    format!("<{tag}> of {}", self.describe(a))
                }
                _ => format!("<{tag}>"),
            },
        }
    }

    /// [`Source::describe`], formatted only when displayed.
    pub(crate) fn described<'s, 'n>(&'s self, node: Node<'n, 'n>) -> Described<'s, 'a, 'n> {
        Described { src: self, node }
    }

    /// A required attribute.
    pub(crate) fn req<'n>(&self, node: Node<'n, 'n>, attr: &str) -> Result<&'n str> {
        node.attribute(attr).ok_or_else(|| {
            self.error(
                node,
                format!("{} is missing the attribute `{attr}`", self.describe(node)),
            )
        })
    }

    /// An optional finite number.
    pub(crate) fn f64_opt(&self, node: Node, attr: &str) -> Result<Option<f64>> {
        match node.attribute(attr) {
            None => Ok(None),
            Some(s) => parse_f64(s).map(Some).ok_or_else(|| {
                self.error(
                    node,
                    format!(
                        "{}: attribute `{attr}` = \"{s}\" is not a finite number",
                        self.describe(node)
                    ),
                )
            }),
        }
    }

    /// An optional boolean: `true`, `false`, `1` or `0` (XML Schema's canonical forms).
    pub(crate) fn bool_opt(&self, node: Node, attr: &str) -> Result<Option<bool>> {
        match node.attribute(attr) {
            None => Ok(None),
            Some("true" | "1") => Ok(Some(true)),
            Some("false" | "0") => Ok(Some(false)),
            Some(s) => Err(self.error(
                node,
                format!(
                    "{}: attribute `{attr}` = \"{s}\" is not a boolean (true, false, 1 or 0)",
                    self.describe(node)
                ),
            )),
        }
    }

    /// A number with a default.
    pub(crate) fn f64_or(&self, node: Node, attr: &str, default: f64) -> Result<f64> {
        Ok(self.f64_opt(node, attr)?.unwrap_or(default))
    }

    /// An optional list of exactly `N` finite numbers.
    pub(crate) fn array_opt<const N: usize>(
        &self,
        node: Node,
        attr: &str,
    ) -> Result<Option<[f64; N]>> {
        let Some(s) = node.attribute(attr) else {
            return Ok(None);
        };
        // Exactly N finite numbers, read into place.
        let mut out = [0.0; N];
        let mut words = s.split_whitespace();
        let mut ok = true;
        for o in out.iter_mut() {
            // A word has no surrounding whitespace: parsed without `trim`.
            match words.next().and_then(super::number::finite) {
                Some(v) => *o = v,
                None => ok = false,
            }
        }
        match ok && words.next().is_none() {
            true => Ok(Some(out)),
            false => Err(self.error(
                node,
                format!(
                    "{}: attribute `{attr}` = \"{s}\" must be {N} finite numbers",
                    self.describe(node)
                ),
            )),
        }
    }

    /// An optional 3-vector.
    pub(crate) fn vec3_opt(&self, node: Node, attr: &str) -> Result<Option<Vector3<f64>>> {
        Ok(self.array_opt::<3>(node, attr)?.map(Vector3::from))
    }

    /// An error unless every value is within `±bound` (the importer's number ranges of
    /// [`crate::model::LARGEST_LENGTH`] and [`crate::model::LARGEST_MAGNITUDE`]).
    pub(crate) fn within(&self, node: Node, attr: &str, values: &[f64], bound: f64) -> Result<()> {
        match values.iter().find(|v| !(v.is_finite() && v.abs() <= bound)) {
            None => Ok(()),
            Some(v) => Err(self.error(
                node,
                format!(
                    "{}: attribute `{attr}` = {v:e} is outside the accepted range [−{bound:e}, {bound:e}]",
                    self.describe(node)
                ),
            )),
        }
    }

    /// A position or length 3-vector \[m\] with a default: finite and within
    /// ±[`LARGEST_LENGTH`].
    pub(crate) fn position_or(
        &self,
        node: Node,
        attr: &str,
        default: Vector3<f64>,
    ) -> Result<Vector3<f64>> {
        let v = self.vec3_or(node, attr, default)?;
        self.within(node, attr, v.as_slice(), LARGEST_LENGTH)?;
        Ok(v)
    }

    /// An optional length \[m\] (a distance, a pitch): finite and within ±[`LARGEST_LENGTH`].
    pub(crate) fn length_opt(&self, node: Node, attr: &str) -> Result<Option<f64>> {
        let v = self.f64_opt(node, attr)?;
        if let Some(x) = v {
            self.within(node, attr, &[x], LARGEST_LENGTH)?;
        }
        Ok(v)
    }

    /// A 3-vector with a default.
    pub(crate) fn vec3_or(
        &self,
        node: Node,
        attr: &str,
        default: Vector3<f64>,
    ) -> Result<Vector3<f64>> {
        Ok(self.vec3_opt(node, attr)?.unwrap_or(default))
    }

    /// A frame from `xyz` with `rpy` or `quat_xyzw` (URDF 1.1) on `node` (identity if absent).
    pub(crate) fn frame(&self, node: Option<Node>) -> Result<Isometry3<f64>> {
        let Some(node) = node else {
            return Ok(Isometry3::identity());
        };
        let xyz = self.position_or(node, "xyz", Vector3::zeros())?;
        let rot = if let Some(q) = self.array_opt::<4>(node, "quat_xyzw")? {
            // Scaled by its largest component first, so that the norm cannot overflow.
            let big = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let quat =
                nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]) / big.max(f64::MIN_POSITIVE);
            if big == 0.0 {
                return Err(self.error(
                    node,
                    format!("{}: `quat_xyzw` is zero", self.describe(node)),
                ));
            }
            UnitQuaternion::from_quaternion(quat)
        } else {
            let rpy = self.vec3_or(node, "rpy", Vector3::zeros())?;
            UnitQuaternion::from_euler_angles(rpy.x, rpy.y, rpy.z)
        };
        Ok(Isometry3::from_parts(Translation3::from(xyz), rot))
    }

    /// A unit axis from attribute `xyz` of `node` (default when absent); a zero axis is an error.
    pub(crate) fn axis(
        &self,
        node: Option<Node>,
        owner: Node,
        default: Vector3<f64>,
    ) -> Result<Vector3<f64>> {
        let Some(node) = node else { return Ok(default) };
        let a = self.vec3_or(node, "xyz", default)?;
        // Scaled by its largest component first, so that the norm cannot overflow (an axis
        // of 1e200 would have an infinite norm and normalize to zero).
        let big = a.amax();
        if big < 1e-12 {
            return Err(self.error(
                node,
                format!("{} has a zero-length axis", self.describe(owner)),
            ));
        }
        let a = a / big;
        Ok(a / a.norm())
    }
}

/// Parses XML text (DTDs allowed): by [`super::lean::parse`], or by `roxmltree` where it
/// declines; a malformed document is an [`Error::Input`] at the position of the problem.
pub(crate) fn parse_document<'a>(text: &'a str, file: &str) -> Result<Document<'a>> {
    if let Some(doc) = super::lean::parse(text) {
        return Ok(doc);
    }
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    located(roxmltree::Document::parse_with_options(text, opts), file)
}

/// `roxmltree`'s result as a [`Document`], its error located in `file`.
pub(crate) fn located<'a>(
    parsed: std::result::Result<roxmltree::Document<'a>, roxmltree::Error>,
    file: &str,
) -> Result<Document<'a>> {
    parsed.map(|d| Document::from_roxmltree(&d)).map_err(|e| {
        let p = e.pos();
        Error::Input {
            file: file.to_string(),
            line: p.row,
            col: p.col,
            message: format!("not well-formed XML: {e}"),
            element: String::new(),
        }
    })
}

/// An element's description for messages ([`Source::described`]).
pub(crate) struct Described<'s, 'a, 'n> {
    src: &'s Source<'a>,
    node: Node<'n, 'n>,
}

impl std::fmt::Display for Described<'_, '_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.src.describe(self.node))
    }
}

/// Parses a finite number.
pub(crate) fn parse_f64(s: &str) -> Option<f64> {
    super::number::finite_trimmed(s)
}

/// First child element with this local name.
#[inline]
pub(crate) fn child<'a>(node: Node<'a, 'a>, name: &str) -> Option<Node<'a, 'a>> {
    node.children().find(|c| c.is_named(name))
}

/// Whether the element is in the `mech` namespace.
pub(crate) fn is_mech(node: Node) -> bool {
    node.tag_name().namespace() == Some(MECH_NS)
}
