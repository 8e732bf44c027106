//! The touching rows whose normal force would pull (below `−τ`, the effort tolerance),
//! dropped and the forces solved again without them (module `held`), at most [`ROUNDS`]
//! times: a stop or contact can only push, `λ_n ≥ 0`.

use super::held::Multipliers;
use super::unilateral::Touching;
use crate::error::Result;

/// Largest number of solves dropping the rows that pull.
const ROUNDS: usize = 20;

/// Solves with the touching rows of `list`, dropping those whose normal force would pull
/// (below `−tau`) and solving again, at most [`ROUNDS`] times. Returns the last solve, the
/// forces (zero on the dropped rows) and the rows that pulled in the first round.
#[allow(clippy::type_complexity)]
pub(super) fn with_rounds(
    list: &[Touching],
    tau: f64,
    mut solve: impl FnMut(&[bool]) -> Result<Multipliers>,
) -> Result<(Multipliers, Vec<Vec<f64>>, Vec<(usize, f64)>)> {
    let mut on = vec![true; list.len()];
    let mut pulling = Vec::new();
    let mut round = 0;
    loop {
        let r = solve(&on)?;
        let negative: Vec<usize> = (0..list.len())
            .filter(|&i| on[i] && r.forces[i][0] < -tau)
            .collect();
        if round == 0 {
            pulling = negative.iter().map(|&i| (i, r.forces[i][0])).collect();
        }
        round += 1;
        if negative.is_empty() || round == ROUNDS {
            let mut forces = r.forces.clone();
            for (i, f) in forces.iter_mut().enumerate() {
                if !on[i] || f[0] < -tau {
                    f.iter_mut().for_each(|x| *x = 0.0);
                }
            }
            return Ok((r, forces, pulling));
        }
        for &i in &negative {
            on[i] = false;
        }
    }
}
