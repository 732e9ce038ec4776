//! The Chebyshev series of the two representations (module docs): [`BoundedSeries`],
//! `f = √(1 − θ²) Σ β_n U_{n−1}`, and [`UnboundedSeries`], `f = Σ γ_n T_n/√(1 − θ²)`, with
//! their densities, integrals, evaluation rows and closed-form Cauchy transforms inside and
//! outside [−1, 1]; and the Clenshaw sums of T and U series ([`chebyshev_t_sum`],
//! [`chebyshev_u_sum`]).

use std::f64::consts::PI;

use super::{BoundedGrid, UnboundedGrid};

/// A density bounded at both ends of [−1, 1], `f = √(1−θ²) Σ β_n U_{n−1}(θ)`.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BoundedSeries {
    /// β_1 … β_M.
    pub beta: Vec<f64>,
}

/// A density with inverse-square-root ends, `f = Σ γ_n T_n(θ)/√(1−θ²)`.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UnboundedSeries {
    /// γ_0 … γ_{M−1}.
    pub gamma: Vec<f64>,
}

/// One evaluation row, `row[n] = scale · v_n(τ)` with `v_{n+1} = 2τ v_n − v_{n−1}` from
/// `(v_{−1}, v_0, scale)`: the single-point form of [`ColumnMatrix::refill`] (the
/// same operations in the same order); a zero scale gives a zero row.
///
/// [`ColumnMatrix::refill`]: super::ColumnMatrix::refill
fn recurrence_row(tau: f64, [mut prev, mut cur, scale]: [f64; 3], row: &mut [f64]) {
    if scale.abs() <= 0.0 {
        row.fill(0.0);
        return;
    }
    let two_tau = 2.0 * tau;
    for r in row.iter_mut() {
        *r = scale * cur;
        (prev, cur) = (cur, two_tau * cur - prev);
    }
}

/// Clenshaw's recurrence in steps of two: the even- and odd-indexed terms of a Chebyshev sum
/// (T or U) each obey `f_{j+1} = α f_j − f_{j−1}` with `α = 4x² − 2 = 2T_2(x)`, so the two
/// sums run as independent chains `b_j = (c − b_{j+2}) + α b_{j+1}`, which the processor
/// overlaps (the one-step recurrence is a chain of dependent multiply–adds, as long as the
/// series). The subtraction does not wait for `b_{j+1}`, so a link of the chain is one
/// multiplication and one addition (written `c + α b_{j+1} − b_{j+2}`, it would be a
/// multiplication and two additions on the chain). Returns `(b_0, b_1)` of the even chain
/// and of the odd chain at each of the `L`
/// points; the points' chains run interleaved (four points give eight independent chains),
/// each with the same operations in the same order, so a point's sums do not depend on the
/// others. The chains are compiled for the processor's widest SIMD lanes, chosen at run time
/// by `pulp` (AVX2 puts four points' chains in one register, where SSE2 needs two): the same
/// multiplications and additions, no fused ones, so the sums are [`clenshaw_pair`]'s to the bit
/// on every processor. These sums are a sizeable part of a tangential step, which is why they
/// get the wider lanes.
fn clenshaw_pairs<const L: usize>(c: &[f64], x: [f64; L]) -> [([f64; 2], [f64; 2]); L] {
    struct Pairs<'a, const L: usize>(&'a [f64], [f64; L]);
    impl<const L: usize> pulp::WithSimd for Pairs<'_, L> {
        type Output = [([f64; 2], [f64; 2]); L];
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) -> Self::Output {
            clenshaw_pairs_scalar(self.0, self.1)
        }
    }
    pulp::Arch::new().dispatch(Pairs(c, x))
}

/// [`clenshaw_pairs`]' sums, inlined into the lanes' instruction set.
#[inline(always)]
fn clenshaw_pairs_scalar<const L: usize>(c: &[f64], x: [f64; L]) -> [([f64; 2], [f64; 2]); L] {
    let alpha = x.map(|x| 4.0 * x * x - 2.0);
    let pairs = c.chunks_exact(2);
    // With an odd count the top coefficient belongs to the even chain, whose b starts there.
    let top = pairs.remainder().first().copied().unwrap_or(0.0);
    let (mut e1, mut e2) = ([top; L], [0.0; L]);
    let (mut o1, mut o2) = ([0.0; L], [0.0; L]);
    for pair in pairs.rev() {
        for l in 0..L {
            (e1[l], e2[l]) = ((pair[0] - e2[l]) + alpha[l] * e1[l], e1[l]);
            (o1[l], o2[l]) = ((pair[1] - o2[l]) + alpha[l] * o1[l], o1[l]);
        }
    }
    std::array::from_fn(|l| ([e1[l], e2[l]], [o1[l], o2[l]]))
}

