//! A state carried onto another mesh ([`Solver::transfer`]), for steps whose contact moves
//! beyond the elements refined for it (a normal or electric load that changes).
//!
//! # What is carried
//! The next step sees the previous state through its slip reference, the element means of the
//! previous `ux` (module docs of [`super`]: `s = (ux − ux_prev) − (δx − δx_prev)`), and through
//! the start of its iterations (tractions and element states). `ux_prev` is a function of the
//! previous tractions alone, so its means over the new elements are computed exactly from the
//! old piecewise-constant p, q and g with the element integrals between the two meshes,
//!
//! ```text
//! Ux_i = −(w12/2) Σ_j S_ij p_j − (w13/2) Σ_j S_ij g_j − (y11/π) Σ_j L_ij q_j,
//! L_ij = ∫_{e_i}∫_{e_j} ln(|x − s|/d) ds dx,   S_ij = ∫_{e_i}∫_{e_j} sign(x − s) ds dx
//!      = F(x2 − s1) − F(x1 − s1) − F(x2 − s2) + F(x1 − s2),   F(t) = t|t|/2,
//! ```
//!
//! with `e_i = [x1, x2]` a new element and `e_j = [s1, s2]` an old one: the slip of the next
//! step is that of the old mesh's displacement field, with no interpolation error. The
//! tractions are carried as their means over the new elements (p, q and g integrate to the
//! same resultants on both meshes), the element states as the state of the old element that
//! holds the new element's centre, and the rigid-body unknowns (δz, δx, φ0) as they are.

use std::f64::consts::PI;

use super::influence::g2;
use super::{ElementState, GeneralState, Mesh, Solver};

/// `∫_{x1}^{x2} ∫_{s1}^{s2} sign(x − s) ds dx`, exact (`F'' = sign`, `F(t) = t|t|/2`).
pub fn sign_pair(x1: f64, x2: f64, s1: f64, s2: f64) -> f64 {
    let f = |t: f64| 0.5 * t * t.abs();
    f(x2 - s1) - f(x1 - s1) - f(x2 - s2) + f(x1 - s2)
}

/// The means over the elements of `to` of a piecewise-constant density on `from`.
fn means(from: &Mesh, values: &[f64], to: &Mesh) -> Vec<f64> {
    (0..to.len())
        .map(|i| {
            let (x1, x2) = (to.edges[i], to.edges[i + 1]);
            let first = from.edges.partition_point(|&e| e <= x1).saturating_sub(1);
            let mut sum = 0.0;
            for (j, value) in values.iter().enumerate().skip(first) {
                let (s1, s2) = (from.edges[j], from.edges[j + 1]);
                if s1 >= x2 {
                    break;
                }
                sum += value * (x2.min(s2) - x1.max(s1)).max(0.0);
            }
            sum / (x2 - x1)
        })
        .collect()
}

impl Solver {
    /// `old` (on any mesh) as a state on this solver's mesh (module docs).
    pub fn transfer(&self, old: &GeneralState) -> GeneralState {
        let (from, to) = (&old.mesh, &self.mesh);
        let c = &self.coefficients;
        let w13 = c.electric.map_or(0.0, |e| e.2);
        let d = self.reference_distance;
        // The old elements that carry a traction, and `G(x_a − s_b)` at every pair of a new
        // edge and one of their edges: each element integral is four entries of the table.
        let loaded = |j: usize| old.pressure[j] != 0.0 || old.shear[j] != 0.0 || old.charge[j] != 0.0;
        let j0 = (0..from.len()).find(|&j| loaded(j)).unwrap_or(0);
        let j1 = (0..from.len()).rfind(|&j| loaded(j)).unwrap_or(0);
        let old_edges = &from.edges[j0..=j1 + 1];
        let width = old_edges.len();
        let table: Vec<f64> = to
            .edges
            .iter()
            .flat_map(|&x| old_edges.iter().map(move |&s| g2(x - s, d)))
            .collect();
        let displacement = (0..to.len())
            .map(|i| {
                let (x1, x2) = (to.edges[i], to.edges[i + 1]);
                let (lower, upper) = (&table[i * width..], &table[(i + 1) * width..]);
                let mut u = 0.0;
                for (b, j) in (j0..=j1).enumerate() {
                    let (p, q, g) = (old.pressure[j], old.shear[j], old.charge[j]);
                    let (s1, s2) = (from.edges[j], from.edges[j + 1]);
                    let sign = sign_pair(x1, x2, s1, s2);
                    let log = upper[b] - lower[b] - upper[b + 1] + lower[b + 1];
                    u += -0.5 * c.w12 * sign * p - 0.5 * w13 * sign * g - (c.y11 / PI) * log * q;
                }
                u / (x2 - x1)
            })
            .collect();
        let codes = to
            .centres()
            .iter()
            .map(|&x| {
                let k = from.edges.partition_point(|&e| e <= x);
                if k == 0 || k > from.len() {
                    ElementState::Exterior
                } else {
                    old.codes[k - 1]
                }
            })
            .collect();
        GeneralState {
            mesh: to.clone(),
            pressure: means(from, &old.pressure, to),
            shear: means(from, &old.shear, to),
            charge: means(from, &old.charge, to),
            displacement,
            slip: vec![0.0; to.len()],
            codes,
            ..old.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_pair_is_the_product_of_widths_for_separate_elements_and_zero_on_itself() {
        assert!((sign_pair(2.0, 3.0, 0.0, 0.5) - 0.5).abs() < 1e-15);
        assert!((sign_pair(0.0, 0.5, 2.0, 3.0) + 0.5).abs() < 1e-15);
        assert!(sign_pair(0.0, 1.0, 0.0, 1.0).abs() < 1e-15);
        // Overlapping, by hand: ∫₀¹∫_{0.5}^{1.5} sign(x − s) ds dx = ∫₀^{0.5}(−1) dx
        // + ∫_{0.5}^{1}(2x − 2) dx = −0.5 − 0.25.
        assert!((sign_pair(0.0, 1.0, 0.5, 1.5) + 0.75).abs() < 1e-15);
    }

    #[test]
    fn means_keep_the_integral_of_a_density() {
        let from = Mesh::uniform(-1.0, 1.0, 7);
        let to = Mesh::graded(
            -1.2,
            1.1,
            &[super::super::Focus {
                at: 0.3,
                size: 0.01,
            }],
            1.2,
            0.2,
        );
        let values: Vec<f64> = (0..7).map(|i| (i as f64 - 2.5).powi(2)).collect();
        let m = means(&from, &values, &to);
        let total = |mesh: &Mesh, v: &[f64]| {
            v.iter()
                .zip(mesh.widths())
                .map(|(v, w)| v * w)
                .sum::<f64>()
        };
        assert!((total(&from, &values) - total(&to, &m)).abs() < 1e-12);
    }
}
