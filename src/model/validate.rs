//! What [`ModelBuilder::build`] checks before it builds: every id and coordinate index in
//! range, link mass properties finite and not negative, limits ordered, force tables with
//! increasing deflections, free lengths not negative, and a joint graph whose tree joints form
//! a forest rooted at the world.
//!
//! Tree joints (`tree && !merged`) give each body at most one parent; following parents from
//! any body must end at the world or at a body no tree joint places (a floating body), never
//! come back to itself: `parent(b) ≠ b`, `parentᵏ(b) ≠ b` for all `k ≥ 1`.

use super::{BodyId, ForceLaw, JointId, ModelBuilder};
use crate::error::{Error, Result};

fn bad<T>(what: String) -> Result<T> {
    Err(Error::Model(what))
}

/// A force table has at least two rows, deflections strictly increasing.
fn law_ok(law: &ForceLaw, what: impl Fn() -> String) -> Result<()> {
    let ForceLaw::Table { points, .. } = law else {
        return Ok(());
    };
    let what = what();
    if points.len() < 2 {
        return bad(format!("{what}: a force table needs at least two rows"));
    }
    for w in points.windows(2) {
        if w[1].0.is_nan() || w[1].0 <= w[0].0 {
            return bad(format!(
                "{what}: deflections must increase strictly ({} after {})",
                w[1].0, w[0].0
            ));
        }
    }
    Ok(())
}

impl ModelBuilder {
    pub(super) fn validate(&self) -> Result<()> {
        let m = &self.model;
        let nb = m.bodies.len();
        let body_ok = |b: &Option<BodyId>| b.is_none_or(|b| b.0 < nb);
        for l in &m.links {
            if !body_ok(&l.body) {
                return bad(format!(
                    "link `{}` is on a body that does not exist",
                    l.name
                ));
            }
        }
        for (l, i) in m.links.iter().zip(&self.inertials) {
            let finite = i.mass.is_finite()
                && i.com.iter().all(|x| x.is_finite())
                && i.inertia.iter().all(|x| x.is_finite());
            if !finite || i.mass < 0.0 {
                return bad(format!(
                    "link `{}` has a negative or non-finite mass property",
                    l.name
                ));
            }
        }
        for j in &m.joints {
            if !j.bodies.iter().all(body_ok) {
                return bad(format!(
                    "joint `{}` joins a body that does not exist",
                    j.name
                ));
            }
            if !j.merged && j.bodies[0] == j.bodies[1] {
                return bad(format!("joint `{}` joins a body to itself", j.name));
            }
            if let Some([lo, hi]) = j.limits {
                if lo.is_nan() || hi.is_nan() || lo > hi {
                    return bad(format!(
                        "joint `{}` has limits lower {lo} > upper {hi} (or not numbers)",
                        j.name
                    ));
                }
            }
        }
        self.validate_tree()?;
        let coordinate = |joint: JointId, dof: usize, what: &str| -> Result<()> {
            match m.joints.get(joint.0) {
                None => bad(format!("{what} refers to a joint that does not exist")),
                Some(j) if dof >= j.kind.scalar_coordinates() => bad(format!(
                    "{what} on joint `{}` ({}): coordinate {dof} is out of range",
                    j.name,
                    j.kind.name()
                )),
                Some(_) => Ok(()),
            }
        };
        for s in &m.joint_springs {
            coordinate(s.joint, s.dof, "a joint spring")?;
            law_ok(&s.law, || {
                format!("joint spring on `{}`", m.joints[s.joint.0].name)
            })?;
        }
        for e in &m.efforts {
            coordinate(e.joint, e.dof, "an effort")?;
        }
        for l in &m.locks {
            coordinate(l.joint, l.dof, "a lock")?;
        }
        for i in &m.initial {
            let Some(j) = m.joints.get(i.joint.0) else {
                return bad("an initial value refers to a joint that does not exist".into());
            };
            let count = j.kind.value_counts().iter().copied().max().unwrap_or(0);
            if i.dof >= count {
                return bad(format!(
                    "an initial value on joint `{}` ({}): value {} is out of range (it takes {count})",
                    j.name,
                    j.kind.name(),
                    i.dof
                ));
            }
        }
        for x in &m.mimics {
            coordinate(x.joint, 0, "a mimic")?;
            coordinate(x.reference, 0, "a mimic")?;
        }
        for s in &m.springs {
            if !s.ends.iter().all(|e| body_ok(&e.body)) {
                return bad(format!(
                    "spring `{}` ends on a body that does not exist",
                    s.name
                ));
            }
            if s.free_length < 0.0 {
                return bad(format!(
                    "spring `{}` has a negative free length {} m",
                    s.name, s.free_length
                ));
            }
            law_ok(&s.law, || format!("spring `{}`", s.name))?;
        }
        for l in &m.loads {
            if l.body.0 >= nb {
                return bad(format!(
                    "load `{}` is on a body that does not exist",
                    l.name
                ));
            }
        }
        if !m.gravity.iter().all(|g| g.is_finite()) {
            return bad("gravity is not finite".into());
        }
        Ok(())
    }

