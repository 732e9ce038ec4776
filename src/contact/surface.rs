//! The surface fields of a state (seed eqs. 64–65, module docs of [`crate::contact`]): σxx0,
//! Dx0 and the displacements at a point ([`SurfacePoint`]), the true gap just outside the
//! contact ends ([`GapReport`]), and the integrals over the contact that give the tangential
//! displacement and the approach δ.

use serde::Serialize;

use super::rules::contact_piece_nodes;
use super::{ContactModel, ContactState, graded_nodes};

/// Surface fields at one point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SurfacePoint {
    /// x (m).
    pub x: f64,
    /// p (Pa).
    pub pressure: f64,
    /// q (Pa).
    pub traction: f64,
    /// g (C/m²).
    pub charge: f64,
    /// σxx0 (Pa).
    pub sigma_xx: f64,
    /// Dx0 (C/m²).
    pub d_x: f64,
}

impl ContactModel {
    /// p, q, g, σxx0 and Dx0 at x (seed eqs. 64–65, module docs).
    pub fn surface_point(&self, state: &ContactState, x: f64) -> SurfacePoint {
        let c = &self.compliance;
        let (y23, y33, w13) = c
            .electric
            .map_or((0.0, 0.0, 0.0), |e| (e.y23, e.y33, e.w13));
        let p = state.pressure_at(x);
        let q = state.traction_at(x);
        let g = state.charge_at(x);
        let dux = state.strain_at(self, x);
        let dphi = w13 * q + y23 * state.pressure_cauchy(x) + y33 * state.charge_cauchy(x);
        self.surface_fields(x, (p, q, g), dux, dphi)
    }

    /// [`Self::surface_point`] at each of `xs` (bit-identical): p, H'p, q and the strain in
    /// batches ([`ContactState::pressures_and_cauchys_into`], [`ContactState::tractions_with`],
    /// [`ContactState::strains_with`]), which sum the stick zone's chain for eight points at
    /// a time.
    pub fn surface_points(&self, state: &ContactState, xs: &[f64]) -> Vec<SurfacePoint> {
        let c = &self.compliance;
        let (y23, y33, w13) = c
            .electric
            .map_or((0.0, 0.0, 0.0), |e| (e.y23, e.y33, e.w13));
        let (mut p, mut h, mut q, mut strain) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        state.pressures_and_cauchys_into(xs, &mut p, &mut h);
        state.tractions_with(xs, &p, &mut q);
        state.strains_with(self, xs, (&p, &h), &mut strain);
        let mut w = Vec::new();
        state.potential_charges_into(xs, &mut w);
        (0..xs.len())
            .map(|k| {
                let x = xs[k];
                let g = state.split.ratio * p[k] + w[k];
                let dphi = w13 * q[k] + y23 * h[k] + y33 * state.charge_cauchy_with(x, h[k]);
                self.surface_fields(x, (p[k], q[k], g), strain[k], dphi)
            })
            .collect()
    }

    /// σxx0 and Dx0 (seed eqs. 64–65) from p, q, g, the surface strain `∂ux/∂x` and the
    /// potential gradient `∂φ/∂x` at x.
    pub fn surface_fields(
        &self,
        x: f64,
        (p, q, g): (f64, f64, f64),
        strain: f64,
        gradient: f64,
    ) -> SurfacePoint {
        let d = &self.field_coefficients;
        SurfacePoint {
            x,
            pressure: p,
            traction: q,
            charge: g,
            sigma_xx: -d.delta1 * p - d.delta2 * g + d.delta3 * strain,
            d_x: -d.e15_over_c44 * q - d.delta4 * gradient,
        }
    }
}

/// The true gap just outside the contact ends (seed model check, formulation §7).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GapReport {
    /// Smallest gap found within one half-width outside either end (m); negative means the
    /// surface interpenetrates the punch.
    pub min_gap: f64,
    /// Where (m).
    pub at: f64,
    /// The Hertzian scale `a²/(2R)` (m), for comparison.
    pub scale: f64,
}

