//! The vocabulary of the `mech:` namespace (`urn:urdf-mech:1`), checked strictly: an unknown
//! element or attribute there is an error with a "did you mean" suggestion (the known name at
//! the smallest edit distance), a `mech:` element outside `<robot>`'s children is an error, and
//! a `mech` prefix bound to another URI is a warning (its elements are foreign, so ignored).
//!
//! Children of `mech:` elements may be written with or without the prefix; attributes of other
//! namespaces (`xml:`, a tool's own) are left alone.

use super::dom::Node;
use super::xml::{Source, MECH_NS};
use crate::error::Result;

/// A child element: local name and attributes.
struct Child {
    name: &'static str,
    attributes: &'static [&'static str],
    children: &'static [Child],
}

/// A top-level `mech:` element: local name, attributes and child elements.
struct Element {
    name: &'static str,
    attributes: &'static [&'static str],
    children: &'static [Child],
}

/// The child elements that may appear more than once (a spring's two `<end>`s, counted where
/// they are read; a force table's rows); any other child appears at most once.
const REPEATABLE: &[&str] = &["point", "end"];

const FRAME: &[&str] = &["xyz", "rpy", "quat_xyzw"];

const POINT: Child = Child {
    name: "point",
    attributes: &["deflection", "force"],
    children: &[],
};

const FORCE_DEFLECTION: Child = Child {
    name: "force_deflection",
    attributes: &["interpolation", "extrapolate"],
    children: &[POINT],
};

const ELEMENTS: &[Element] = &[
    Element {
        name: "gravity",
        attributes: &["xyz"],
        children: &[],
    },
    Element {
        name: "link_gravity",
        attributes: &["link", "enabled"],
        children: &[],
    },
    Element {
        name: "frame",
        attributes: &["name", "link", "xyz", "rpy", "quat_xyzw"],
        children: &[],
    },
    Element {
        name: "loop_joint",
        attributes: &["name", "type", "pitch", "length"],
        children: &[
            Child {
                name: "parent",
                attributes: &["link"],
                children: &[],
            },
            Child {
                name: "child",
                attributes: &["link"],
                children: &[],
            },
            Child {
                name: "origin",
                attributes: FRAME,
                children: &[],
            },
            Child {
                name: "child_origin",
                attributes: &["xyz", "rpy", "quat_xyzw", "auto"],
                children: &[],
            },
            Child {
                name: "axis",
                attributes: &["xyz"],
                children: &[],
            },
            Child {
                name: "axis2",
                attributes: &["xyz"],
                children: &[],
            },
            Child {
                name: "limit",
                attributes: &["lower", "upper", "effort", "velocity"],
                children: &[],
            },
        ],
    },
    Element {
        name: "spring",
        attributes: &[
            "name",
            "stiffness",
            "free_length",
            "preload",
            "mode",
            "damping",
        ],
        children: &[
            Child {
                name: "end",
                attributes: &["link", "xyz"],
                children: &[],
            },
            FORCE_DEFLECTION,
        ],
    },
    Element {
        name: "joint_spring",
        attributes: &[
            "joint",
            "stiffness",
            "reference",
            "preload",
            "dof",
            "damping",
        ],
        children: &[FORCE_DEFLECTION],
    },
    Element {
        name: "force",
        attributes: &["name", "link", "xyz", "force", "torque", "frame"],
        children: &[],
    },
    Element {
        name: "joint_effort",
        attributes: &["joint", "value", "dof"],
        children: &[],
    },
    Element {
        name: "lock",
        attributes: &["joint", "value", "dof"],
        children: &[],
    },
    Element {
        name: "ground",
        attributes: &["name", "xyz", "normal"],
        children: &[],
    },
    Element {
        name: "obstacle",
        attributes: &["link"],
        children: &[],
    },
    Element {
        name: "base",
        attributes: FRAME,
        children: &[],
    },
    Element {
        name: "contact",
        attributes: &["link", "enabled", "friction", "mu"],
        children: &[],
    },
    Element {
        name: "initial",
        attributes: &["joint", "value", "dof"],
        children: &[],
    },
];

/// Names of the top-level `mech:` elements.
pub(super) fn element_names() -> impl Iterator<Item = &'static str> {
    ELEMENTS.iter().map(|e| e.name)
}

/// "did you mean `x`?" for the closest known name within a third of its length (at least 2
/// edits), else the list of known names.
pub(super) fn suggest<'a>(name: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    let known: Vec<&str> = known.into_iter().collect();
    match crate::names::closest(name, known.iter().copied()) {
        Some(k) => format!("did you mean `{k}`?"),
        _ if known.is_empty() => "it takes none".to_string(),
        _ => format!("known: {}", known.join(", ")),
    }
}

