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

use faer::Mat;

use super::recall::same_bits;
use super::{ElementState, GeneralState, Loads, Solver};
use crate::contact::{ContactModel, ContactState, SurfacePoint};
use crate::quadrature::gauss_legendre;

/// Gauss–Legendre points per element for the element means.
const POINTS: usize = 8;

/// Bits kept by [`Solver::adopt_rounded`] below the power of two above a field's largest
/// magnitude.
pub const ROUND_BITS: i32 = 32;

/// Round each value to a multiple of `2^(k − ROUND_BITS)`, `2^k` the power of two at or above
/// the largest magnitude: exact arithmetic (a scaling by a power of two and a rounding to an
/// integer), so values equal to round-off round to the same value unless they straddle a
/// midpoint (a chance of about 1e−15·2³² ≈ 4e−6 per value).
pub fn round_to_scale(values: &mut [f64]) {
    let largest = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest <= 0.0 || !largest.is_finite() {
        return;
    }
    let quantum = 2.0_f64.powi(largest.log2().ceil() as i32 - ROUND_BITS);
    for v in values {
        *v = (*v / quantum).round() * quantum;
    }
}

impl Solver {
    /// The friction coefficient η.
    pub fn friction(&self) -> f64 {
        self.coefficients.friction
    }

    /// The element state of a spectral state, with the punch displacement `shift` (m) as its
    /// δx (module docs).
    pub fn adopt(&self, state: &ContactState, loads: Loads, shift: f64) -> GeneralState {
        let [pressure, shear, charge] = self.element_means(state, loads);
        self.state_of_tractions(pressure, shear, charge, loads, shift)
    }

    /// [`Self::adopt`] with the element means of p, q and g rounded to [`ROUND_BITS`] bits
    /// below their largest magnitude ([`round_to_scale`]): spectral states equal to round-off
    /// (the turning states of a steady cycle) are adopted as one state to the bit, whose steps
    /// the general solver's recall then takes from memory ([`super::Recall`]). The rounding
    /// moves a traction by at most 2⁻³³ of the largest, far below the solver's tolerance.
    pub fn adopt_rounded(&self, state: &ContactState, loads: Loads, shift: f64) -> GeneralState {
        let [mut pressure, mut shear, mut charge] = self.element_means(state, loads);
        for values in [&mut pressure, &mut shear, &mut charge] {
            round_to_scale(values);
        }
        self.state_of_tractions(pressure, shear, charge, loads, shift)
    }

    /// How far the tractions of a spectral state are from those of an element state on this
    /// solver's mesh, as the L1 norms of the differences of the element means relative to
    /// the load: `[Σ w|p̄ − p|/P, Σ w|q̄ − q|/(ηP)]`, p̄ and q̄ the spectral state's means,
    /// P the element state's normal load. A memory that differs where the contact sticks shows
    /// in q there, which the ends of the zones do not show.
    pub fn traction_distance(&self, spectral: &ContactState, state: &GeneralState) -> [f64; 2] {
        let [pressure, shear, _] = self.element_means(spectral, state.loads);
        let load = state.loads.normal;
        let l1 = |a: &[f64], b: &[f64]| -> f64 {
            (0..a.len())
                .map(|i| self.mesh.width(i) * (a[i] - b[i]).abs())
                .sum()
        };
        [
            l1(&pressure, &state.pressure) / load,
            l1(&shear, &state.shear) / (self.coefficients.friction * load),
        ]
    }

