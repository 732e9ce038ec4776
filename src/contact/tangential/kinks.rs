//! The closed-form kink terms of an evaluation (tangential module docs, "Kinks at the stick
//! ends"): the half-ellipses `A √(distance)` of p and w at the new and the remembered stick ends,
//! their amplitudes from q̃'s root coefficients k by the local relations
//! `A = ±(κ/Y*) k/(1 + α²)` and `B = ±(w13/y33)(k ∓ (κ/Y*) η² s² A)`, and the end probes that
//! read k off q̃ by Richardson's extrapolation.

use crate::contact::{
    ContactState, Kink, Kinks, StickZone, half_ellipse, half_ellipse_cauchy, kink_domain,
    smootherstep,
};
use crate::quadrature::{BoundedSeries, RowMatrix, dot};

use super::residual::Geometry;

/// p's square-root coefficient on the slip side of a kink point, `side (κ/Y*) k/(1 + α²)`,
/// `α = κηS/Y*`, for q̃'s root k there and the slip sign S (tangential module docs).
pub(super) fn pressure_root(side: f64, kappa: f64, eta: f64, sign: f64, k: f64) -> f64 {
    let alpha = kappa * eta * sign;
    side * kappa * k / (1.0 + alpha * alpha)
}

/// How far a kink term on a stretch of `length` is kept (1) or switched off (0): a stretch
/// narrower than the grid spacing at the contact ends, `a (π/M)²`, holds no collocation point;
/// smootherstep between one and two spacings.
pub(super) fn resolved(length: f64, a: f64, m: usize) -> f64 {
    let spacing = a * (std::f64::consts::PI / m as f64).powi(2);
    smootherstep(length / spacing - 1.0)
}

/// Where the kink functions are needed in an evaluation.
pub(super) struct KinkPoints<'a> {
    pub(super) pressure: &'a [f64],
    pub(super) charge: &'a [f64],
    pub(super) stick: &'a [f64],
    pub(super) samples: &'a [f64],
    /// The shape quadrature's nodes (mixed slip signs only: `H'(pS)` needs p there).
    pub(super) nodes: &'a [f64],
}

/// The kink terms of one evaluation (tangential module docs, "Kinks at the stick ends"): their
/// points, the local relations that give their amplitudes from q̃'s root coefficients, and the
/// kink functions (half-ellipses over a) and their Cauchy transforms at the points where the
/// inner iteration needs them, as matrices over the terms.
#[derive(Default)]
pub(super) struct KinkMaps {
    /// `(point, side)` of each term; the first two are the new stick ends.
    points: Vec<(f64, f64)>,
    /// The roots k of the remembered terms (from the third on).
    fixed_roots: Vec<f64>,
    /// Per term: `side (κ/Y*)/(1 + α²)`, `α = κηS/Y*` with S the slip sign beside the point
    /// when its root formed ([`pressure_root`]).
    pressure_factor: Vec<f64>,
    /// Per term: `(κ/Y*) η² S²`, the factor of p's stick-side root in w's relation.
    stick_side: Vec<f64>,
    /// Per term: the factor from a root coefficient to the amplitude of the half-ellipse
    /// over a, `a/√L` (L the term's stretch), switched off for stretches the grid does not
    /// resolve.
    to_amplitude: Vec<f64>,
    /// w13/y33.
    charge: f64,
    pub(super) cauchy_at_pressure: RowMatrix,
    pub(super) cauchy_at_charge: RowMatrix,
    pub(super) cauchy_at_stick: RowMatrix,
    pub(super) at_stick: RowMatrix,
    pub(super) at_samples: RowMatrix,
    pub(super) at_nodes: RowMatrix,
}

impl KinkMaps {
    /// The maps for the terms `points` (`(point, side, root, sign)`, the root used only for the
    /// remembered ones) on `state`'s geometry; `coefficients` are κ/Y*, w13/y33 and η.
    ///
    /// A term on a stretch the grid does not resolve is switched off ([`resolved`]):
    /// unresolved, it only disturbed the search for the first state after a reversal, whose
    /// edge slip zones start that thin (insulating Figure-3 history: a left slip zone of
    /// 8e−5 a).
    pub(super) fn new(
        state: &ContactState,
        points: &[(f64, f64, f64, f64)],
        at: KinkPoints<'_>,
        m: usize,
        coefficients: [f64; 3],
    ) -> Self {
        let [kappa, charge, eta] = coefficients;
        let (c, a) = (state.centre, state.half_width);
        let domains: Vec<(f64, f64)> = points
            .iter()
            .map(|&(x0, side, _, _)| kink_domain(x0, side, c, a))
            .collect();
        let pressure_factor = points
            .iter()
            .map(|&(_, side, _, sign)| pressure_root(side, kappa, eta, sign, 1.0))
            .collect();
        let stick_side = points
            .iter()
            .map(|&(_, _, _, sign)| kappa * eta * eta * sign * sign)
            .collect();
        let to_amplitude = domains
            .iter()
            .map(|&(u, v)| {
                let blend = resolved(v - u, a, m);
                if blend > 0.0 {
                    blend * a / (v - u).sqrt()
                } else {
                    0.0
                }
            })
            .collect();
        let table = |xs: &[f64], f: &dyn Fn(f64, f64, f64) -> f64| {
            let mut out = RowMatrix::zeros(xs.len(), points.len());
            for (i, &x) in xs.iter().enumerate() {
                for (o, &(u, v)) in out.row_mut(i).iter_mut().zip(&domains) {
                    *o = f(x, u, v) / a;
                }
            }
            out
        };
        Self {
            points: points.iter().map(|&(x0, side, _, _)| (x0, side)).collect(),
            fixed_roots: points.iter().skip(2).map(|&(_, _, k, _)| k).collect(),
            pressure_factor,
            stick_side,
            to_amplitude,
            charge,
            cauchy_at_pressure: table(at.pressure, &half_ellipse_cauchy),
            cauchy_at_charge: table(at.charge, &half_ellipse_cauchy),
            cauchy_at_stick: table(at.stick, &half_ellipse_cauchy),
            at_stick: table(at.stick, &half_ellipse),
            at_samples: table(at.samples, &half_ellipse),
            at_nodes: table(at.nodes, &half_ellipse),
        }
    }

