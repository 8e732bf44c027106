//! Mechanisms built in code (`tests/it/common/builders.rs`, on `model::ModelBuilder`) are the
//! mechanisms of the URDF text they replace in the other tests: the same bodies (mass, centre
//! of mass, inertia), joints (kind, frames, tree or loop, limits) and forces, and the same rest
//! pose, energy and iteration count from the solver.
use crate::common::builders::{chain, four_bar, inertia, initial, linear, lock, pendulum};
use crate::common::model_from;
use nalgebra::Vector3;
use restpose::model::JointKind;
use restpose::{Model, Options};

/// The two models have the same bodies, joints and force elements; the importer's model also
/// has the `world` link, which carries no body.
fn assert_same_model(built: &Model, imported: &Model) {
    assert_eq!(built.name(), imported.name());
    assert_eq!(
        format!("{:?}", built.bodies()),
        format!("{:?}", imported.bodies())
    );
    assert_eq!(built.joints().len(), imported.joints().len());
    for (a, b) in built.joints().iter().zip(imported.joints()) {
        assert_eq!(
            (&a.name, a.kind, a.bodies, a.tree, a.merged, a.limits),
            (&b.name, b.kind, b.bodies, b.tree, b.merged, b.limits)
        );
        for k in 0..2 {
            let (fa, fb) = (a.body_from_joint[k], b.body_from_joint[k]);
            assert!(
                (fa.translation.vector - fb.translation.vector).amax() < 1e-15
                    && fa.rotation.angle_to(&fb.rotation) < 1e-15,
                "{}: frame {k}: {fa} vs {fb}",
                a.name
            );
        }
    }
    assert_eq!(
        format!("{:?}", built.joint_springs()),
        format!("{:?}", imported.joint_springs())
    );
    for (what, a, b) in [
        (
            "springs",
            format!("{:?}", built.springs()),
            format!("{:?}", imported.springs()),
        ),
        (
            "locks",
            format!("{:?}", built.locks()),
            format!("{:?}", imported.locks()),
        ),
        (
            "initial",
            format!("{:?}", built.initial()),
            format!("{:?}", imported.initial()),
        ),
        (
            "gravity",
            format!("{:?}", built.gravity()),
            format!("{:?}", imported.gravity()),
        ),
        (
            "length",
            format!("{:?}", built.length_scale()),
            format!("{:?}", imported.length_scale()),
        ),
    ] {
        assert_eq!(a, b, "{what}");
    }
}

/// Both solve to the same rest pose in the same iterations.
fn assert_same_rest(built: &Model, imported: &Model) {
    let (sa, ra) = restpose::solve(built, &Options::default()).unwrap();
    let (sb, rb) = restpose::solve(imported, &Options::default()).unwrap();
    assert!(ra.converged() && rb.converged());
    assert_eq!(ra.iterations, rb.iterations, "{}", built.name());
    assert_eq!(ra.independent_coordinates, rb.independent_coordinates);
    assert!((ra.energy.total - rb.energy.total).abs() < 1e-12 * (1.0 + rb.energy.total.abs()));
    for ((n, a), (_, b)) in sa.joint_values(built).iter().zip(sb.joint_values(imported)) {
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12, "{n}: built {x}, imported {y}");
        }
    }
}

#[test]
fn built_chains_are_the_generated_chains() {
    for (n, planar) in [(6, false), (5, true)] {
        let built = chain(n, planar).0.build().unwrap();
        let imported = model_from(&restpose::generate::chain(n, planar));
        assert_same_model(&built, &imported);
        assert_same_rest(&built, &imported);
    }
}

/// The pendulum of `tests/it/angles.rs`, with a spring, a lock, limits and a start value.
#[test]
fn built_pendulum_is_the_urdf_pendulum() {
    let (mut b, pivot) = pendulum(
        "p",
        JointKind::Revolute,
        2.0,
        Vector3::new(1.0, 0.0, 0.0),
        inertia(0.01, 0.1, 0.1),
    );
    b.set_limits(pivot, -20.0, 20.0);
    b.set_gravity(Vector3::new(0.0, -9.81, 0.0));
    b.add_joint_spring(pivot, 0, linear(3.0), 0.0);
    let mut locked = b.clone();
    lock(&mut locked, pivot, 3.5);
    initial(&mut b, pivot, 0, 0.3);
    let urdf = |extra: &str| {
        model_from(&format!(
            r#"<robot name="p" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="1 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="pivot" type="revolute"><parent link="world"/><child link="bar"/>
    <axis xyz="0 0 1"/><limit lower="-20" upper="20" effort="1" velocity="1"/></joint>
  <mech:gravity xyz="0 -9.81 0"/>
  <mech:joint_spring joint="pivot" stiffness="3" reference="0"/>
  {extra}
</robot>"#
        ))
    };
    let (built, imported) = (
        b.build().unwrap(),
        urdf(r#"<mech:initial joint="pivot" value="0.3"/>"#),
    );
    assert_same_model(&built, &imported);
    assert_same_rest(&built, &imported);
    let (built, imported) = (
        locked.build().unwrap(),
        urdf(r#"<mech:lock joint="pivot" value="3.5"/>"#),
    );
    assert_same_model(&built, &imported);
    assert_same_rest(&built, &imported);
}

/// The four-bar of `tests/it/properties.rs`, closed by a loop joint.
#[test]
fn built_four_bar_is_the_urdf_four_bar() {
    let (a, b, c, t, k) = (0.25, 1.0, 0.7, 1.1, 20.0);
    let masses = [0.5, 1.0, 1.5];
    let (builder, _) = four_bar([a, b, c], t, masses, k).unwrap();
    let built = builder.build().unwrap();
    let start = |name: &str| {
        built
            .initial()
            .iter()
            .find(|i| built.get_joint(i.joint).unwrap().name == name)
            .unwrap()
            .value
    };
    let inertial = |m: f64, x: f64| {
        format!("<inertial><origin xyz=\"{x} 0 0\"/><mass value=\"{m}\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>")
    };
    let imported = model_from(&format!(
        r#"<robot name="fourbar" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
<link name="crank">{}</link><link name="coupler">{}</link><link name="rocker">{}</link>
<joint name="crank_j" type="continuous"><parent link="world"/><child link="crank"/><axis xyz="0 0 1"/></joint>
<joint name="coupler_j" type="continuous"><parent link="crank"/><child link="coupler"/><origin xyz="{a} 0 0"/><axis xyz="0 0 1"/></joint>
<joint name="rocker_j" type="continuous"><parent link="world"/><child link="rocker"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
<mech:loop_joint name="close" type="revolute"><parent link="coupler"/><origin xyz="{b} 0 0"/><child link="rocker"/><child_origin xyz="{c} 0 0"/><axis xyz="0 0 1"/></mech:loop_joint>
<mech:initial joint="crank_j" value="{t}"/><mech:initial joint="coupler_j" value="{}"/><mech:initial joint="rocker_j" value="{}"/>
<mech:joint_spring joint="crank_j" stiffness="{k}" reference="{t}"/>
<mech:gravity xyz="0 -9.81 0"/></robot>"#,
        inertial(masses[0], a / 2.0),
        inertial(masses[1], b / 2.0),
        inertial(masses[2], c / 2.0),
        start("coupler_j"),
        start("rocker_j"),
    ));
    assert_same_model(&built, &imported);
    assert_same_rest(&built, &imported);
}
