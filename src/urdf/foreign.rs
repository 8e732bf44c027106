//! Foreign force elements mapped to restpose's: `<drake:linear_spring_damper>` to a spring,
//! `<gazebo reference="J"><springStiffness>k</springStiffness><springReference>q0`
//! `</springReference></gazebo>` to a joint spring. Damping is accepted and ignored (statics).

use super::edges::drake_part;
use super::import::Builder;
use super::xml::{child, parse_f64, Source};
use crate::error::Result;
use crate::model::{ForceLaw, JointSpring, Spring, SpringEnd, SpringMode};
use roxmltree::Node;

pub(super) fn read(src: &Source, drake: &[Node], gazebo: &[Node], b: &mut Builder) -> Result<()> {
    for (k, &n) in drake
        .iter()
        .filter(|n| n.tag_name().name() == "linear_spring_damper")
        .enumerate()
    {
        let name = n
            .attribute("name")
            .map_or_else(|| format!("linear_spring_damper_{k}"), str::to_string);
        let value = |tag: &str| -> Result<f64> {
            let (c, v) = drake_part(src, n, tag, "value")?;
            parse_f64(v).ok_or_else(|| {
                src.error(
                    c,
                    format!("<drake:{tag}> value \"{v}\" is not a finite number"),
                )
            })
        };
        let end = |body: &str, point: &str| -> Result<SpringEnd> {
            let (c, _) = drake_part(src, n, body, "name")?;
            let (body, bfl) = b.link_ref(src, c, "name")?;
            let (pc, _) = drake_part(src, n, point, "value")?;
            let p = src.vec3_opt(pc, "value")?.unwrap_or_default();
            Ok(SpringEnd {
                body,
                point: (bfl * nalgebra::Point3::from(p)).coords,
            })
        };
        let ends = [
            end("linear_spring_damper_body_A", "linear_spring_damper_p_AP")?,
            end("linear_spring_damper_body_B", "linear_spring_damper_p_BQ")?,
        ];
        let free_length = value("linear_spring_damper_free_length")?;
        let stiffness = value("linear_spring_damper_stiffness")?;
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