/// [`clenshaw_pairs`] at one point, written out: the one-point sums are the hot path of the
/// chain's values one point at a time, where the one-lane instance of the generic form is
/// slower; the operations are the same, so the sums are bit-identical.
fn clenshaw_pair(c: &[f64], x: f64) -> ([f64; 2], [f64; 2]) {
    let alpha = 4.0 * x * x - 2.0;
    let pairs = c.chunks_exact(2);
    let (mut e1, mut e2) = (pairs.remainder().first().copied().unwrap_or(0.0), 0.0);
    let (mut o1, mut o2) = (0.0, 0.0);
    for pair in pairs.rev() {
        (e1, e2) = ((pair[0] - e2) + alpha * e1, e1);
        (o1, o2) = ((pair[1] - o2) + alpha * o1, o1);
    }
    ([e1, e2], [o1, o2])
}

/// Σ c_k T_k(x) by Clenshaw's recurrence in steps of two (`clenshaw_pairs`; c_0 included).
/// With `f_0, f_1` the first two members of a chain, the sum is `f_0 b_0 + (f_1 − α f_0) b_1`:
/// for T_0, T_2: `b_0 − T_2(x) b_1`; for T_1, T_3: `x (b_0 − b_1)`.
pub fn chebyshev_t_sum(c: &[f64], x: f64) -> f64 {
    let ([e0, e1], [o0, o1]) = clenshaw_pair(c, x);
    e0 - (2.0 * x * x - 1.0) * e1 + x * (o0 - o1)
}

/// [`chebyshev_t_sum`] at each of `L` points (interleaved, bit-identical).
pub fn chebyshev_t_sums<const L: usize>(c: &[f64], x: [f64; L]) -> [f64; L] {
    let chains = clenshaw_pairs(c, x);
    std::array::from_fn(|l| {
        let ([e0, e1], [o0, o1]) = chains[l];
        e0 - (2.0 * x[l] * x[l] - 1.0) * e1 + x[l] * (o0 - o1)
    })
}

/// Σ c_k U_k(x) by Clenshaw's recurrence in steps of two (`clenshaw_pairs`): for U_0, U_2
/// the sum is `b_0 + b_1`, for U_1, U_3 it is `2x b_0` (see [`chebyshev_t_sum`]).
pub fn chebyshev_u_sum(c: &[f64], x: f64) -> f64 {
    let ([e0, e1], [o0, _]) = clenshaw_pair(c, x);
    e0 + e1 + 2.0 * x * o0
}

/// [`chebyshev_u_sum`] at each of `L` points (interleaved, bit-identical).
pub fn chebyshev_u_sums<const L: usize>(c: &[f64], x: [f64; L]) -> [f64; L] {
    let chains = clenshaw_pairs(c, x);
    std::array::from_fn(|l| {
        let ([e0, e1], [o0, _]) = chains[l];
        e0 + e1 + 2.0 * x[l] * o0
    })
}

/// Σ c_n z^n, n from `start`, by Horner.
fn power_sum(c: &[f64], z: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &cn| acc * z + cn)
}

/// [`power_sum`] at each of `L` points, their recurrences interleaved (bit-identical).
fn power_sums<const L: usize>(c: &[f64], z: [f64; L]) -> [f64; L] {
    let mut acc = [0.0; L];
    for &cn in c.iter().rev() {
        for l in 0..L {
            acc[l] = acc[l] * z[l] + cn;
        }
    }
    acc
}

/// `z = τ − sgn(τ)√(τ²−1)` for |τ| ≥ 1, the exterior Joukowski variable (|z| ≤ 1).
fn exterior(tau: f64) -> f64 {
    tau - tau.signum() * (tau * tau - 1.0).max(0.0).sqrt()
}