    /// The element means of p, q and g of a spectral state (module docs): the rule's points
    /// of every element in contact evaluated in one batch ([`ContactState::pressures_into`],
    /// bit-identical to the state's values point by point), then summed element by element.
    fn element_means(&self, state: &ContactState, loads: Loads) -> [Vec<f64>; 3] {
        let mesh = &self.mesh;
        let n = mesh.len();
        let (c, a) = (state.centre, state.half_width);
        let (nodes, weights) = gauss_legendre(POINTS);
        let conducting = !matches!(self.electric_control(loads), super::ElectricControl::None);
        // The points and weights dx of each element in contact, in order.
        let (mut xs, mut dxs, mut elements) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            let (x1, x2) = (mesh.edges[i].max(c - a), mesh.edges[i + 1].min(c + a));
            if x2 <= x1 {
                continue;
            }
            // θ of x = c − a cos θ, increasing with x.
            let angle = |x: f64| ((c - x) / a).clamp(-1.0, 1.0).acos();
            let (t1, t2) = (angle(x1), angle(x2));
            let (mid, half) = (0.5 * (t1 + t2), 0.5 * (t2 - t1));
            elements.push(i);
            for (v, w) in nodes.iter().zip(&weights) {
                let t = mid + half * v;
                xs.push(c - a * t.cos());
                dxs.push(w * half * a * t.sin());
            }
        }
        let (mut p, mut q, mut w) = (Vec::new(), Vec::new(), Vec::new());
        state.pressures_into(&xs, &mut p);
        state.tractions_with(&xs, &p, &mut q);
        if conducting {
            state.potential_charges_into(&xs, &mut w);
        }
        let mut pressure = vec![0.0; n];
        let mut shear = vec![0.0; n];
        let mut charge = vec![0.0; n];
        for (e, &i) in elements.iter().enumerate() {
            let (mut sp, mut sq, mut sg) = (0.0, 0.0, 0.0);
            for k in e * POINTS..(e + 1) * POINTS {
                sp += p[k] * dxs[k];
                sq += q[k] * dxs[k];
                if conducting {
                    // g = χp + w ([`ContactState::charge_at`]).
                    sg += (state.split.ratio * p[k] + w[k]) * dxs[k];
                }
            }
            let width = mesh.width(i);
            pressure[i] = sp / width;
            shear[i] = sq / width;
            charge[i] = sg / width;
        }
        [pressure, shear, charge]
    }

    /// The element state of given element tractions: displacements, approach, potential and
    /// element states (module docs).
    fn state_of_tractions(
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
        let fixed = self.fixed_displacement(&pressure, &charge, loads.bulk_stress);
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
    /// mesh's elements in contact. σxx0 includes the bulk stress σB of the state's loads (the
    /// uniform state adds `σxx = σB` and nothing to Dx).
    pub fn surface_point(
        &self,
        model: &ContactModel,
        state: &GeneralState,
        x: f64,
    ) -> SurfacePoint {
        let edges = &self.mesh.edges;
        // The logarithm of each element that carries a traction or charge, shared by the
        // three Cauchy integrals.
        let logs: Vec<f64> = (0..edges.len() - 1)
            .map(|j| {
                let carries = [&state.pressure, &state.shear, &state.charge]
                    .iter()
                    .any(|values| values.get(j).is_some_and(|&v| v != 0.0));
                if carries { log_ratio(edges, j, x) } else { 0.0 }
            })
            .collect();
        let cauchy = |values: &[f64]| {
            values
                .iter()
                .zip(&logs)
                .filter(|(v, _)| **v != 0.0)
                .map(|(v, l)| v * l)
                .sum::<f64>()
                / PI
        };
        let integrals = [&state.pressure, &state.shear, &state.charge].map(|v| cauchy(v));
        self.fields_from(model, state, x, integrals)
    }

    /// [`Solver::surface_point`] at each of `points`, with the logarithms kept in `kept`
    /// where given ([`PointLogs`]: the Cauchy integrals of all points are then one product
    /// of the kept table with p, q and g, the same sums to round-off).
    pub fn surface_points(
        &self,
        model: &ContactModel,
        state: &GeneralState,
        points: &[f64],
        kept: Option<&mut PointLogs>,
    ) -> Vec<SurfacePoint> {
        let direct = || {
            (points.iter())
                .map(|&x| self.surface_point(model, state, x))
                .collect()
        };
        let Some(kept) = kept else {
            return direct();
        };
        let edges = &self.mesh.edges;
        if !(same_bits(&kept.edges, edges) && same_bits(&kept.points, points)) {
            *kept = PointLogs {
                edges: edges.clone(),
                points: points.to_vec(),
                logs: None,
            };
            return direct();
        }
        let n = self.mesh.len();
        let logs = kept.logs.get_or_insert_with(|| {
            Mat::from_fn(points.len(), n, |k, j| {
                let l = log_ratio(edges, j, points[k]);
                if l.is_finite() { l } else { 0.0 }
            })
        });
        let fields = [&state.pressure, &state.shear, &state.charge];
        let values = Mat::from_fn(n, 3, |j, f| fields[f][j] / PI);
        let mut cauchy = Mat::<f64>::zeros(points.len(), 3);
        faer::linalg::matmul::matmul(
            cauchy.as_mut(),
            faer::Accum::Replace,
            logs.as_ref(),
            values.as_ref(),
            1.0,
            faer::Par::Seq,
        );
        (points.iter().enumerate())
            .map(|(k, &x)| {
                let [p, q, g] = [0, 1, 2].map(|f| cauchy[(k, f)]);
                self.fields_from(model, state, x, [p, q, g])
            })
            .collect()
    }

    /// The fields at x from the Cauchy integrals `[C_p, C_q, C_g]`.
    fn fields_from(
        &self,
        model: &ContactModel,
        state: &GeneralState,
        x: f64,
        [cp, cq, cg]: [f64; 3],
    ) -> SurfacePoint {
        let edges = &self.mesh.edges;
        let c = &self.coefficients;
        let (y23, y33, w13) = c.electric.unwrap_or((0.0, 0.0, 0.0));
        let local = |values: &[f64]| match edges.partition_point(|&e| e <= x) {
            0 => 0.0,
            k if k > values.len() => 0.0,
            k => values[k - 1],
        };
        let (p, q, g) = (
            local(&state.pressure),
            local(&state.shear),
            local(&state.charge),
        );
        let strain = -c.w12 * p - w13 * g + c.y11 * cq;
        let gradient = w13 * q + y23 * cp + y33 * cg;
        let mut point = model.surface_fields(x, (p, q, g), strain, gradient);
        point.sigma_xx += state.loads.bulk_stress;
        point
    }
}