impl ContactModel {
    /// Gap `g(x) = uz(x) − (δ0 − x²/(2R))` outside the contact, from
    /// `g' = w12 q + y22 H'p + y23 H'g + x/R` (eq. B; q = 0 outside) integrated from each contact
    /// end with `x = end ± v²` (which absorbs the inverse square root of a conducting punch's
    /// charge), sampled at 60 points, clustered quadratically towards the end, up to one
    /// half-width away.
    pub fn outside_gap(&self, state: &ContactState) -> GapReport {
        let y23 = self.compliance.electric.map_or(0.0, |e| e.y23);
        let slope = |x: f64| {
            self.compliance.y22 * state.pressure_cauchy(x)
                + y23 * state.charge_cauchy(x)
                + self.profile.slope(x)
        };
        let (c, a) = (state.centre, state.half_width);
        let (nodes, weights) = crate::quadrature::gauss_legendre(64);
        let mut report = GapReport {
            min_gap: f64::INFINITY,
            at: f64::NAN,
            scale: self.profile.gap(a),
        };
        for dir in [1.0, -1.0] {
            let end = c + dir * a;
            for k in 1..=60 {
                let reach = a * (k as f64 / 60.0).powi(2);
                let vmax = reach.sqrt();
                // ∫_0^{vmax} g'(end + dir v²) 2v dv · dir
                let gap: f64 = nodes
                    .iter()
                    .zip(&weights)
                    .map(|(u, w)| {
                        let v = 0.5 * vmax * (u + 1.0);
                        0.5 * vmax * w * slope(end + dir * v * v) * 2.0 * v
                    })
                    .sum::<f64>()
                    * dir;
                if gap < report.min_gap {
                    report.min_gap = gap;
                    report.at = end + dir * reach;
                }
            }
        }
        report
    }
}

impl ContactState {
    /// `∫ f dt` over the contact by the contact integrals' rule (`contact_piece_nodes` on
    /// the pieces of [`graded_nodes`]), split at the traction's breakpoints
    /// and at `split` (if inside). With the centre kink of a normal-loading zone among the
    /// breakpoints (it was missing before), the arcsine moment's φ0 over the default history
    /// agrees with a 256-node rule to 1e−10 V of 17 V (the 96-node rule without the kink point:
    /// 8e−7 V).
    pub fn contact_integral(&self, split: Option<f64>, f: &dyn Fn(&[f64], &mut Vec<f64>)) -> f64 {
        let (at, weights) = graded_nodes(self.contact_points(split), self.contact_rule());
        let mut values = Vec::with_capacity(at.len());
        f(&at, &mut values);
        weights.iter().zip(&values).map(|(w, v)| w * v).sum()
    }

    /// The nodes of the contact integrals' rule on a piece `[x0, x1]` of this contact
    /// ([`contact_piece_nodes`]), for [`graded_nodes`].
    fn contact_rule(&self) -> impl Fn(f64, f64) -> usize + use<> {
        let (contact, m) = ((self.centre, self.half_width), self.pressure.beta.len());
        move |x0, x1| contact_piece_nodes(x0, x1, contact, m)
    }

    /// The contact ends, the traction's breakpoints inside the contact and `split` (if inside).
    fn contact_points(&self, split: Option<f64>) -> Vec<f64> {
        let (c, a) = (self.centre, self.half_width);
        let mut pts = vec![c - a, c + a];
        pts.extend(
            self.traction_breakpoints()
                .into_iter()
                .filter(|x| *x >= c - a && *x <= c + a),
        );
        if let Some(x) = split.filter(|x| *x > c - a && *x < c + a) {
            pts.push(x);
        }
        pts
    }