impl BoundedSeries {
    /// From nodal ψ values on a grid.
    pub fn from_nodes(grid: &BoundedGrid, psi: &[f64]) -> Self {
        let mut beta = vec![0.0; grid.len()];
        grid.coefficients(psi, &mut beta);
        Self { beta }
    }

    /// ψ(τ) for |τ| ≤ 1 (polynomial; may be evaluated at the ends).
    pub fn psi(&self, tau: f64) -> f64 {
        chebyshev_u_sum(&self.beta, tau)
    }

    /// The density `√(1−τ²) ψ(τ)`, zero outside [−1, 1].
    pub fn density(&self, tau: f64) -> f64 {
        self.densities([tau])[0]
    }

    /// [`Self::density`] at each of `L` points (the sums interleaved, [`chebyshev_u_sums`]).
    pub fn densities<const L: usize>(&self, tau: [f64; L]) -> [f64; L] {
        let psi = chebyshev_u_sums(&self.beta, tau);
        std::array::from_fn(|l| {
            if tau[l].abs() >= 1.0 {
                0.0
            } else {
                (1.0 - tau[l] * tau[l]).sqrt() * psi[l]
            }
        })
    }

    /// `∫_{−1}^{1} density = π β_1/2`.
    pub fn integral(&self) -> f64 {
        PI * self.beta.first().copied().unwrap_or(0.0) / 2.0
    }

    /// The start of [`Self::density_row`] for [`ColumnMatrix::refill`]:
    /// `(U_{−1}, U_0, √(1−τ²))`, zero scale outside.
    ///
    /// [`ColumnMatrix::refill`]: super::ColumnMatrix::refill
    pub fn density_start(tau: f64) -> [f64; 3] {
        [0.0, 1.0, (1.0 - tau * tau).max(0.0).sqrt()]
    }

    /// The start of [`Self::cauchy_row`] inside (|τ| < 1) for
    /// [`ColumnMatrix::refill`]: `(T_0, T_1, −1)`.
    ///
    /// [`ColumnMatrix::refill`]: super::ColumnMatrix::refill
    pub fn cauchy_start_inside(tau: f64) -> [f64; 3] {
        [1.0, tau, -1.0]
    }

    /// The row r with `density(τ) = r · β`: `√(1−τ²) U_{n−1}(τ)`, n = 1..M (zero outside).
    pub fn density_row(tau: f64, row: &mut [f64]) {
        recurrence_row(tau, Self::density_start(tau), row);
    }

    /// The row r with `cauchy(τ) = r · β`: `−T_n(τ)` inside, `−zⁿ` outside, n = 1..M.
    pub fn cauchy_row(tau: f64, row: &mut [f64]) {
        if tau.abs() < 1.0 {
            recurrence_row(tau, Self::cauchy_start_inside(tau), row);
        } else {
            let z = exterior(tau);
            let mut power = z;
            for r in row.iter_mut() {
                *r = -power;
                power *= z;
            }
        }
    }

    /// `(1/π)⨍ f(t)/(t − τ) dt` at any τ (inside: −Σ β_n T_n; outside: −Σ β_n zⁿ).
    pub fn cauchy(&self, tau: f64) -> f64 {
        self.cauchys([tau])[0]
    }

    /// [`Self::cauchy`] at each of `L` points: inside, −Σ_{n≥1} β_n T_n(τ) from the two-step
    /// Clenshaw chains of ψ (`clenshaw_pairs`; not run when every point is outside), each
    /// point's sums bit-identical to one point at a time; outside, `−z Σ β_n z^{n−1}` with the
    /// exterior variable z. ([`Self::densities_and_cauchys`] gives the density from the same
    /// chains.)
    pub fn cauchys<const L: usize>(&self, tau: [f64; L]) -> [f64; L] {
        self.densities_and_cauchys(tau).1
    }

