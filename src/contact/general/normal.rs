//! The normal and electric subproblem at fixed shear traction (module docs of [`super`]):
//! Kalker's active-set method on the contact elements.

use std::collections::HashSet;
use std::f64::consts::PI;

use super::dense::{Kernel, NotPositiveDefinite, Workspace};
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
    let mut extensions = 0;
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
        let gaps = gaps(
            input,
            (&sol.pressure, &sol.charge, sol.approach),
            &sol.contact,
        );
        // Gap tolerance: 1e−9 of the profile height at the outermost contact element.
        let scale = (0..n)
            .filter(|&i| contact[i])
            .map(|i| input.coefficients.profile.gap(input.mesh.centre(i)))
            .fold(0.0, f64::max);
        let tol = 1e-9 * scale;
        let penetrating: Vec<usize> = (0..n).filter(|&i| !contact[i] && gaps[i] < -tol).collect();
        if penetrating.is_empty() && input.grow && extensions < MAX_EXTENSIONS {
            // p ≥ 0 and gap ≥ 0 hold; make the contact the largest such set (module docs of
            // `super`, "smooth contact ends"), then check the gaps again.
            extensions += 1;
            let grown = extend(input, &sol, work)?;
            if grown.contact != sol.contact {
                seen.insert(contact.clone());
                contact = grown.contact;
                last_admissible = Some(sol);
                continue;
            }
        }
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

/// How many times one call of [`solve`] extends the contact ends (each extension runs until
/// no neighbour can join; a second one only follows a set that the gap check changed).
const MAX_EXTENSIONS: usize = 2;

/// The contact extended element by element into its exterior neighbours while the solution on
/// the larger set keeps `p ≥ 0` on every contact element (module docs of `super`, "smooth
/// contact ends"): a neighbour whose trial gives a negative pressure anywhere is not tried
/// again in this call.
fn extend(
    input: &NormalInput,
    sol: &NormalSolution,
    work: &mut Workspace,
) -> Result<NormalSolution, SolveFailure> {
    let n = input.mesh.len();
    let mut best = sol.clone();
    let mut rejected = vec![false; n];
    loop {
        let c = &best.contact;
        let Some(next) = (0..n).find(|&i| {
            !c[i] && !rejected[i] && ((i > 0 && c[i - 1]) || (i + 1 < n && c[i + 1]))
        }) else {
            return Ok(best);
        };
        let mut trial = c.clone();
        trial[next] = true;
        let candidate = solve_on(input, &trial, work)?;
        if (0..n).all(|i| !trial[i] || candidate.pressure[i] >= 0.0) {
            best = NormalSolution {
                iterations: best.iterations + 1,
                ..candidate
            };
        } else {
            rejected[next] = true;
        }
    }
}

/// Mean gap per element, `(1/Δi)∫(uz − δz + x²/2R)`, outside the contact (`contact[i]`
/// false); 0 on it, where the contact equations make it zero. p and g vanish outside the
/// contact, so only the columns of the contact's span enter.
pub(super) fn gaps(
    input: &NormalInput,
    (pressure, charge, approach): (&[f64], &[f64], f64),
    contact: &[bool],
) -> Vec<f64> {
    let c = input.coefficients;
    let n = input.mesh.len();
    let first = contact.iter().position(|&x| x).unwrap_or(0);
    let last = contact.iter().rposition(|&x| x).map_or(0, |i| i + 1);
    let support = first..last.max(first);
    let outside: Vec<bool> = contact.iter().map(|&x| !x).collect();
    let mut lp = vec![0.0; n];
    input
        .influence
        .log_apply_rows(pressure, support.clone(), &outside, &mut lp);
    let mut lg = vec![0.0; n];
    if c.electric.is_some() {
        input
            .influence
            .log_apply_rows(charge, support, &outside, &mut lg);
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
            if contact[i] {
                return 0.0;
            }
            (uz - w * approach + c.profile.gap_integral(x1, x2)) / w
        })
        .collect()
}

