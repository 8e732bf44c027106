//! What a rest written back by `--write-urdf` does not carry: the servos whose reference is
//! their joint's start.
//!
//! A servo's reference is, first found, its own `@REF`, the reference pose's value
//! (`--servo-reference`, `--srdf-state`), the joint's start (`mech:initial`, `--initial`), 0
//! (module `urdf::servo`). The written file starts every joint at its rest `θ*`, so a servo
//! whose reference came from the file's start (or 0), `θ_ref ≠ θ*`, is held about `θ*` when
//! the written file is analysed again with the same options: another model, whose rest lies
//! elsewhere (Talos's grippers, which its SRDF `half_sitting` does not name: 2 iterations to
//! a rest 1.5·10⁻⁶ J lower). Those servos are named with the option that keeps them.

use restpose::urdf::ImportOptions;
use restpose::{Model, State};

/// The note for the servos of `model` whose reference would move to their rest in `state`
/// when the written file is analysed again with `options`, if any.
pub(crate) fn moved_servo_references(
    options: &ImportOptions,
    model: &Model,
    state: &State,
) -> Option<String> {
    let kept = |name: &str| {
        options
            .servos
            .iter()
            .any(|r| r.joint.as_deref() == Some(name) && r.reference.is_some())
            || options.servo_reference.iter().any(|(n, _)| n == name)
            || options.initial.iter().any(|(n, d, _)| n == name && *d == 0)
    };
    let moved: Vec<String> = model
        .servos()
        .iter()
        .filter_map(|s| {
            let name = &model.joints()[s.joint.index()].name;
            let rest = state.joint(model, name)?.first().copied()?;
            (!kept(name) && rest != s.reference)
                .then(|| format!("--servo {name}={}@{}", s.stiffness, s.reference))
        })
        .collect();
    (!moved.is_empty()).then(|| {
        format!(
            "note: the written file starts every joint at its rest; {} servo(s) take their \
             reference from the start, so analysing it again would hold them about the rest \
             instead; to keep these servos add: {}",
            moved.len(),
            moved.join(" ")
        )
    })
}