    /// The root coefficients of all terms for the new stick ends' `ends`, into `out`.
    pub(super) fn roots_into(&self, ends: [f64; 2], out: &mut Vec<f64>) {
        out.clear();
        if !self.points.is_empty() {
            out.extend(ends.iter().chain(&self.fixed_roots));
        }
    }

    /// The amplitudes of p's kinks, into `out`: p's root on the slip side of each point is
    /// `A = side (κ/Y*) k/(1 + α²)`.
    pub(super) fn pressure_amplitudes_into(&self, roots: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            roots
                .iter()
                .zip(&self.pressure_factor)
                .zip(&self.to_amplitude)
                .map(|((k, f), t)| f * k * t),
        );
    }

    /// The amplitudes of w's kinks, into `out`: `B = side (w13/y33)(k − side (κ/Y*) η² S² A)`
    /// with p's root A (q = ηSp + q̃ carries p's stick-side root −side α A next to q̃'s).
    pub(super) fn charge_amplitudes_into(&self, roots: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(roots.iter().enumerate().map(|(j, k)| {
            let side = self.points[j].1;
            let root_p = self.pressure_factor[j] * k;
            side * self.charge * (k - side * self.stick_side[j] * root_p) * self.to_amplitude[j]
        }));
    }

    /// The kink terms with amplitudes `amp`, into `out` (its allocation kept).
    pub(super) fn kinks_into(&self, amp: &[f64], out: &mut Kinks) {
        out.0.clear();
        out.0.extend(
            self.points
                .iter()
                .zip(amp)
                .filter(|(_, a)| a.abs() > 0.0)
                .map(|(&(at, side), &amplitude)| Kink {
                    at,
                    side,
                    amplitude,
                }),
        );
    }
}

/// Where q̃'s square-root coefficients at the stick ends are read: at `END_PROBE` and twice
/// that of the zone's half-width h inside each end.
const END_PROBE: f64 = 0.01;

/// The square-root coefficients of q̃ (own series and inherited correction) at the stick
/// ends, `q̃ ≈ k_lo √(x − lo)` and `q̃ ≈ k_hi √(hi − x)`, by Richardson's extrapolation of
/// `q̃/√r` from the distances `r = d` and `2d` (`d = END_PROBE h`): `k ≈ 2 q̃(d)/√d − q̃(2d)/√(2d)`,
/// exact for `k√r (1 + c r)`. Where a remembered stick end inside the zone (whose root q̃
/// carries, [`RememberedRoot`](crate::contact::RememberedRoot)) lies closer to an end than
/// `4d`, d there is a quarter of its distance, so that both probes read the stretch between
/// the two roots (unless that puts them closer to the end than the series' first node: then
/// d stays): in a steady
/// cycle the extreme states' stick ends lie about 0.01a apart, and probes straddling the
/// remembered one misread k, whose kinks the series then had to carry (`docs/performance.md`,
/// "Convergence in M"). Reading k from the series' end values `ψ(±1)`
/// instead (the exact limit of a polynomial) is ill-conditioned: the sum
/// `Σ (±1)ⁿ (n + 1) β_n` weighs the coefficients' tail, and at M = 256 it moved by 1e−3 of
/// itself between evaluations 1e−6 a apart, which stalled steps at residuals of 1e−7. The
/// coefficients are carried scaled by `scale = √d` of their end (Pa,
/// `k √d = 2 q̃(d) − q̃(2d)/√2`: the root's part of q̃ at the probes), so that the inner
/// iteration converges them as far as the traction; scaled by √h, their round-off, amplified
/// by `√(h/d)`, kept the inner iteration of a recalled step at M = 512 at its tolerance for
/// ten passes instead of four once the probes moved nearer.
pub(super) struct EndProbes {
    /// Density rows of the own series at `lo + d_lo`, `lo + 2d_lo`, `hi − d_hi`, `hi − 2d_hi`.
    rows: [Vec<f64>; 4],
    /// The closed-form part of q̃ (inherited chain and extras) at the same points.
    closed: [f64; 4],
    /// The same points (m).
    points: [f64; 4],
    /// √d at each end: a root's effect on q̃ at the probes, so that the inner iteration
    /// converges the roots as far as it does the traction.
    pub(super) scale: [f64; 2],
}

