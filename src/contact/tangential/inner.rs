//! The linear maps of the inner iteration at one geometry (`InnerMaps`): the stick equation's
//! right-hand side from the pressure and the charge (`local p − η s y11 H'p` and `w13 w`, over
//! y11, seed eqs. 43/60) and q̃'s density at the pressure and charge points, as matrices on the
//! series coefficients.

use crate::contact::ContactState;
use crate::quadrature::{BoundedSeries, ColumnMatrix, RowMatrix};

use super::residual::Coefficients;

/// The buffers of [`InnerMaps::stick_terms`] for series of M terms at M + 1 stick points.
pub(super) struct StickSums {
    coefficients: [Vec<f64>; 2],
    sums: [Vec<f64>; 2],
}

impl StickSums {
    pub(super) fn new(m: usize) -> Self {
        Self {
            coefficients: [vec![0.0; m + 2], vec![0.0; m + 2]],
            sums: [vec![0.0; m + 1], vec![0.0; m + 1]],
        }
    }
}

/// The linear maps of the inner iteration at one geometry, as matrices on the series
/// coefficients (each applied once per pass instead of a Clenshaw sum per point): at the stick
/// points, the stick right-hand side from the pressure (`local p − η s y11 H'p`, over y11) and
/// from the charge (`w13 w`, over y11), both from one matrix of `T_n` values
/// ([`Self::stick_terms`]; one matrix instead of one each for p, w and `H'p`: less memory
/// to read at every pass); at the pressure and charge points inside the stick
/// zone, the density of the stick correction (zero at the others). (The pressure's density at
/// its own and the charge's collocation points does not depend on the geometry: it is a
/// sine transform, [`Discretisation::bounded_at_collocation`].) For mixed slip signs,
/// `H'(pS)(x) = S(x) H'p(x) + (1/π)∫ p(t)(S(t) − S(x))/(t − x) dt` at the stick points (as
/// `ContactState::shape_cauchy`) is kept in three parts: `H'p` at the stick points, p at the
/// graded nodes of the slip and stick pieces, and the quotient weights.
///
/// [`Discretisation::bounded_at_collocation`]:
///     crate::contact::pressure::Discretisation::bounded_at_collocation
#[derive(Default)]
pub(crate) struct InnerMaps {
    /// `T_n(τ_i)`, n = 0 … M + 1, at the stick points (τ in the contact's coordinate).
    stick_t: ColumnMatrix,
    /// `1/√(1 − τ_i²)` at the stick points.
    stick_root: Vec<f64>,
    pub(super) coefficients: Coefficients,
    /// Rows at the sample points inside the stick zone only (`own_rows`): q̃'s own part is
    /// zero outside.
    own_at_samples: ColumnMatrix,
    /// The indices of the sample points inside the stick zone, increasing.
    pub(super) own_rows: Vec<usize>,
    pub(super) shape_nodes: ColumnMatrix,
    pub(super) shape_weights: RowMatrix,
    /// S at the stick points.
    pub(super) stick_shape: Vec<f64>,
    /// The positions of the shape quadrature's nodes (mixed slip signs only).
    pub(super) node_points: Vec<f64>,
}