    /// The surface tangential displacement `ux(x)` and the normal approach δn of the punch.
    ///
    /// `ux` with the regularised kernel of seed eq. (4), `∫₀^∞ cos(sr)/s ds → −ln(|r|/d)`:
    /// `ux(x) = −½ ∫ ((w12 + χ w13) p + w13 w)(s) sign(x − s) ds − (y11/π) ∫ q(s) ln(|x − s|/d) ds`.
    /// The datum d adds `(y11/π) ln(d) Q`, a term linear in Q.
    ///
    /// `δn = uz(x) + x²/(2R)` (any x in the contact; evaluated at the contact centre), with
    /// `uz(x) = ½∫ w12 q(s) sign(x − s) ds − (1/π)∫ (y22 p + y23 g)(s) ln(|x − s|/d) ds`
    /// (eq. B integrated with the regularised kernel).
    ///
    /// Both from one evaluation of p, w and q on the nodes of [`Self::contact_integral`]'s
    /// rule, split at both x and the contact centre. Each logarithm's singularity is taken out,
    /// `∫ (f(s) − f(x)) ln(|x − s|/d) ds + f(x) ∫ ln(|x − s|/d) ds` (the second integral in
    /// closed form), so that the rule suffices. Measured on the default history (M = 64, 32
    /// nodes per piece): δ within 1e−18 m (1e−10 of its range) of a 256-node rule, where the
    /// 96-node rule without the subtraction was within 1.3e−17 m and the 32-node rule without
    /// it 6.4e−16 m. With both split points in one rule (before, each integral had its own),
    /// the records' δ against four times the nodes: 8.5e−12 of its range (default history,
    /// M = 32; 8.5e−11 before) and 5.2e−10 (Figure-3 history with Γ = 4e−7 C/m; 1.5e−9).
    pub fn displacement_and_approach(&self, model: &ContactModel, x: f64) -> (f64, f64) {
        self.displacement_and_approach_with(model, x, self.contact_rule())
    }

    /// [`Self::displacement_and_approach`] with `nodes(x0, x1)` nodes on the piece `[x0, x1]`
    /// instead of the contact integrals' rule.
    pub(crate) fn displacement_and_approach_with(
        &self,
        model: &ContactModel,
        x: f64,
        nodes: impl Fn(f64, f64) -> usize,
    ) -> (f64, f64) {
        let centre = self.centre;
        let mut points = self.contact_points(Some(x));
        points.push(centre);
        let (at, weights) = graded_nodes(points, nodes);
        // p, w and q at the nodes, then at x and the centre.
        let fields = |xs: &[f64]| {
            let (mut p, mut w, mut q) = (Vec::new(), Vec::new(), Vec::new());
            self.pressures_into(xs, &mut p);
            self.potential_charges_into(xs, &mut w);
            self.tractions_with(xs, &p, &mut q);
            (p, w, q)
        };
        let (p, w, q) = fields(&at);
        let (p0, w0, q0) = fields(&[x, centre]);
        let c = &model.compliance;
        let w13 = c.electric.map_or(0.0, |e| e.w13);
        let y23 = c.electric.map_or(0.0, |e| e.y23);
        let local = model.local_pressure_strain(self.split);
        // The densities of ux's sign integral and of uz's logarithmic one.
        let tangential = |p: f64, w: f64| local * p + w13 * w;
        let normal = |p: f64, w: f64| c.y22 * p + y23 * (self.split.ratio * p + w);
        let d = model.reference_distance;
        let log_distance = |from: f64, s: f64| {
            if (from - s).abs() > 0.0 {
                ((from - s).abs() / d).ln()
            } else {
                0.0
            }
        };
        let (q_x, normal_centre) = (q0[0], normal(p0[1], w0[1]));
        let mut sums = [0.0; 4];
        for k in 0..at.len() {
            let (s, wt) = (at[k], weights[k]);
            sums[0] += wt * tangential(p[k], w[k]) * (x - s).signum();
            sums[1] += wt * (q[k] - q_x) * log_distance(x, s);
            sums[2] += wt * q[k] * (centre - s).signum();
            sums[3] += wt * (normal(p[k], w[k]) - normal_centre) * log_distance(centre, s);
        }
        let (lo, hi) = (centre - self.half_width, centre + self.half_width);
        let pi = std::f64::consts::PI;
        let ux = -0.5 * sums[0] - c.y11 / pi * (sums[1] + q_x * log_moment(lo, hi, x, d));
        let uz =
            0.5 * c.w12 * sums[2] - (sums[3] + normal_centre * log_moment(lo, hi, centre, d)) / pi;
        (ux, uz + model.profile.gap(centre))
    }

