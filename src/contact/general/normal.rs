//! The normal and electric subproblem at fixed shear traction (module docs of [`super`]):
//! Kalker's active-set method on the contact elements.

use std::collections::HashSet;
use std::f64::consts::PI;

use faer::Mat;

use super::dense::{Factored, Workspace};
use super::influence::Influence;
use super::mesh::Mesh;
use super::{Coefficients, ElectricControl};
use crate::error::SolveFailure;

/// The normal subproblem's data.
pub(super) struct NormalInput<'a> {
    pub mesh: &'a Mesh,
    pub influence: &'a Influence,
    pub coefficients: &'a Coefficients,
    /// Shear traction per element (Pa), held fixed.
    pub shear: &'a [f64],
    /// P (N/m).
    pub normal_load: f64,
    pub electric: ElectricControl,
    /// Whether elements may enter the contact (false: the set may only shrink).
    pub grow: bool,
}

/// The normal subproblem's solution.
#[derive(Debug, Clone)]
pub(super) struct NormalSolution {
    pub pressure: Vec<f64>,
    pub charge: Vec<f64>,
    /// Rigid approach δz of the punch (m, into the solid).
    pub approach: f64,
    /// Punch potential φ0 (V; zero without a conducting punch).
    pub potential: f64,
    pub contact: Vec<bool>,
    pub iterations: usize,
    /// Whether the active set returned to an earlier set (the last set with p ≥ 0 is kept).
    pub cycled: bool,
}

/// Kalker's NORM on the elements: solve the contact equations on the current set, drop every
/// element with p < 0, else add every element with a negative gap, until neither occurs.
pub(super) fn solve(
    input: &NormalInput,
    mut contact: Vec<bool>,
    work: &mut Workspace,
) -> Result<NormalSolution, SolveFailure> {
    let n = input.mesh.len();
    let mut seen: HashSet<Vec<bool>> = HashSet::new();
    let mut last_admissible: Option<NormalSolution> = None;
    for iteration in 1..=4 * n + 10 {
        if !contact.iter().any(|&c| c) {
            return Err(SolveFailure::NoAdmissibleState {
                reason: "the normal subproblem lost every contact element".into(),
            });
        }
        let mut sol = solve_on(input, &contact, work)?;
        sol.iterations = iteration;
        let negative: Vec<usize> = (0..n)
            .filter(|&i| contact[i] && sol.pressure[i] < 0.0)
            .collect();
        if !negative.is_empty() {
            seen.insert(contact.clone());
            for i in negative {
                contact[i] = false;
            }
            if seen.contains(&contact) {
                return last_admissible.ok_or(SolveFailure::NoAdmissibleState {
                    reason: "the normal active set cycles without a state with p ≥ 0".into(),
                });
            }
            continue;
        }
        let gaps = gaps(input, &sol);
        // Gap tolerance: 1e−9 of the profile height at the outermost contact element.
        let scale = (0..n)
            .filter(|&i| contact[i])
            .map(|i| input.coefficients.profile.gap(input.mesh.centre(i)))
            .fold(0.0, f64::max);
        let tol = 1e-9 * scale;
        let penetrating: Vec<usize> = (0..n).filter(|&i| !contact[i] && gaps[i] < -tol).collect();
        if penetrating.is_empty() || !input.grow {
            return Ok(sol);
        }
        seen.insert(contact.clone());
        for i in penetrating {
            contact[i] = true;
        }
        if seen.contains(&contact) {
            sol.cycled = true;
            return Ok(sol);
        }
        last_admissible = Some(sol);
    }
    Err(SolveFailure::NoConvergence {
        what: "normal active set",
        iterations: 4 * n + 10,
        residual: f64::NAN,
    })
}