    /// Each body has at most one tree joint placing it, tree joints have a body as their
    /// child, and no chain of tree joints comes back to where it started.
    fn validate_tree(&self) -> Result<()> {
        let m = &self.model;
        let mut parent: Vec<Option<usize>> = vec![None; m.bodies.len()];
        for (k, j) in m.joints.iter().enumerate() {
            if !j.tree || j.merged {
                continue;
            }
            let Some(child) = j.bodies[1] else {
                return bad(format!(
                    "tree joint `{}` has the world as its child; swap parent and child",
                    j.name
                ));
            };
            if let Some(other) = parent[child.0] {
                return bad(format!(
                    "body `{}` is the child of two tree joints (`{}` and `{}`); close loops with a loop joint",
                    m.bodies[child.0].name, m.joints[other].name, j.name
                ));
            }
            parent[child.0] = Some(k);
        }
        // 0: not seen, 1: on the current walk, 2: leads to the world or a floating body.
        let mut state = vec![0u8; m.bodies.len()];
        let mut walk = Vec::new();
        for start in 0..m.bodies.len() {
            walk.clear();
            let mut b = Some(start);
            while let Some(i) = b {
                match state[i] {
                    2 => break,
                    1 => {
                        return bad(format!(
                            "body `{}` is on a cycle of tree joints (through joint `{}`); close loops with a loop joint",
                            m.bodies[i].name,
                            parent[i].map_or("", |k| m.joints[k].name.as_str())
                        ))
                    }
                    _ => {}
                }
                state[i] = 1;
                walk.push(i);
                b = parent[i].and_then(|k| m.joints[k].bodies[0]).map(|p| p.0);
            }
            for &i in &walk {
                state[i] = 2;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::model::{ForceLaw, Initial, JointKind, ModelBuilder};
    use nalgebra::{Isometry3, Matrix3, Vector3};

    fn error(b: ModelBuilder) -> String {
        b.build().unwrap_err().to_string()
    }

    /// Ids from another builder, or coordinates a joint does not have, are errors.
    #[test]
    fn build_refuses_ids_out_of_range() {
        let mut other = ModelBuilder::new("other");
        other.add_body("x");
        let stranger = other.add_body("y");
        let mut b = ModelBuilder::new("m");
        let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), Matrix3::identity());
        let id = Isometry3::identity();
        let j = b.add_joint("j", JointKind::Revolute, None, id, Some(a), id);
        let mut bad = b.clone();
        bad.add_joint("k", JointKind::Revolute, Some(a), id, Some(stranger), id);
        let e = error(bad);
        assert!(
            e.contains("joint `k` joins a body that does not exist"),
            "{e}"
        );
        let mut bad = b.clone();
        let law = ForceLaw::Linear {
            stiffness: 1.0,
            preload: 0.0,
        };
        bad.add_joint_spring(j, 1, law, 0.0);
        let e = error(bad);
        assert!(e.contains("coordinate 1 is out of range"), "{e}");
        let mut bad = b.clone();
        bad.add_initial(Initial {
            joint: j,
            dof: 1,
            value: 0.0,
        });
        let e = error(bad);
        assert!(
            e.contains("initial value on joint `j` (revolute): value 1 is out of range"),
            "{e}"
        );
        assert!(b.build().is_ok());
    }

    /// A body placed by two tree joints, a cycle of tree joints, the world as a tree joint's
    /// child, and limits the wrong way round are refused, naming the joint or body; the same
    /// second joint as a loop joint is accepted.
    #[test]
    fn build_refuses_a_joint_graph_that_is_no_tree() {
        let id = Isometry3::identity();
        let mut b = ModelBuilder::new("m");
        let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), Matrix3::identity());
        let c = b.add_rigid_body("c", 1.0, Vector3::zeros(), Matrix3::identity());
        let ja = b.add_joint("ja", JointKind::Revolute, None, id, Some(a), id);
        let mut two = b.clone();
        two.add_joint("jc", JointKind::Revolute, Some(a), id, Some(c), id);
        let mut closed = two.clone();
        two.add_joint("again", JointKind::Revolute, None, id, Some(c), id);
        let e = error(two);
        assert!(
            e.contains("body `c` is the child of two tree joints (`jc` and `again`)"),
            "{e}"
        );
        closed.add_loop_joint("again", JointKind::Revolute, None, id, Some(c), id);
        assert!(closed.build().is_ok());