/// The linear contact equations on a fixed set (module docs, "normal subproblem"). With
/// `G = −L/π` on C (symmetric positive definite) the gap and potential rows read
/// `Y ⊗ G (p; g) = (b₁ + w δz; b₂ + w φ0)`, `Y = [y22 y23; y23 y33]`, so one factor of G
/// and the solves `u = G⁻¹b₁`, `v = G⁻¹b₂`, `e = G⁻¹w` give the solution in closed form:
/// under charge control `δz = (y22 P + y23 Γ − wᵀu)/wᵀe`, `φ0 = (y23 P + y33 Γ − wᵀv)/wᵀe`
/// and `(p; g) = Y⁻¹ (u + δz e; v + φ0 e)`.
fn solve_on(
    input: &NormalInput,
    contact: &[bool],
    work: &mut Workspace,
) -> Result<NormalSolution, SolveFailure> {
    let c = input.coefficients;
    let mesh = input.mesh;
    let n = mesh.len();
    let act: Vec<usize> = (0..n).filter(|&i| contact[i]).collect();
    let (y23, y33, w13) = c.electric.unwrap_or((0.0, 0.0, 0.0));
    let mut sq = vec![0.0; n];
    if c.coupled {
        input.influence.sign_apply(input.shear, &mut sq);
    }
    let kernel = Kernel {
        log: &input.influence.log,
        scale: -1.0 / PI,
    };
    let factor = Workspace::factor(&mut work.normal, kernel, &act).map_err(not_definite)?;
    let mut b1 = vec![0.0; n];
    let mut b2 = vec![0.0; n];
    let mut w = vec![0.0; n];
    for &i in &act {
        let (x1, x2) = (mesh.edges[i], mesh.edges[i + 1]);
        w[i] = x2 - x1;
        b1[i] = -c.profile.gap_integral(x1, x2) - 0.5 * c.w12 * sq[i];
        b2[i] = -0.5 * w13 * sq[i];
        if let ElectricControl::Potential(phi) = input.electric {
            b2[i] += w[i] * phi;
        }
    }
    let on_c = |a: &[f64], b: &[f64]| act.iter().map(|&i| a[i] * b[i]).sum::<f64>();
    let [u, e, v] = factor.solve([&b1, &w, &b2]);
    let (wu, we) = (on_c(&w, &u), on_c(&w, &e));
    let load = input.normal_load;
    let mut pressure = vec![0.0; n];
    let mut charge = vec![0.0; n];
    let (approach, potential) = match (input.electric, c.electric.is_some()) {
        (ElectricControl::Charge(gamma), true) => {
            let wv = on_c(&w, &v);
            let dz = (c.y22 * load + y23 * gamma - wu) / we;
            let phi = (y23 * load + y33 * gamma - wv) / we;
            let det = c.y22 * y33 - y23 * y23;
            // Y⁻¹ = [ya yb; yb yc].
            let (ya, yb, yc) = (y33 / det, -y23 / det, c.y22 / det);
            for &i in &act {
                let (s, t) = (u[i] + dz * e[i], v[i] + phi * e[i]);
                pressure[i] = ya * s + yb * t;
                charge[i] = yb * s + yc * t;
            }
            (dz, phi)
        }
        (ElectricControl::Potential(phi), true) => {
            // Eliminating g: (y22 − y23²/y33) G p = b₁ − (y23/y33) b₂ + w δz.
            let wv = on_c(&w, &v);
            let ratio = y23 / y33;
            let ystar = c.y22 - y23 * ratio;
            let dz = (ystar * load - wu + ratio * wv) / we;
            for &i in &act {
                pressure[i] = (u[i] - ratio * v[i] + dz * e[i]) / ystar;
                charge[i] = (v[i] - y23 * pressure[i]) / y33;
            }
            (dz, phi)
        }
        _ => {
            let dz = (c.y22 * load - wu) / we;
            for &i in &act {
                pressure[i] = (u[i] + dz * e[i]) / c.y22;
            }
            (dz, 0.0)
        }
    };
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !(finite(&pressure) && finite(&charge) && approach.is_finite() && potential.is_finite()) {
        return Err(SolveFailure::NonFinite {
            field: "normal subproblem solution",
        });
    }
    Ok(NormalSolution {
        pressure,
        charge,
        approach,
        potential,
        contact: contact.to_vec(),
        iterations: 0,
        cycled: false,
    })
}

/// The failure of a factor: the kernel is not positive definite on the elements.
pub(super) fn not_definite(_: NotPositiveDefinite) -> SolveFailure {
    SolveFailure::NoAdmissibleState {
        reason: "the logarithmic kernel is not positive definite on the contact elements: \
                 the datum d must exceed a quarter of the mesh's length"
            .into(),
    }
}