/// Mean gap per element, `(1/Δi)∫(uz − δz + x²/2R)`, for every element.
fn gaps(input: &NormalInput, sol: &NormalSolution) -> Vec<f64> {
    let c = input.coefficients;
    let n = input.mesh.len();
    let mut lp = vec![0.0; n];
    input.influence.log_apply(&sol.pressure, &mut lp);
    let mut lg = vec![0.0; n];
    if c.electric.is_some() {
        input.influence.log_apply(&sol.charge, &mut lg);
    }
    let mut sq = vec![0.0; n];
    if c.coupled {
        input.influence.sign_apply(input.shear, &mut sq);
    }
    let (y23, _, _) = c.electric.unwrap_or((0.0, 0.0, 0.0));
    (0..n)
        .map(|i| {
            let (x1, x2) = (input.mesh.edges[i], input.mesh.edges[i + 1]);
            let w = x2 - x1;
            let uz = -(c.y22 / PI) * lp[i] - (y23 / PI) * lg[i] + 0.5 * c.w12 * sq[i];
            (uz - w * sol.approach + c.profile.gap_integral(x1, x2)) / w
        })
        .collect()
}

/// The linear contact equations on a fixed set (module docs, "normal subproblem").
fn solve_on(
    input: &NormalInput,
    contact: &[bool],
    work: &mut Workspace,
) -> Result<NormalSolution, SolveFailure> {
    let c = input.coefficients;
    let mesh = input.mesh;
    let n = mesh.len();
    let act: Vec<usize> = (0..n).filter(|&i| contact[i]).collect();
    let m = act.len();
    let (has_g, charge_row) = match (c.electric, input.electric) {
        (Some(_), ElectricControl::Charge(_)) => (true, true),
        (Some(_), ElectricControl::Potential(_)) => (true, false),
        _ => (false, false),
    };
    let (y23, y33, w13) = c.electric.unwrap_or((0.0, 0.0, 0.0));
    let size = if has_g { 2 * m + 1 } else { m + 1 } + usize::from(charge_row);
    let mut a = Mat::<f64>::zeros(size, size);
    let mut b = vec![0.0; size];
    let mut sq = vec![0.0; n];
    if c.coupled {
        input.influence.sign_apply(input.shear, &mut sq);
    }
    let col_dz = if has_g { 2 * m } else { m };
    let cached = matches!(&work.normal, Some((set, _)) if set.as_slice() == contact);
    for (r, &i) in act.iter().enumerate() {
        let (x1, x2) = (mesh.edges[i], mesh.edges[i + 1]);
        let w = x2 - x1;
        for (k, &j) in act.iter().enumerate().filter(|_| !cached) {
            let l = input.influence.log[(i, j)];
            a[(r, k)] = -(c.y22 / PI) * l;
            if has_g {
                a[(r, m + k)] = -(y23 / PI) * l;
                a[(m + r, k)] = -(y23 / PI) * l;
                a[(m + r, m + k)] = -(y33 / PI) * l;
            }
        }
        a[(r, col_dz)] = -w;
        b[r] = -c.profile.gap_integral(x1, x2) - 0.5 * c.w12 * sq[i];
        if has_g {
            b[m + r] = -0.5 * w13 * sq[i];
            match input.electric {
                ElectricControl::Potential(phi) => b[m + r] += w * phi,
                _ => a[(m + r, col_dz + 1)] = -w,
            }
        }
    }
    let row_p = col_dz;
    for (k, &j) in act.iter().enumerate() {
        a[(row_p, k)] = mesh.width(j);
        if charge_row {
            a[(row_p + 1, m + k)] = mesh.width(j);
        }
    }
    b[row_p] = input.normal_load;
    if let ElectricControl::Charge(gamma) = input.electric
        && charge_row
    {
        b[row_p + 1] = gamma;
    }
    if !cached {
        let f = Factored::new(a).ok_or(SolveFailure::NonFinite {
            field: "normal subproblem matrix",
        })?;
        work.normal = Some((contact.to_vec(), f));
    }
    let factored = &work.normal.as_ref().expect("factored above").1;
    let x = factored.solve(&b).ok_or(SolveFailure::NonFinite {
        field: "normal subproblem solution",
    })?;
    let mut pressure = vec![0.0; n];
    let mut charge = vec![0.0; n];
    for (k, &j) in act.iter().enumerate() {
        pressure[j] = x[k];
        if has_g {
            charge[j] = x[m + k];
        }
    }
    let potential = match input.electric {
        ElectricControl::Potential(phi) => phi,
        _ if charge_row => x[col_dz + 1],
        _ => 0.0,
    };
    Ok(NormalSolution {
        pressure,
        charge,
        approach: x[col_dz],
        potential,
        contact: contact.to_vec(),
        iterations: 0,
        cycled: false,
    })
}