        let mut cycle = ModelBuilder::new("m");
        let a2 = cycle.add_rigid_body("a", 1.0, Vector3::zeros(), Matrix3::identity());
        let c2 = cycle.add_rigid_body("c", 1.0, Vector3::zeros(), Matrix3::identity());
        cycle.add_joint("ac", JointKind::Revolute, Some(a2), id, Some(c2), id);
        cycle.add_joint("ca", JointKind::Revolute, Some(c2), id, Some(a2), id);
        let e = error(cycle);
        assert!(e.contains("is on a cycle of tree joints"), "{e}");

        let mut world = b.clone();
        world.add_joint("down", JointKind::Revolute, Some(a), id, None, id);
        let e = error(world);
        assert!(
            e.contains("tree joint `down` has the world as its child"),
            "{e}"
        );

        let mut limits = b.clone();
        limits.set_limits(ja, 1.0, -1.0);
        let e = error(limits);
        assert!(
            e.contains("joint `ja` has limits lower 1 > upper -1"),
            "{e}"
        );
    }

    /// A force table out of order and a negative free length are refused, naming the element.
    #[test]
    fn build_refuses_bad_force_elements() {
        use crate::model::{Spring, SpringEnd, SpringMode};
        let id = Isometry3::identity();
        let mut b = ModelBuilder::new("m");
        let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), Matrix3::identity());
        let j = b.add_joint("j", JointKind::Revolute, None, id, Some(a), id);
        let mut table = b.clone();
        let points = vec![(0.0, 0.0), (0.1, 1.0), (0.1, 2.0)];
        let law = ForceLaw::Table {
            points,
            extrapolate_linear: true,
            bounded: false,
        };
        table.add_joint_spring(j, 0, law, 0.0);
        let e = error(table);
        assert!(
            e.contains("joint spring on `j`: deflections must increase strictly (0.1 after 0.1)"),
            "{e}"
        );
        let end = |body| SpringEnd {
            body,
            point: Vector3::zeros(),
        };
        b.add_spring(Spring {
            name: "s".into(),
            ends: [end(Some(a)), end(None)],
            free_length: -1.0,
            law: ForceLaw::Linear {
                stiffness: 1.0,
                preload: 0.0,
            },
            mode: SpringMode::Both,
        });
        let e = error(b);
        assert!(
            e.contains("spring `s` has a negative free length -1 m"),
            "{e}"
        );
    }

    /// Numbers out of range are refused by `build` itself, naming the element.
    #[test]
    fn build_checks_numbers() {
        let id = Isometry3::identity();
        let mut b = ModelBuilder::new("m");
        let a = b.add_rigid_body("a", 1e300, Vector3::zeros(), Matrix3::identity());
        b.add_joint("j", JointKind::Revolute, None, id, Some(a), id);
        match b.build() {
            Err(crate::Error::InvalidNumber { element, .. }) => assert_eq!(element, "link `a`"),
            other => panic!("expected InvalidNumber, got {other:?}"),
        }
    }
}