/// `ln|(s_{j+1} − x)/(s_j − x)|` of element j.
fn log_ratio(edges: &[f64], j: usize, x: f64) -> f64 {
    ((edges[j + 1] - x) / (edges[j] - x)).abs().ln()
}

/// The logarithms of [`Solver::surface_point`] at fixed points on one mesh, kept while the
/// mesh stays: a run samples the fields of every step at the same grid points (the fatigue
/// indicators, `crate::fatigue::step_samples`), and the general solver keeps its mesh while
/// the normal and electric loads stay. The table is built at the second use of a mesh in a
/// row, so a mesh used for one step (each step of a history that changes P) costs what the
/// direct evaluation does. A speed-up only, switched by passing it or not (the fields agree
/// to round-off: test `kept_point_logs_give_the_direct_fields`).
#[derive(Debug, Clone, Default)]
pub struct PointLogs {
    /// The mesh edges and the points of the last use.
    edges: Vec<f64>,
    points: Vec<f64>,
    /// `ln|(s_{j+1} − x)/(s_j − x)|` per point (rows) and element, once built (0 where a
    /// point is an edge of the element: fields are sampled away from edges).
    logs: Option<Mat<f64>>,
}

#[cfg(test)]
mod tests {
    use super::super::{Focus, Mesh, Options};
    use super::*;
    use crate::contact::normal::{NormalOptions, solve_normal};
    use crate::contact::pressure::Discretisation;
    use crate::contact::{Electrode, Profile};
    use crate::material::{Material, PZT4};

    /// The paper's baseline: PZT-4, R = 60 mm, η = 0.3, conducting punch with Γ = 6e−7 C/m,
    /// P = 2000 N/m, at the end of normal loading (Spence's state: slip zones of opposite
    /// signs at the contact ends).
    fn baseline() -> (ContactModel, ContactState) {
        let model = ContactModel::new(
            Material::Piezoelectric(PZT4),
            Profile::cylinder(0.06),
            0.3,
            Electrode::ConductingCharge { charge: 6e-7 },
        );
        let disc = Discretisation::new(64);
        let normal = solve_normal(&model, &disc, 2000.0, NormalOptions::default()).unwrap();
        (model, normal.state)
    }

    fn mesh(state: &ContactState, end: f64, inner: f64) -> Mesh {
        let (c, a) = (state.centre, state.half_width);
        let focus = [-1.0, 1.0].map(|s| Focus {
            at: c + s * a,
            size: end * a,
        });
        Mesh::graded(c - 1.25 * a, c + 1.25 * a, &focus, 1.06, inner * a)
    }

    fn loads(q: f64) -> Loads {
        Loads {
            normal: 2000.0,
            tangential: q,
            electric: 6e-7,
            bulk_stress: 0.0,
        }
    }

    /// The adopted element means carry P and Γ to round-off and Q (zero) to 1e−8 P; p, q, g,
    /// σxx0 and Dx0 at 200 points of |x − c| < 0.9a agree with the spectral state's to the
    /// error of piecewise-constant tractions, which falls as the elements shrink (measured:
    /// largest 1.3e−2 of p0 with elements of 2e−3 a at the ends and 2e−2 a inside, 7.7e−3
    /// with 5e−4 a and 6e−3 a, both σxx0).
    #[test]
    fn adopted_state_keeps_the_resultants_and_the_surface_fields() {
        let (model, state) = baseline();
        let a = state.half_width;
        let p0 = 2.0 * 2000.0 / (std::f64::consts::PI * a);
        let mut errors = Vec::new();
        for (end, inner) in [(2e-3, 2e-2), (5e-4, 6e-3)] {
            let solver = Solver::new(&model, mesh(&state, end, inner), Options::default());
            let adopted = solver.adopt(&state, loads(0.0), 0.0);
            let (p, q, g) = adopted.resultants();
            assert!((p / 2000.0 - 1.0).abs() < 1e-12, "P {p}");
            assert!((g / 6e-7 - 1.0).abs() < 1e-12, "Γ {g}");
            assert!(q.abs() < 1e-7 * 2000.0, "Q {q}");
            let mut worst = [0.0f64; 5];
            for k in 0..200 {
                let x = state.centre + a * (-0.9 + 1.8 * (k as f64 + 0.5) / 200.0);
                let s = model.surface_point(&state, x);
                let e = solver.surface_point(&model, &adopted, x);
                let d = [
                    (s.pressure - e.pressure) / p0,
                    (s.traction - e.traction) / (0.3 * p0),
                    (s.charge - e.charge) / (6e-7 / a),
                    (s.sigma_xx - e.sigma_xx) / p0,
                    (s.d_x - e.d_x) / (6e-7 / a),
                ];
                for (w, d) in worst.iter_mut().zip(d) {
                    *w = w.max(d.abs());
                }
            }
            errors.push(worst);
        }
        for k in 0..5 {
            assert!(errors[1][k] < 1e-2, "field {k}: {:?}", errors[1]);
            assert!(errors[1][k] < 0.75 * errors[0][k], "field {k}: {errors:?}");
        }
    }