    /// Where the traction is not smooth: the stick ends, and the ends, fade ramps and centre
    /// kinks of the zones in the chain.
    pub fn traction_breakpoints(&self) -> Vec<f64> {
        let Some(stick) = self.traction.stick.as_ref() else {
            return Vec::new();
        };
        let mut pts = vec![stick.lo, stick.hi];
        pts.extend(stick.chain_points());
        pts
    }
}

/// `∫ ln(|x − s|/d) ds` from `lo` to `hi`, in closed form (any x).
fn log_moment(lo: f64, hi: f64, x: f64, d: f64) -> f64 {
    // F(r) = r ln(|r|/d) − r is an antiderivative of ln(|r|/d) in r = s − x.
    let antiderivative = |r: f64| {
        if r.abs() > 0.0 {
            r * (r.abs() / d).ln() - r
        } else {
            0.0
        }
    };
    antiderivative(hi - x) - antiderivative(lo - x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batch gives [`ContactModel::surface_point`]'s values to the bit at 401 points in and
    /// beside the contact, over the first 30 steps of the default history (a loading and a
    /// reversal, with the chains of earlier stick zones).
    #[test]
    fn surface_points_are_surface_point_at_each_point() {
        let model = crate::scenario::default_scenario().model;
        let disc = crate::contact::pressure::Discretisation::new(64);
        let bits = |p: &SurfacePoint| {
            [p.x, p.pressure, p.traction, p.charge, p.sigma_xx, p.d_x].map(f64::to_bits)
        };
        let mut reversed = false;
        crate::history::walk_default_history(&disc, 30, |old, s| {
            reversed |= old.tangential_load > s.tangential_load;
            let xs: Vec<f64> = (0..401)
                .map(|k| s.centre + s.half_width * (-1.5 + 3.0 * (k as f64 + 0.3) / 401.0))
                .collect();
            let batch = model.surface_points(s, &xs);
            for (&x, b) in xs.iter().zip(&batch) {
                assert_eq!(bits(b), bits(&model.surface_point(s, x)), "x = {x:e}");
            }
        });
        assert!(reversed, "the steps reach a reversal");
    }

    #[test]
    fn log_moment_matches_hand_integrals() {
        // ∫_{−1}^{1} ln|s| ds = −2; ∫_{−1}^{1} ln(2 − s) ds = ∫_1^3 ln r dr = 3 ln 3 − 2;
        // the datum d subtracts (hi − lo) ln d; x = lo gives ∫_0^2 ln r dr = 2 ln 2 − 2.
        let cases = [
            (0.0, 1.0, -2.0),
            (2.0, 1.0, 3.0 * 3f64.ln() - 2.0),
            (-2.0, 1.0, 3.0 * 3f64.ln() - 2.0),
            (0.0, 0.01, -2.0 - 2.0 * 0.01f64.ln()),
            (-1.0, 1.0, 2.0 * 2f64.ln() - 2.0),
        ];
        for (x, d, expected) in cases {
            let got = log_moment(-1.0, 1.0, x, d);
            assert!(
                (got - expected).abs() < 1e-14,
                "x = {x}, d = {d}: {got} vs {expected}"
            );
        }
    }
}