impl EndProbes {
    pub(super) fn new(g: &Geometry, m: usize, closed: &StickZone, interior: &[f64]) -> Self {
        let half = 0.5 * (g.hi - g.lo);
        let near = |end: f64| {
            interior
                .iter()
                .map(|x| (x - end).abs())
                .fold(f64::INFINITY, f64::min)
        };
        // A probe closer to the end than the series' first node, `h (1 − cos(π/(M + 1)))`,
        // reads what the series cannot resolve; there the standard probes are kept.
        let standard = END_PROBE * half;
        let floor = half * (1.0 - (std::f64::consts::PI / (m + 1) as f64).cos());
        let d = [g.lo, g.hi].map(|end| {
            let clear = 0.25 * near(end);
            if clear < standard && clear >= floor {
                clear
            } else {
                standard
            }
        });
        let points = [
            g.lo + d[0],
            g.lo + 2.0 * d[0],
            g.hi - d[1],
            g.hi - 2.0 * d[1],
        ];
        let rows = points.map(|x| {
            let mut row = vec![0.0; m];
            BoundedSeries::density_row((x - 0.5 * (g.lo + g.hi)) / half, &mut row);
            row
        });
        Self {
            rows,
            closed: points.map(|x| closed.correction_at(x)),
            points,
            scale: d.map(f64::sqrt),
        }
    }

    /// `[k_lo, k_hi]` times `scale` from q̃ at the four points.
    fn extrapolate(&self, v: [f64; 4]) -> [f64; 2] {
        // k √d = 2 q̃(d) − q̃(2d)/√2.
        let root = |near: f64, far: f64| 2.0 * near - far * std::f64::consts::FRAC_1_SQRT_2;
        [root(v[0], v[1]), root(v[2], v[3])]
    }

    /// The scaled coefficients of the q̃ whose own series is `beta`.
    pub(super) fn scaled_roots_of(&self, beta: &[f64]) -> [f64; 2] {
        let mut v = self.closed;
        for (vi, row) in v.iter_mut().zip(&self.rows) {
            *vi += dot(row, beta);
        }
        self.extrapolate(v)
    }

    /// The scaled coefficients of a q̃ given as a function.
    pub(super) fn scaled_roots(&self, f: impl Fn(f64) -> f64) -> [f64; 2] {
        self.extrapolate(self.points.map(f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The end probes keep clear of a remembered stick end near a new one: a quarter and a half
    /// of its distance from the end when it lies within `4 END_PROBE h`, unless that is closer
    /// to the end than the series' first node; elsewhere `END_PROBE h` and twice that.
    #[test]
    fn end_probes_keep_clear_of_a_remembered_end() {
        let g = Geometry {
            lo: -1.0,
            hi: 1.0,
            a: 1.2,
            c: 0.0,
        };
        let m = 64;
        let zone = StickZone::new(g.lo, g.hi, BoundedSeries::default(), 0.0);
        let first_node = 1.0 - (std::f64::consts::PI / 65.0).cos();
        // h = 1: a remembered end 0.015 inside the right end, one 0.5 inside the left.
        let probes = EndProbes::new(&g, m, &zone, &[-0.5, 1.0 - 0.015]);
        let close = |x: f64, y: f64| (x - y).abs() < 1e-15;
        let d = probes.scale.map(|s| s * s);
        assert!(close(d[0], END_PROBE) && close(d[1], 0.015 / 4.0));
        assert!(close(probes.points[2], 1.0 - 0.015 / 4.0));
        assert!(close(probes.points[3], 1.0 - 0.015 / 2.0));
        // A quarter of the distance below the first node: the standard probes.
        let probes = EndProbes::new(&g, m, &zone, &[1.0 - 3.0 * first_node]);
        assert!(probes.scale.iter().all(|&s| close(s * s, END_PROBE)));
        // Nothing remembered nearby.
        let probes = EndProbes::new(&g, m, &zone, &[]);
        assert!(probes.scale.iter().all(|&s| close(s * s, END_PROBE)));
        // The extrapolation is exact for k √r (1 + c r) at either spacing.
        let q = |r: f64| 3.0 * r.sqrt() * (1.0 + 0.7 * r);
        let probes = EndProbes::new(&g, m, &zone, &[1.0 - 0.015]);
        let [left, right] = probes.scaled_roots(|x| q((x - g.lo).min(g.hi - x)));
        let (kl, kr) = (left / probes.scale[0], right / probes.scale[1]);
        assert!(
            (kl - 3.0).abs() < 1e-12 && (kr - 3.0).abs() < 1e-12,
            "{kl} {kr}"
        );
    }
}
