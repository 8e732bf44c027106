//! Foreign force elements mapped to restpose's: `<drake:linear_spring_damper>` to a spring,
//! `<gazebo reference="J"><springStiffness>k</springStiffness><springReference>q0`
//! `</springReference></gazebo>` to a joint spring. Damping is accepted and ignored (statics).

use super::dom::Node;
use super::edges::drake_part;
use super::import::Builder;
use super::xml::{child, parse_f64, Source};
use crate::error::Result;
use crate::model::{
    ForceLaw, JointSpring, Spring, SpringEnd, SpringMode, LARGEST_LENGTH, LARGEST_MAGNITUDE,
};

pub(super) fn read(src: &Source, drake: &[Node], gazebo: &[Node], b: &mut Builder) -> Result<()> {
    for (k, &n) in drake
        .iter()
        .filter(|n| n.tag_name().name() == "linear_spring_damper")
        .enumerate()
    {
        let name = n
            .attribute("name")
            .map_or_else(|| format!("linear_spring_damper_{k}"), str::to_string);
        // A number within `±bound`, not negative unless `signed`, at its element.
        let value = |tag: &str, bound: f64, signed: bool| -> Result<f64> {
            let (c, v) = drake_part(src, n, tag, "value")?;
            let x = parse_f64(v).ok_or_else(|| {
                src.error(
                    c,
                    format!("<drake:{tag}> value \"{v}\" is not a finite number"),
                )
            })?;
            if !signed && x < 0.0 {
                return Err(src.error(
                    c,
                    format!("spring `{name}`: <drake:{tag}> value {x} is negative"),
                ));
            }
            src.within(c, "value", &[x], bound)?;
            Ok(x)
        };
        let end = |body: &str, point: &str| -> Result<SpringEnd> {
            let (c, _) = drake_part(src, n, body, "name")?;
            let (body, bfl) = b.link_ref(src, c, "name")?;
            let (pc, _) = drake_part(src, n, point, "value")?;
            let p = src.position_or(pc, "value", nalgebra::Vector3::zeros())?;
            Ok(SpringEnd {
                body,
                point: (bfl * nalgebra::Point3::from(p)).coords,
            })
        };
        let ends = [
            end("linear_spring_damper_body_A", "linear_spring_damper_p_AP")?,
            end("linear_spring_damper_body_B", "linear_spring_damper_p_BQ")?,
        ];
        if let Some(w) = coincident_ends(&name, &ends) {
            b.warnings.push(src.warning(n, w));
        }
        let free_length = value("linear_spring_damper_free_length", LARGEST_LENGTH, false)?;
        let stiffness = value("linear_spring_damper_stiffness", LARGEST_MAGNITUDE, false)?;
        b.model.add_spring(Spring {
            name,
            ends,
            free_length,
            law: ForceLaw::Linear {
                stiffness,
                preload: 0.0,
            },
            mode: SpringMode::Both,
        });
    }
    for &g in gazebo {
        let Some(joint) = g.attribute("reference") else {
            continue;
        };
        let Some(k) = child(g, "springStiffness") else {
            continue;
        };
        let number = |c: Node| -> Result<f64> {
            let t = c.text().unwrap_or("").trim();
            parse_f64(t).ok_or_else(|| {
                src.error(
                    c,
                    format!("<{}> \"{t}\" is not a finite number", c.tag_name().name()),
                )
            })
        };
        let stiffness = number(k)?;
        let reference = child(g, "springReference")
            .map(number)
            .transpose()?
            .unwrap_or(0.0);
        let id = b.model.joint_id(joint).ok_or_else(|| {
            src.error(g, format!("<gazebo reference=\"{joint}\"> has a springStiffness but the model has no joint `{joint}`"))
        })?;
        if b.model.partial().joints[id.0].kind.scalar_coordinates() == 0 {
            return Err(src.error(k, format!("joint `{joint}` has no coordinate for a spring")));
        }
        b.model.push_joint_spring(JointSpring {
            joint: id,
            dof: 0,
            reference,
            law: ForceLaw::Linear {
                stiffness,
                preload: 0.0,
            },
        });
    }
    Ok(())
}

/// The warning for a spring whose two ends are the same point of the same body (or both of
/// the world): its length is zero in every pose, so its force has no direction and it stores
/// a constant energy.
pub(super) fn coincident_ends(name: &str, ends: &[SpringEnd; 2]) -> Option<String> {
    let [a, b] = ends;
    let scale = a.point.amax().max(b.point.amax()).max(1.0);
    (a.body == b.body && (a.point - b.point).amax() <= 1e-12 * scale).then(|| {
        format!(
            "spring `{name}`: both ends are the same point of the same {}: its length is zero in every pose and its force has no direction (it does nothing)",
            if a.body.is_some() { "body" } else { "world frame" }
        )
    })
}