    /// The adopted state is an equilibrium of the element equations: a step at the same loads
    /// slips by at most 1e−6 a (measured 6.9e−8 a) and moves p and q by the difference between
    /// the element solution and the means of the spectral one at the contact ends (measured
    /// 4.4e−3 of p0 and of ηp0).
    #[test]
    fn a_step_at_the_same_loads_keeps_the_adopted_state() {
        let (model, state) = baseline();
        let solver = Solver::new(&model, mesh(&state, 5e-4, 6e-3), Options::default());
        let adopted = solver.adopt(&state, loads(0.0), 0.0);
        let (next, _) = solver.step(&adopted, loads(0.0)).unwrap();
        let a = state.half_width;
        let p0 = 2.0 * 2000.0 / (std::f64::consts::PI * a);
        let largest = |x: &[f64], y: &[f64]| {
            x.iter()
                .zip(y)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let dq = largest(&next.shear, &adopted.shear) / (0.3 * p0);
        let dp = largest(&next.pressure, &adopted.pressure) / p0;
        let slip = next.slip.iter().map(|s| s.abs()).fold(0.0, f64::max) / a;
        assert!(slip < 1e-6, "{slip:e}");
        assert!(dp < 1e-2 && dq < 1e-2, "{dp:e} {dq:e}");
    }

    /// The fields of the kept logarithms ([`PointLogs`]: the table is built at the second use
    /// of a mesh and its points) agree with the direct evaluation to round-off at 201 points
    /// in and beside the contact of a state with p, q and g (measured: 6.1e−16 of p0 in σxx0,
    /// 2.0e−15 of Γ/a in Dx0); a table on other points is not used for these.
    #[test]
    fn kept_point_logs_give_the_direct_fields() {
        let (model, state) = baseline();
        let solver = Solver::new(&model, mesh(&state, 5e-4, 6e-3), Options::default());
        let adopted = solver.adopt(&state, loads(0.0), 0.0);
        let (loaded, _) = solver.step(&adopted, loads(0.3 * 0.3 * 2000.0)).unwrap();
        let a = state.half_width;
        let p0 = 2.0 * 2000.0 / (std::f64::consts::PI * a);
        let points: Vec<f64> = (0..201)
            .map(|k| state.centre + a * (-1.2 + 2.4 * (k as f64 + 0.25) / 201.0))
            .collect();
        let mut kept = PointLogs::default();
        let direct = solver.surface_points(&model, &loaded, &points, None);
        let first = solver.surface_points(&model, &loaded, &points, Some(&mut kept));
        assert!(kept.logs.is_none(), "built at the first use");
        assert_eq!(first, direct, "the first use evaluates directly");
        let tabled = solver.surface_points(&model, &loaded, &points, Some(&mut kept));
        assert!(kept.logs.is_some(), "built at the second use");
        let (mut sigma, mut d) = (0.0f64, 0.0f64);
        for (t, e) in tabled.iter().zip(&direct) {
            let bits = |p: &SurfacePoint| [p.x, p.pressure, p.traction, p.charge].map(f64::to_bits);
            assert_eq!(bits(t), bits(e), "the local fields are read, not summed");
            sigma = sigma.max((t.sigma_xx - e.sigma_xx).abs() / p0);
            d = d.max((t.d_x - e.d_x).abs() / (6e-7 / a));
        }
        assert!(sigma < 1e-13 && d < 1e-13, "σxx0 {sigma:e} of p0, Dx0 {d:e} of Γ/a");
        let others = &points[..100];
        let again = solver.surface_points(&model, &loaded, others, Some(&mut kept));
        assert!(kept.logs.is_none(), "other points start a new table");
        assert_eq!(again, direct[..100].to_vec());
    }
}
