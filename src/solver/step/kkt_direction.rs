//! The Newton direction of the sparse path, from the KKT system (module `sparse::kkt`):
//! `[W Φ_qᵀ; Φ_q 0] [δq; λ] = [−S(V_qᵀ − Φ_qᵀ μ); 0]`, its independent part the reduced Newton
//! step `Ĥ⁻¹(−∇f)`, with `W` shifted where `Ĥ` is indefinite.

use crate::solver::partition::Partition;
use crate::solver::sparse::kkt::Factored;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The Newton direction from the sparse KKT system (module `sparse::kkt`): the exact
/// reduced Newton step if it is a descent direction, else the step with the `W` block shifted
/// by `δ I`, `δ = 10⁻⁶ max|Ŵ_ii|` and growing a hundredfold until it is (a
/// Levenberg–Marquardt-type modification of an indefinite reduced Hessian); the steepest
/// descent direction if no shift works. Also returns whether the step came from KKT factors
/// with a positive definite reduced Hessian (LDLᵀ with one negative pivot per row), which then
/// stay in `sys` for the step's second-order correction (module `second_order`).
pub(crate) fn kkt_direction(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
) -> (DVector<f64>, bool) {
    let g = &eval.grad_v;
    // Right side `−S (V_qᵀ − Φ_qᵀ μ)`: zero on the dependent coordinates (`Φ_uᵀ μ = V_uᵀ`) and
    // `−∇f` on the independent ones. It has the same projection `Zᵀ b = −∇f` as `−S V_qᵀ`,
    // but is small near the minimum where `V_q` is not (the applied forces balanced by the
    // constraint forces), so the solve's rounding error shrinks with the gradient.
    let mut b = DVector::zeros(q.len());
    for (k, &c) in part.independent.iter().enumerate() {
        b[c] = -g[k];
    }
    let mut delta = 0.0;
    for attempt in 0..12 {
        let mut factored = sys.factor_step_kkt(q, part, eval, attempt == 0, delta);
        let mut dq = sys.kkt_solve(&b);
        if dq.is_none() && matches!(factored, Factored::Ldlt { .. }) {
            // LDLᵀ without pivoting was not accurate enough here: LU with partial pivoting.
            factored = sys.kkt_fall_back_to_lu();
            dq = sys.kkt_solve(&b);
        }
        // The step is taken if it goes downhill, even where the reduced Hessian is indefinite
        // (LDLᵀ would count its negative eigenvalues, but a global shift large enough to
        // remove them slows the soft parts of a stiff mechanism down to a crawl; the line
        // search and the final stability check handle what is left).
        if let (false, Some(dq)) = (factored == Factored::None, dq) {
            let d = DVector::from_iterator(
                part.independent.len(),
                part.independent.iter().map(|&c| dq[c]),
            );
            if d.dot(g) < -1e-12 * d.norm() * g.norm() {
                // The factors are a metric for the second-order correction where the reduced
                // Hessian they hold is positive definite (module `second_order`).
                let definite = factored
                    == Factored::Ldlt {
                        negative: part.rows.len(),
                    };
                return (d, definite);
            }
        }
        delta = if delta == 0.0 {
            1e-6 * sys.kkt_scale().max(1e-12)
        } else {
            delta * 100.0
        };
    }
    (-g.clone(), false)
}