impl InnerMaps {
    /// The maps for `state`'s geometry (contact and stick zone) at the stick collocation
    /// points and at the pressure-then-charge sample points, for series of M coefficients.
    pub(super) fn rebuild(
        &mut self,
        state: &ContactState,
        stick_points: &[f64],
        sample_points: &[f64],
        m: usize,
        k: Coefficients,
    ) {
        let (c, a) = (state.centre, state.half_width);
        let stick = state.traction.stick.as_ref().expect("stick zone set");
        let rows = stick_points.len();
        let Self {
            stick_t,
            stick_root,
            own_at_samples,
            own_rows,
            shape_nodes,
            shape_weights,
            ..
        } = self;
        // The stick points lie inside the contact, where `cauchy_row` is the T recurrence.
        let taus: Vec<f64> = stick_points.iter().map(|&xs| (xs - c) / a).collect();
        debug_assert!(taus.iter().all(|t| t.abs() < 1.0));
        stick_t.refill(m + 2, &taus, |t| [t, 1.0, 1.0]);
        stick_root.clear();
        stick_root.extend(taus.iter().map(|t| 1.0 / (1.0 - t * t).sqrt()));
        let stick_shape: Vec<f64> = stick_points.iter().map(|&x| state.slip_shape(x)).collect();
        let (mid, half) = (stick.mid(), stick.half());
        // Rows only where the density is not zero: in the bench's forward step at 0.35 ηP
        // (M = 128) 122 of the 256 sample points lie outside the stick zone (counted).
        own_rows.clear();
        let mut inside_taus = Vec::with_capacity(sample_points.len());
        for (k, &xq) in sample_points.iter().enumerate() {
            let tau = (xq - mid) / half;
            if tau.abs() < 1.0 {
                own_rows.push(k);
                inside_taus.push(tau);
            }
        }
        own_at_samples.refill(m, &inside_taus, BoundedSeries::density_start);
        let mut node_points = Vec::new();
        if k.shape.is_none() {
            let table = state.shape_quadrature(stick);
            node_points = table.iter().map(|&(t, _, _)| t).collect();
            let node_taus: Vec<f64> = table.iter().map(|&(t, _, _)| (t - c) / a).collect();
            shape_nodes.refill(m, &node_taus, BoundedSeries::density_start);
            shape_weights.reset(rows, table.len());
            for (i, (&xs, &sx)) in stick_points.iter().zip(&stick_shape).enumerate() {
                for (wij, &(t, w, st)) in shape_weights.row_mut(i).iter_mut().zip(&table) {
                    if (t - xs).abs() > 1e-14 * a {
                        *wij = w * (st - sx) / (t - xs) / std::f64::consts::PI;
                    }
                }
            }
        } else {
            shape_nodes.clear();
            shape_weights.reset(0, 0);
        }
        self.stick_shape = stick_shape;
        self.coefficients = k;
        self.node_points = node_points;
    }

    /// The stick rows' terms of the pressure (coefficients `beta_p`, β_n for n = 1 … M) and
    /// of the charge (`gamma`, γ_n for n = 0 … M − 1) into `srhs`: `local/y11 · p + η s T·β`
    /// (the `−η s H'p` term, with equal slip signs) `+ w13/y11 · w`; with mixed slip signs the
    /// `η s` term is left out and `H'p` at the stick points goes into `cauchy` instead. With
    /// `√(1−τ²) U_{n−1}(τ) = (T_{n−1}(τ) − T_{n+1}(τ))/(2√(1−τ²))` both densities are T
    /// series over `√(1−τ²)`, so one matrix of `T_n(τ_i)` serves every term, read once for
    /// the two coefficient vectors: `a` (the densities' coefficients, L (β_{k+1} − β_{k−1})/2
    /// + W γ_k) and `b` (η s β_k, or −β_k for `H'p`).
    pub(super) fn stick_terms(
        &self,
        beta_p: &[f64],
        gamma: &[f64],
        buffers: &mut StickSums,
        srhs: &mut [f64],
        cauchy: &mut [f64],
    ) {
        let Coefficients {
            local_over_y11,
            shape,
            charge,
        } = self.coefficients;
        let m = beta_p.len();
        let beta = |k: usize| {
            if (1..=m).contains(&k) {
                beta_p[k - 1]
            } else {
                0.0
            }
        };
        let [a, b] = &mut buffers.coefficients;
        let factor = shape.unwrap_or(-1.0);
        for (k, (ak, bk)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
            let below = k.checked_sub(1).map_or(0.0, beta);
            *ak = 0.5 * local_over_y11 * (beta(k + 1) - below);
            *bk = factor * beta(k);
        }
        if let Some(w) = charge {
            for (ak, g) in a.iter_mut().zip(gamma) {
                *ak += w * g;
            }
        }
        let [ya, yb] = &mut buffers.sums;
        self.stick_t.apply_pair([a, b], [ya, yb]);
        let densities = srhs.iter_mut().zip(ya.iter().zip(&self.stick_root));
        if shape.is_some() {
            for ((r, (ya, root)), yb) in densities.zip(yb.iter()) {
                *r = root * ya + yb;
            }
        } else {
            for (r, (ya, root)) in densities {
                *r = root * ya;
            }
            cauchy.copy_from_slice(yb);
        }
    }

