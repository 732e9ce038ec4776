//! Between the two solvers: a state of the spectral solver ([`ContactState`]) as the element
//! state that the general solver steps from ([`Solver::adopt`]), and the surface fields of an
//! element state ([`Solver::surface_point`]).
//!
//! # Adopting a spectral state
//! p, q and g are averaged over each element by Gauss–Legendre quadrature in the angle θ of
//! `x = c − a cos θ`, in which the square-root ends of p and the inverse square roots of a
//! conducting punch's charge are smooth (`p dx` and `g dx` are). The element displacements
//! that are the slip reference of the next step follow from those means by the element
//! equations of [`super`] (`Ux = −(w12/2)S p − (w13/2)S g − (y11/π)L q`), so the next step sees
//! the adopted tractions exactly as it would see its own. The rigid approach and potential
//! are the width-weighted means over the contact elements of `(Uz_i + Z_i)/w_i` and `Φ_i/w_i`.
//! An element is stuck where `|q| < ηp` (within a relative 1e−9), slipping where q is at the
//! friction limit (the sign of the slip opposing q), and exterior where `p = 0`.
//!
//! # Surface fields of an element state (seed eqs. 64–65)
//! With piecewise-constant p, q, g and `C_f(x) = (1/π)⨍ f(s)/(s − x) ds =
//! (1/π) Σ_j f_j ln|(s_{j+1} − x)/(s_j − x)|`, the surface strain and potential gradient are
//!
//! ```text
//! ∂ux/∂x = −w12 p − w13 g + y11 C_q,     ∂φ/∂x = w13 q + y23 C_p + y33 C_g,
//! ```
//!
//! which [`ContactModel::surface_fields`] turns into σxx0 and Dx0. They are logarithmically
//! singular at element edges where the traction jumps; fields are sampled away from edges.

use std::f64::consts::PI;

use super::{ElementState, GeneralState, Loads, Solver};
use crate::contact::{ContactModel, ContactState, SurfacePoint};
use crate::quadrature::gauss_legendre;

/// Gauss–Legendre points per element for the element means.
const POINTS: usize = 8;

impl Solver {
    /// The friction coefficient η.
    pub fn friction(&self) -> f64 {
        self.coefficients.friction
    }

    /// The element state of a spectral state, with the punch displacement `shift` (m) as its
    /// δx (module docs).
    pub fn adopt(&self, state: &ContactState, loads: Loads, shift: f64) -> GeneralState {
        let mesh = &self.mesh;
        let n = mesh.len();
        let (c, a) = (state.centre, state.half_width);
        let (nodes, weights) = gauss_legendre(POINTS);
        let conducting = self.coefficients.electric.is_some()
            && !matches!(self.electric_control(loads), super::ElectricControl::None);
        let mut pressure = vec![0.0; n];
        let mut shear = vec![0.0; n];
        let mut charge = vec![0.0; n];
        for i in 0..n {
            let (x1, x2) = (mesh.edges[i].max(c - a), mesh.edges[i + 1].min(c + a));
            if x2 <= x1 {
                continue;
            }
            // θ of x = c − a cos θ, increasing with x.
            let angle = |x: f64| ((c - x) / a).clamp(-1.0, 1.0).acos();
            let (t1, t2) = (angle(x1), angle(x2));
            let (mid, half) = (0.5 * (t1 + t2), 0.5 * (t2 - t1));
            let (mut sp, mut sq, mut sg) = (0.0, 0.0, 0.0);
            for (v, w) in nodes.iter().zip(&weights) {
                let t = mid + half * v;
                let x = c - a * t.cos();
                let dx = w * half * a * t.sin();
                sp += state.pressure_at(x) * dx;
                sq += state.traction_at(x) * dx;
                if conducting {
                    sg += state.charge_at(x) * dx;
                }
            }
            let width = mesh.width(i);
            pressure[i] = sp / width;
            shear[i] = sq / width;
            charge[i] = sg / width;
        }
        self.from_tractions(pressure, shear, charge, loads, shift)
    }

    /// The element state of given element tractions: displacements, approach, potential and
    /// element states (module docs).
    fn from_tractions(
        &self,
        pressure: Vec<f64>,
        shear: Vec<f64>,
        charge: Vec<f64>,
        loads: Loads,
        shift: f64,
    ) -> GeneralState {
        let mesh = &self.mesh;
        let n = mesh.len();
        let c = &self.coefficients;
        let (y23, y33, w13) = c.electric.unwrap_or((0.0, 0.0, 0.0));
        let fixed = self.fixed_displacement(&pressure, &charge);
        let (mut lp, mut lq, mut lg, mut sq) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        self.influence.log_apply(&pressure, &mut lp);
        self.influence.log_apply(&shear, &mut lq);
        self.influence.log_apply(&charge, &mut lg);
        self.influence.sign_apply(&shear, &mut sq);
        let coupled = if c.coupled { 1.0 } else { 0.0 };
        let (mut width, mut approach, mut potential) = (0.0, 0.0, 0.0);
        let mut displacement = vec![0.0; n];
        let mut codes = vec![ElementState::Exterior; n];
        for i in 0..n {
            let w = mesh.width(i);
            displacement[i] = (fixed[i] - (c.y11 / PI) * lq[i]) / w;
            if pressure[i] <= 0.0 {
                continue;
            }
            let uz = coupled * 0.5 * c.w12 * sq[i] - (c.y22 / PI) * lp[i] - (y23 / PI) * lg[i];
            let phi = coupled * 0.5 * w13 * sq[i] - (y23 / PI) * lp[i] - (y33 / PI) * lg[i];
            approach += uz + c.profile.gap_integral(mesh.edges[i], mesh.edges[i + 1]);
            potential += phi;
            width += w;
            let limit = c.friction * pressure[i] * (1.0 - 1e-9);
            codes[i] = if shear[i] >= limit && limit > 0.0 {
                ElementState::SlipNegative
            } else if shear[i] <= -limit && limit > 0.0 {
                ElementState::SlipPositive
            } else {
                ElementState::Stick
            };
        }
        let width = width.max(f64::MIN_POSITIVE);
        GeneralState {
            mesh: mesh.clone(),
            pressure,
            shear,
            charge,
            displacement,
            slip: vec![0.0; n],
            codes,
            approach: approach / width,
            shift,
            potential: if c.electric.is_some() {
                potential / width
            } else {
                0.0
            },
            loads,
        }
    }

    /// p, q, g, σxx0 and Dx0 of an element state at x (module docs); zero fields outside the
    /// mesh's elements in contact.
    pub fn surface_point(
        &self,
        model: &ContactModel,
        state: &GeneralState,
        x: f64,
    ) -> SurfacePoint {
        let edges = &self.mesh.edges;
        let c = &self.coefficients;
        let (y23, y33, w13) = c.electric.unwrap_or((0.0, 0.0, 0.0));
        let local = |values: &[f64]| match edges.partition_point(|&e| e <= x) {
            0 => 0.0,
            k if k > values.len() => 0.0,
            k => values[k - 1],
        };
        let cauchy = |values: &[f64]| {
            values
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(j, v)| v * ((edges[j + 1] - x) / (edges[j] - x)).abs().ln())
                .sum::<f64>()
                / PI
        };
        let (p, q, g) = (
            local(&state.pressure),
            local(&state.shear),
            local(&state.charge),
        );
        let strain = -c.w12 * p - w13 * g + c.y11 * cauchy(&state.shear);
        let gradient = w13 * q + y23 * cauchy(&state.pressure) + y33 * cauchy(&state.charge);
        model.surface_fields(x, (p, q, g), strain, gradient)
    }
}
