//! Tests of the sparse partition (module `partition`): rank and conditioning against the
//! dense full-pivoting partition, and where contact rows are pivoted.

use crate::constraints::Constraints;
use crate::solver::system::{Backend, System};
use crate::urdf::{load_str, ImportOptions};

fn models() -> Vec<crate::model::Model> {
    let mut texts: Vec<String> = [
        include_str!("../../../robots/pendulum.urdf"),
        include_str!("../../../robots/slider_crank.urdf"),
        include_str!("../../../robots/four_bar_spatial.urdf"),
        include_str!("../../../robots/stewart_platform.urdf"),
        include_str!("../../../robots/tractor_trailer.urdf"),
        include_str!("../../../robots/quadruped_leg.urdf"),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    texts.push(crate::generate::ladder(5));
    texts.push(crate::generate::chain(9, false));
    texts
        .iter()
        .map(|t| {
            load_str(t, "m.urdf", &ImportOptions::default())
                .unwrap()
                .model
        })
        .collect()
}

/// A rope of 60 links, 20 hanging 0.3 rad off the vertical, the rest lying on the ground,
/// with the contacts touching at the start active: the lowest hanging link's contact (at
/// its lower end, on the ground) has the lever `l cos φ` on its own angle, below half its
/// reach, so its row is carried on up the hanging links (each with the same lever here: the
/// rope is straight) instead of pivoting on the steep link's angle; the lying links' rows
/// are pivoted with their links. The partition lists its second-pass choices and its `Φ_u` is as well
/// conditioned as the dense full-pivoting one's (within 10×).
#[test]
fn a_contact_below_a_steep_link_is_not_pivoted_on_its_angle() {
    use crate::constraints::unilateral::{gap, Unilateral};
    use crate::constraints::BlockKind;
    let model = load_str(
        &crate::generate::rope(60),
        "rope.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let q0 = crate::solver::initial_state(&model).q;
    let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
    let options = crate::solver::Options::default();
    let active: Vec<_> = crate::solver::inequality::active_set::inequalities(&model, &options)
        .into_iter()
        .filter(|u| gap(&model, u, &q, &Default::default()).is_some_and(|g| g.abs() < 1e-9))
        .map(|u| crate::solver::inequality::active_set::activate(&model, &options, u, &q))
        .collect();
    // Links 19 (the lowest hanging one) to 59 touch.
    assert_eq!(active.len(), 41);
    let cons = || Constraints::new(&model, &[]).with_active(&model, &active);
    let mut sparse = System::new(&model, cons(), Backend::Sparse);
    let mut dense = System::new(&model, cons(), Backend::Dense);
    let ps = sparse.partition(&q);
    let pd = dense.partition(&q);
    assert!(!ps.second_pass.is_empty() && pd.second_pass.is_empty());
    assert_eq!(ps.independent.len(), pd.independent.len());
    assert_eq!(ps.independent.len(), 19);
    // The body of the dependent coordinate each contact row was pivoted on.
    let link_of = |name: &str| model.bodies.iter().position(|b| b.name == name).unwrap();
    for block in &sparse.problem.cons.blocks {
        let BlockKind::Unilateral(a) = &block.kind else {
            continue;
        };
        let Unilateral::Contact { point, .. } = a.row else {
            panic!("only contacts here");
        };
        let own = link_of(&model.contact_points[point].link);
        let k = ps.rows.iter().position(|&r| r == block.first).unwrap();
        let pivot_body = ps.dependent[k] / 7;
        if own == link_of("link19") {
            assert!(pivot_body < own, "{pivot_body}");
        } else {
            assert_eq!(pivot_body, own);
        }
    }
    let j = sparse.jacobian(&q);
    let cond = |p: &crate::solver::partition::Partition| {
        let r = p.rows.len();
        let a = nalgebra::DMatrix::from_fn(r, r, |i, k| {
            j[(p.rows[i], p.dependent[k])]
                * sparse.problem.scaling.rows[p.rows[i]]
                * sparse.problem.scaling.columns[p.dependent[k]]
        });
        let sv = crate::solver::svd::svd(a, false, false)
            .unwrap()
            .singular_values;
        sv.max() / sv.min()
    };
    let (cs, cd) = (cond(&ps), cond(&pd));
    assert!(cs < 10.0 * cd, "cond(Φ_u) sparse {cs:e} vs dense {cd:e}");
}

/// The body-by-body elimination finds the rank of the dense full-pivoting partition (same
/// degrees of freedom, same number of redundant rows), and its `Φ_u` is well conditioned.
#[test]
fn same_rank_as_full_pivoting_and_well_conditioned() {
    for model in models() {
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
        let cons = || Constraints::new(&model, &[]);
        let mut dense = System::new(&model, cons(), Backend::Dense);
        let mut sparse = System::new(&model, cons(), Backend::Sparse);
        let pd = dense.partition(&q);
        let ps = sparse.partition(&q);
        assert_eq!(ps.independent.len(), pd.independent.len(), "{}", model.name);
        assert_eq!(ps.redundant.len(), pd.redundant.len(), "{}", model.name);
        assert_eq!(
            ps.rows.len() + ps.redundant.len(),
            sparse.problem.cons.len()
        );
        let j = sparse.jacobian(&q);
        let r = ps.rows.len();
        let cond = |p: &crate::solver::partition::Partition| {
            let a = nalgebra::DMatrix::from_fn(r, r, |i, k| {
                j[(p.rows[i], p.dependent[k])]
                    * sparse.problem.scaling.rows[p.rows[i]]
                    * sparse.problem.scaling.columns[p.dependent[k]]
            });
            let sv = crate::solver::svd::svd(a, false, false)
                .unwrap()
                .singular_values;
            sv.max() / sv.min()
        };
        let (cs, cd) = (cond(&ps), cond(&pd));
        assert!(
            cs < 1e3 * cd.max(10.0),
            "{}: cond(Φ_u) sparse {cs:e} vs dense {cd:e}",
            model.name
        );
    }
}