    /// [`Self::densities`] and [`Self::cauchys`] at each of `L` points, from one run of the
    /// chains. With `β_n` multiplying `U_{n−1}` in ψ and `T_n` in the transform, and
    /// `T_{k+1} = τ U_k − U_{k−1}`, the transform inside is `−(τ ψ − Σ β_{k+1} U_{k−1})`; in
    /// the chains' terms (even chain `(e_0, e_1)`, odd chain `(o_0, o_1)`, whose sums are
    /// `f_0 b_0 + (f_1 − α f_0) b_1` for a chain's first members `f_0, f_1`) ψ is
    /// `e_0 + e_1 + 2τ o_0` and the transform `−(τ (e_0 − e_1) + T_2(τ) o_0 − o_1)` (the
    /// one-step recurrence of the transform, a chain of dependent operations as long as the
    /// series, took 4.7 % of the forward step at M = 128).
    pub fn densities_and_cauchys<const L: usize>(&self, tau: [f64; L]) -> ([f64; L], [f64; L]) {
        let inside = tau
            .iter()
            .any(|t| t.abs() < 1.0)
            .then(|| clenshaw_pairs(&self.beta, tau));
        let outside = tau.iter().any(|t| t.abs() >= 1.0);
        let z = tau.map(|t| if t.abs() < 1.0 { 0.0 } else { exterior(t) });
        let powers = if outside {
            power_sums(&self.beta, z)
        } else {
            [0.0; L]
        };
        let mut densities = [0.0; L];
        let cauchys = std::array::from_fn(|l| {
            let x = tau[l];
            match inside {
                Some(chains) if x.abs() < 1.0 => {
                    let ([e0, e1], [o0, o1]) = chains[l];
                    densities[l] = (1.0 - x * x).sqrt() * (e0 + e1 + 2.0 * x * o0);
                    -(x * (e0 - e1) + (2.0 * x * x - 1.0) * o0 - o1)
                }
                _ => -z[l] * powers[l],
            }
        });
        (densities, cauchys)
    }
}

impl UnboundedSeries {
    /// From nodal ϑ values on a grid.
    pub fn from_nodes(grid: &UnboundedGrid, theta: &[f64]) -> Self {
        let mut gamma = vec![0.0; grid.len()];
        grid.coefficients(theta, &mut gamma);
        Self { gamma }
    }

    /// ϑ(τ) (polynomial).
    pub fn theta(&self, tau: f64) -> f64 {
        chebyshev_t_sum(&self.gamma, tau)
    }

    /// The density `ϑ(τ)/√(1−τ²)`, zero outside (−1, 1), infinite at the ends.
    pub fn density(&self, tau: f64) -> f64 {
        self.densities([tau])[0]
    }

    /// [`Self::density`] at each of `L` points (the sums interleaved, [`chebyshev_t_sums`]).
    pub fn densities<const L: usize>(&self, tau: [f64; L]) -> [f64; L] {
        let theta = chebyshev_t_sums(&self.gamma, tau);
        std::array::from_fn(|l| {
            if tau[l].abs() >= 1.0 {
                0.0
            } else {
                theta[l] / (1.0 - tau[l] * tau[l]).sqrt()
            }
        })
    }

    /// The start of [`Self::density_row`] for [`ColumnMatrix::refill`]:
    /// `(T_{−1} = T_1, T_0, 1/√(1−τ²))`, zero scale outside.
    ///
    /// [`ColumnMatrix::refill`]: super::ColumnMatrix::refill
    pub fn density_start(tau: f64) -> [f64; 3] {
        if tau.abs() >= 1.0 {
            [0.0; 3]
        } else {
            [tau, 1.0, 1.0 / (1.0 - tau * tau).sqrt()]
        }
    }

    /// The row r with `density(τ) = r · γ`: `T_n(τ)/√(1−τ²)`, n = 0..M−1 (zero outside).
    pub fn density_row(tau: f64, row: &mut [f64]) {
        recurrence_row(tau, Self::density_start(tau), row);
    }

    /// `∫ density = π γ_0`.
    pub fn integral(&self) -> f64 {
        PI * self.gamma.first().copied().unwrap_or(0.0)
    }