/// Checks the attributes (unqualified or `mech:`) and child elements of `node`; `what`
/// describes it in messages (formatted only for an error).
fn check_node(
    src: &Source,
    node: Node,
    what: &dyn Fn() -> String,
    attributes: &[&str],
    children: &[Child],
) -> Result<()> {
    for a in node.attributes() {
        let ns = a.namespace();
        if (ns.is_none() || ns == Some(MECH_NS)) && !attributes.contains(&a.name()) {
            return Err(src.error(
                node,
                format!(
                    "{} has no attribute `{}`: {}",
                    what(),
                    a.name(),
                    suggest(a.name(), attributes.iter().copied())
                ),
            ));
        }
    }
    let mut seen: Vec<&str> = Vec::new();
    for c in node.children().filter(|c| c.is_element()) {
        let ns = c.tag_name().namespace();
        if !(ns.is_none() || ns == Some(MECH_NS)) {
            continue;
        }
        let name = c.tag_name().name();
        if seen.contains(&name) && !REPEATABLE.contains(&name) {
            let named = node
                .attribute("name")
                .map(|n| format!(" `{n}`"))
                .unwrap_or_default();
            return Err(src.error(
                c,
                format!("{}{named} has a second <{name}>: it takes one", what()),
            ));
        }
        seen.push(name);
        let Some(spec) = children.iter().find(|s| s.name == name) else {
            return Err(src.error(
                c,
                format!(
                    "{} has no child element <{name}>: {}",
                    what(),
                    suggest(name, children.iter().map(|s| s.name))
                ),
            ));
        };
        check_node(
            src,
            c,
            &|| format!("<{name}> of {}", what()),
            spec.attributes,
            spec.children,
        )?;
    }
    Ok(())
}

/// Checks every `mech:` element and attribute of the document, and warns about a `mech`
/// prefix bound to another namespace.
///
/// # Errors
/// [`crate::Error::Input`] at the first unknown name, with a suggestion.
pub(super) fn check(src: &Source, robot: Node, warnings: &mut Vec<String>) -> Result<()> {
    let mut warned = false;
    for n in robot.descendants().filter(|n| n.is_element()) {
        // In no namespace, nor any of its attributes: nothing to check.
        if n.is_plain_element() {
            continue;
        }
        let ns = n.tag_name().namespace();
        if let Some(uri) = ns.filter(|&u| u != MECH_NS) {
            if !warned && n.lookup_prefix(uri) == Some("mech") {
                warned = true;
                warnings.push(src.warning(
                    n,
                    format!(
                        "the prefix `mech` is bound to \"{uri}\", not to restpose's \"{MECH_NS}\": its elements are foreign and ignored"
                    ),
                ));
            }
        }
        if let Some(a) = n
            .namespaced_attributes()
            .find(|a| a.namespace() == Some(MECH_NS))
        {
            if !n
                .ancestors()
                .any(|x| x.tag_name().namespace() == Some(MECH_NS))
            {
                return Err(src.error(
                    n,
                    format!(
                        "{}: the `mech:` namespace defines no attribute `{}` here",
                        src.describe(n),
                        a.name()
                    ),
                ));
            }
        }
        if ns != Some(MECH_NS) {
            continue;
        }
        let name = n.tag_name().name();
        let parent = n.parent_element();
        if parent == Some(robot) {
            let Some(spec) = ELEMENTS.iter().find(|e| e.name == name) else {
                return Err(src.error(
                    n,
                    format!(
                        "unknown element <mech:{name}>: {}",
                        suggest(name, element_names())
                    ),
                ));
            };
            check_node(
                src,
                n,
                &|| format!("<mech:{name}>"),
                spec.attributes,
                spec.children,
            )?;
        } else if parent.is_none_or(|p| p.tag_name().namespace() != Some(MECH_NS)) {
            return Err(src.error(
                n,
                format!("<mech:{name}> must be a direct child of <robot>"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_by_edit_distance() {
        assert_eq!(crate::names::distance("refrence", "reference"), 1);
        assert_eq!(crate::names::distance("sprng", "spring"), 1);
        assert_eq!(crate::names::distance("", "abc"), 3);
        assert_eq!(
            suggest("refrence", ["joint", "reference", "dof"]),
            "did you mean `reference`?"
        );
        assert!(suggest("zzzzzz", ["joint", "dof"]).starts_with("known: "));
    }
}