    /// q̃'s own part with coefficients `beta` at every sample point into `out`: the products
    /// of the rows inside the stick zone (into `inside`, one entry per row), zero elsewhere.
    pub(super) fn own_at_samples_into(&self, beta: &[f64], inside: &mut [f64], out: &mut [f64]) {
        self.own_at_samples.apply(beta, inside);
        out.fill(0.0);
        for (&k, &v) in self.own_rows.iter().zip(inside.iter()) {
            out[k] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stick rows from the one matrix of `T_n` values equal the density and Cauchy rows
    /// they replace (`√(1−τ²) U_{n−1}`, `T_n/√(1−τ²)`, `−T_n`), summed directly, for series
    /// of the solver's length with slowly decaying coefficients, at stick points across the
    /// contact and 1e−4 from its ends (where `1/√(1−τ²)` is 71). Measured: 9.3e−16 of the
    /// sum of the terms' sizes at worst; bound 1e−14.
    #[test]
    fn stick_terms_equal_the_density_and_cauchy_rows() {
        use crate::quadrature::UnboundedSeries;
        let m = 128;
        let taus = [-0.9999, -0.998, -0.6, -0.01, 0.0, 0.35, 0.9, 0.9999];
        let beta: Vec<f64> = (1..=m).map(|n| (0.9 * n as f64).sin() / n as f64).collect();
        let gamma: Vec<f64> = (0..m)
            .map(|n| (1.3 * n as f64 + 0.4).cos() / (n + 1) as f64)
            .collect();
        let (local, eta_s, w) = (0.37, -0.25, 1.9);
        let mut worst: f64 = 0.0;
        for shape in [Some(eta_s), None] {
            let mut maps = InnerMaps::default();
            maps.stick_t.refill(m + 2, &taus, |t| [t, 1.0, 1.0]);
            maps.stick_root = taus.iter().map(|t| 1.0 / (1.0 - t * t).sqrt()).collect();
            maps.coefficients = Coefficients {
                local_over_y11: local,
                shape,
                charge: Some(w),
            };
            let mut buffers = StickSums {
                coefficients: [vec![0.0; m + 2], vec![0.0; m + 2]],
                sums: [vec![0.0; taus.len()], vec![0.0; taus.len()]],
            };
            let (mut srhs, mut cauchy) = (vec![0.0; taus.len()], vec![0.0; taus.len()]);
            maps.stick_terms(&beta, &gamma, &mut buffers, &mut srhs, &mut cauchy);
            let mut row = vec![0.0; m];
            for (i, &t) in taus.iter().enumerate() {
                let mut terms = Vec::new();
                BoundedSeries::density_row(t, &mut row);
                terms.extend(row.iter().zip(&beta).map(|(r, b)| local * r * b));
                UnboundedSeries::density_row(t, &mut row);
                terms.extend(row.iter().zip(&gamma).map(|(r, g)| w * r * g));
                BoundedSeries::cauchy_row(t, &mut row);
                let h: Vec<f64> = row.iter().zip(&beta).map(|(r, b)| r * b).collect();
                let size = |v: &[f64]| v.iter().map(|x| x.abs()).sum::<f64>();
                if let Some(eta_s) = shape {
                    terms.extend(h.iter().map(|v| -eta_s * v));
                } else {
                    let direct: f64 = h.iter().sum();
                    worst = worst.max((cauchy[i] - direct).abs() / size(&h));
                }
                let direct: f64 = terms.iter().sum();
                worst = worst.max((srhs[i] - direct).abs() / size(&terms));
            }
        }
        assert!(worst < 1e-14, "{worst:.2e}");
    }
}
