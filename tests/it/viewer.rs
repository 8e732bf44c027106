//! The rerun recording (feature `viewer`): written, then read back with rerun's own decoder.
use crate::common::*;

#[test]
fn recording_holds_the_mechanism_the_search_and_the_forces() {
    let m = robot("slider_crank");
    let opts = restpose::Options {
        record_iterates: true,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&m, &opts).unwrap();
    assert_eq!(report.iterates.len(), report.history.len());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slider_crank.rrd");
    let mode = &report.stability.as_ref().unwrap().modes[0];
    let frames = restpose::solver::mode_animation(&m, &state, mode, 12, 0.15);
    assert_eq!(
        frames.len(),
        12,
        "every pose along the mode closes its loop"
    );
    restpose::view::write_recording(&path, &m, &state, &report, &frames).unwrap();
    let rec = restpose::view::read_recording(&path).unwrap();
    for entity in [
        "world/robot/world/crank",
        "world/robot/world/crank/rod",
        "world/robot/world/slider",
        "world/robot/world/crank/visual_0",
        "world/robot/world/crank/rod/joint_crank_pin",
        "world/springs/return_spring",
        "world/loads/piston_load",
        "world/gravity",
        "world/reactions/wrist_pin",
        "world/com/crank",
        "plots/potential_energy",
        "plots/gradient_norm",
    ] {
        assert!(
            rec.entities.contains(entity),
            "missing {entity}; have {:?}",
            rec.entities
        );
    }
    assert!(rec.timelines.contains("iteration"), "{:?}", rec.timelines);
    assert!(rec.timelines.contains("mode"), "{:?}", rec.timelines);
}

#[test]
fn meshes_become_mesh_entities() {
    let path = format!(
        "{}/robots/gazebo_transmission.urdf",
        env!("CARGO_MANIFEST_DIR")
    );
    let l = restpose::urdf::load_file(&path, &Default::default()).unwrap();
    let (state, report) = restpose::solve(&l.model, &Default::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("arm.rrd");
    restpose::view::write_recording(&out, &l.model, &state, &report, &[]).unwrap();
    let rec = restpose::view::read_recording(&out).unwrap();
    assert!(
        rec.entities.iter().any(|e| e.contains("visual_")),
        "{:?}",
        rec.entities
    );
}

/// Issue 13: the ground, the contact points with their forces (the Solo-12 standing on its
/// feet), and a joint resting on its stop are drawn.
#[test]
fn recording_shows_the_ground_the_contacts_and_the_stops() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let opts = restpose::urdf::ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let m = restpose::urdf::load_file(format!("{dir}/robots/solo12/solo12_ground.urdf"), &opts)
        .unwrap()
        .model;
    let options = restpose::Options {
        friction: restpose::model::Friction::Stick,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&m, &options).unwrap();
    assert_eq!(report.contacts.len(), 4);
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("solo.rrd");
    restpose::view::write_recording(&out, &m, &state, &report, &[]).unwrap();
    let rec = restpose::view::read_recording(&out).unwrap();
    for entity in [
        "world/grounds/floor",
        "world/grounds/floor/grid",
        "world/contacts/points",
        "world/contacts/forces",
    ] {
        assert!(rec.entities.contains(entity), "missing {entity}");
    }
    assert!(!rec.entities.iter().any(|e| e.starts_with("world/stops")));

    let stop = model_from(
        r#"<robot name="stop" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="1 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot" type="revolute"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="1" effort="10" velocity="1"/></joint>
  <mech:gravity xyz="0 -9.81 0"/>
  <mech:joint_spring joint="pivot" stiffness="5"/>
</robot>"#,
    );
    let (state, report) = solve(&stop);
    assert_eq!(report.active_limits.len(), 1);
    let out = tmp.path().join("stop.rrd");
    restpose::view::write_recording(&out, &stop, &state, &report, &[]).unwrap();
    let rec = restpose::view::read_recording(&out).unwrap();
    assert!(
        rec.entities.contains("world/stops/pivot"),
        "{:?}",
        rec.entities
    );
    assert!(!rec.entities.iter().any(|e| e.starts_with("world/contacts")));
}
