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