    /// `(1/π)⨍ f(t)/(t − τ) dt` at any τ ≠ ±1 (inside: Σ γ_n U_{n−1}; outside: −sgn z^n/√(τ²−1)).
    pub fn cauchy(&self, tau: f64) -> f64 {
        if tau.abs() < 1.0 {
            if self.gamma.len() < 2 {
                return 0.0;
            }
            chebyshev_u_sum(&self.gamma[1..], tau)
        } else {
            let z = exterior(tau);
            -tau.signum() * power_sum(&self.gamma, z) / (tau * tau - 1.0).sqrt()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{t, u};
    use crate::quadrature::dot;

    use super::*;

    /// Long series (the lengths of the solver's, odd and even) against the trigonometric sums
    /// `Σ c_k cos kθ` and `Σ c_k sin((k+1)θ)/sin θ`, and against the one-step recurrence.
    #[test]
    fn two_step_clenshaw_matches_long_trigonometric_sums() {
        let one_step = |c: &[f64], x: f64, u: bool| {
            let (mut b1, mut b2) = (0.0, 0.0);
            for &ck in c.iter().skip(usize::from(!u)).rev() {
                (b1, b2) = (2.0 * x * b1 - b2 + ck, b1);
            }
            if u { b1 } else { c[0] + x * b1 - b2 }
        };
        for len in [1, 2, 3, 64, 127, 128, 513] {
            // Coefficients of both signs decaying like a smooth density's.
            let c: Vec<f64> = (0..len)
                .map(|k| (0.7 * k as f64 + 0.3).sin() / (1.0 + k as f64))
                .collect();
            let size: f64 = c.iter().map(|v| v.abs()).sum();
            for &x in &[-0.999_9, -0.93, -0.2, 0.0, 0.41, 0.77, 0.999] {
                let th = f64::acos(x);
                let t_exact: f64 = c
                    .iter()
                    .enumerate()
                    .map(|(k, ck)| ck * (k as f64 * th).cos())
                    .sum();
                let u_exact: f64 = c
                    .iter()
                    .enumerate()
                    .map(|(k, ck)| ck * ((k + 1) as f64 * th).sin() / th.sin())
                    .sum();
                let (t, u) = (chebyshev_t_sum(&c, x), chebyshev_u_sum(&c, x));
                // Round-off: measured below 7e−17 of Σ|c_k| per term for T (against both
                // references), and, for U, below 3.5e−17 of Σ|c_k| times len²/sin θ.
                let tol = 2e-16 * size * len as f64;
                // U_k grows like k + 1 near ±1, and the reference divides by sin θ.
                let tol_u = tol * len as f64 / th.sin();
                for (name, got, exact, recurrence, bound) in [
                    ("T", t, t_exact, one_step(&c, x, false), tol),
                    ("U", u, u_exact, one_step(&c, x, true), tol_u),
                ] {
                    assert!(
                        (got - exact).abs() < bound && (got - recurrence).abs() < bound,
                        "{name}, {len} terms, x = {x}: {got}, trigonometric {exact}, one-step \
                         {recurrence}"
                    );
                }
            }
        }
    }

    /// The many-point sums (in the processor's SIMD lanes) against the one-point sums, to the
    /// bit, at four points and at eight (the width of the contact's batches).
    #[test]
    fn many_point_sums_equal_the_one_point_sums() {
        fn check<const L: usize>(len: usize, tau: [f64; L]) {
            let beta: Vec<f64> = (0..len)
                .map(|k| (0.7 * k as f64 + 0.3).sin() / (1.0 + k as f64))
                .collect();
            let bounded = BoundedSeries { beta: beta.clone() };
            let unbounded = UnboundedSeries {
                gamma: beta.clone(),
            };
            type Case<'a, const L: usize> = (&'a str, [f64; L], &'a dyn Fn(f64) -> f64);
            let many: [Case<L>; 5] = [
                ("U sum", chebyshev_u_sums(&beta, tau), &|t| {
                    chebyshev_u_sum(&beta, t)
                }),
                ("T sum", chebyshev_t_sums(&beta, tau), &|t| {
                    chebyshev_t_sum(&beta, t)
                }),
                ("bounded", bounded.densities(tau), &|t| bounded.density(t)),
                ("H' bounded", bounded.cauchys(tau), &|t| bounded.cauchy(t)),
                ("unbounded", unbounded.densities(tau), &|t| {
                    unbounded.density(t)
                }),
            ];
            for (name, got, one) in many {
                for l in 0..L {
                    assert_eq!(
                        got[l].to_bits(),
                        one(tau[l]).to_bits(),
                        "{name}, {len} terms at {}",
                        tau[l]
                    );
                }
            }
        }
        // Inside, at the ends and outside [−1, 1] (densities zero there, the transform from
        // its exterior form).
        let (inside, ends) = ([-0.9999, -0.3, 0.0, 0.77], [1.0, -1.0, 1.5, 0.999_999]);
        for len in [0, 1, 2, 3, 64, 127] {
            check(len, inside);
            check(len, ends);
            check(
                len,
                std::array::from_fn::<f64, 8, _>(|l| [inside, ends][l % 2][l / 2]),
            );
        }
    }

    #[test]
    fn clenshaw_matches_trigonometric_definitions() {
        for &x in &[-0.93, -0.2, 0.0, 0.41, 0.999] {
            let th: f64 = f64::acos(x);
            for n in 0..12 {
                assert!((t(n, x) - (n as f64 * th).cos()).abs() < 1e-13);
                assert!((u(n, x) - ((n + 1) as f64 * th).sin() / th.sin()).abs() < 1e-11);
            }
        }
    }

    #[test]
    fn evaluation_rows_match_the_series() {
        // Rows dotted with the coefficients against the closed forms of the series, inside and
        // outside the interval (and the Clenshaw sums they replace).
        let bounded = BoundedSeries {
            beta: (1..=12).map(|n| 1.0 / (n * n) as f64).collect(),
        };
        let unbounded = UnboundedSeries {
            gamma: (0..12).map(|n| (-0.7f64).powi(n)).collect(),
        };
        let mut row = vec![0.0; 12];
        for &tau in &[-1.7, -0.999, -0.3, 0.0, 0.41, 0.95, 1.0, 2.5] {
            BoundedSeries::density_row(tau, &mut row);
            let density: f64 = if f64::abs(tau) < 1.0 {
                let s = (1.0 - tau * tau).sqrt();
                (1..=12).map(|n| s * u(n - 1, tau) / (n * n) as f64).sum()
            } else {
                0.0
            };
            assert!(
                (dot(&row, &bounded.beta) - density).abs() < 1e-14,
                "density at {tau}"
            );
            assert!((dot(&row, &bounded.beta) - bounded.density(tau)).abs() < 1e-14);
            BoundedSeries::cauchy_row(tau, &mut row);
            assert!(
                (dot(&row, &bounded.beta) - bounded.cauchy(tau)).abs() < 1e-14,
                "Cauchy at {tau}"
            );
            if f64::abs(tau) < 1.0 {
                let inside: f64 = (1..=12).map(|n| -t(n, tau) / (n * n) as f64).sum();
                assert!((dot(&row, &bounded.beta) - inside).abs() < 1e-14);
            }
            UnboundedSeries::density_row(tau, &mut row);
            let theta: f64 = (0..12).map(|n| (-0.7f64).powi(n as i32) * t(n, tau)).sum();
            let expected = if f64::abs(tau) < 1.0 {
                theta / (1.0 - tau * tau).sqrt()
            } else {
                0.0
            };
            assert!(
                (dot(&row, &unbounded.gamma) - expected).abs() < 1e-12 * expected.abs().max(1.0),
                "charge density at {tau}"
            );
        }
    }

    #[test]
    fn exterior_cauchy_matches_brute_force_quadrature() {
        // f = √(1−t²)(U_0 + 0.3 U_3), direct Gauss–Chebyshev of high order at x = 1.3.
        let s = BoundedSeries {
            beta: vec![1.0, 0.0, 0.0, 0.3],
        };
        let x = 1.3;
        let n = 400;
        let direct: f64 = (1..=n)
            .map(|l| {
                let th = (l as f64 * PI / (n as f64 + 1.0)).cos();
                (1.0 - th * th) * s.psi(th) / ((n as f64 + 1.0) * (th - x))
            })
            .sum();
        assert!((direct - s.cauchy(x)).abs() < 1e-12);
        let w = UnboundedSeries {
            gamma: vec![0.5, 0.2, -0.1],
        };
        let direct: f64 = (1..=n)
            .map(|l| {
                let th = ((2 * l - 1) as f64 * PI / (2.0 * n as f64)).cos();
                w.theta(th) / (n as f64 * (th - x))
            })
            .sum();
        assert!((direct - w.cauchy(x)).abs() < 1e-12);
    }
}
