//! Square-root kinks in closed form: a stick correction's centre kink ([`kink_density`], the
//! bounded solution of `(1/π)⨍ k(t)/(t − u) dt = |u| − 2/π`) and the kinks of p and w at the
//! stick ends ([`Kink`]: half-ellipses `e(x; u, v) = √((x − u)(v − x))` with their Cauchy
//! transforms and integrals; tangential module docs, "Kinks at the stick ends").

use serde::Serialize;

/// `k(u) = −(2u/π) artanh √(1 − u²)`: the bounded solution of
/// `(1/π)⨍ k(t)/(t − u) dt = |u| − 2/π` on (−1, 1). Its U-series coefficients decay only like
/// n⁻², so it is kept in closed form; `k(u)/√(1−u²) → −2/π` at u = ±1.
pub fn kink_density(u: f64) -> f64 {
    // k(u) ≈ −(2u/π) ln(2/|u|) → 0 as u → 0: below 1e−300 it is 0 to f64's resolution of
    // k's values (at most 0.47), and the quotient below would overflow.
    if u.abs() >= 1.0 || u.abs() < 1e-300 {
        return 0.0;
    }
    // artanh √(1 − u²) = ln((1 + √(1 − u²))/|u|): one logarithm of the quotient rather than
    // two (of the numerator and of |u|), on a hot path.
    -2.0 * u / std::f64::consts::PI * ((1.0 + (1.0 - u * u).sqrt()) / u.abs()).ln()
}

/// `(1/π)⨍ k(t)/(t − u) dt`: `|u| − 2/π` inside, `(2/π)((|z| + 1/|z|) arctan|z| − 1)` outside,
/// `z = u − sgn(u)√(u² − 1)`.
pub fn kink_cauchy(u: f64) -> f64 {
    let two_over_pi = 2.0 / std::f64::consts::PI;
    if u.abs() <= 1.0 {
        u.abs() - two_over_pi
    } else {
        let z = (u.abs() - (u * u - 1.0).sqrt()).max(1e-300);
        two_over_pi * ((z + 1.0 / z) * z.atan() - 1.0)
    }
}

/// One square-root kink of a density (the pressure p or the charge w): the term
/// `amplitude · e(x)/a` with the half-ellipse `e(x; u, v) = √((x − u)(v − x))` ([`half_ellipse`])
/// on the slip-side stretch from the kink point `at` to the contact end on `side` (`[at, c + a]`
/// for side +1, `[c − a, at]` for side −1). It starts like a square root at `at`, vanishes like
/// one at the contact end and has a Cauchy transform in closed form ([`half_ellipse_cauchy`]).
/// See the tangential module docs ("Kinks at the stick ends") for where the kinks come from
/// and how the amplitudes are fixed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Kink {
    /// Kink point (m).
    pub at: f64,
    /// +1: the term lies right of the kink point; −1: left.
    pub side: f64,
    /// Amplitude (the density's unit).
    pub amplitude: f64,
}

/// The kinks of a density; empty unless it is coupled to a stick traction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Kinks(pub Vec<Kink>);

/// The stretch `[u, v]` of a kink term at `at` on `side` of a contact `[c − a, c + a]`.
pub fn kink_domain(at: f64, side: f64, centre: f64, half_width: f64) -> (f64, f64) {
    if side > 0.0 {
        (at, centre + half_width)
    } else {
        (centre - half_width, at)
    }
}

/// `√((x − u)(v − x))` on `[u, v]`, zero outside (m).
pub fn half_ellipse(x: f64, u: f64, v: f64) -> f64 {
    if x <= u || x >= v {
        0.0
    } else {
        ((x - u) * (v - x)).sqrt()
    }
}

/// `(1/π)⨍ e(t)/(t − x) dt` of [`half_ellipse`] (m): `−(x − m)` on `[u, v]` and
/// `−(x − m) + sgn(x − m)√((x − u)(x − v))` outside, `m = (u + v)/2` (the n = 1 term of a
/// bounded series, `−h T_1` inside and `−h z` outside; it decays like `−h²/(2(x − m))`).
pub fn half_ellipse_cauchy(x: f64, u: f64, v: f64) -> f64 {
    let m = 0.5 * (u + v);
    if x >= u && x <= v {
        -(x - m)
    } else {
        -(x - m) + (x - m).signum() * ((x - u) * (x - v)).sqrt()
    }
}

/// `∫ e dx = π (v − u)²/8` of [`half_ellipse`] (m²).
pub fn half_ellipse_integral(u: f64, v: f64) -> f64 {
    std::f64::consts::PI * (v - u) * (v - u) / 8.0
}

#[cfg(test)]
mod tests {
    use crate::quadrature::BoundedSeries;

    use super::*;

    /// The half-ellipse on `[u, v]` is the n = 1 term of a bounded series on that interval
    /// (β_1 = h, τ = (x − m)/h): its values, Cauchy transform (inside and on both sides
    /// outside) and integral (h times the series' ∫ dτ) against the series' own formulas,
    /// which the quadrature module tests against brute-force quadrature.
    #[test]
    fn half_ellipse_is_the_first_bounded_term() {
        let (u, v) = (-0.3, 0.9);
        let (m, h) = (0.5 * (u + v), 0.5 * (v - u));
        let series = BoundedSeries { beta: vec![h] };
        for x in [-2.0, -0.31, -0.2, 0.1, 0.5, 0.89, 0.95, 3.0] {
            let t = (x - m) / h;
            assert!(
                (half_ellipse(x, u, v) - series.density(t)).abs() < 1e-15,
                "{x}"
            );
            assert!(
                (half_ellipse_cauchy(x, u, v) - series.cauchy(t)).abs() < 1e-15,
                "{x}"
            );
        }
        assert!((half_ellipse_integral(u, v) - h * series.integral()).abs() < 1e-15);
    }

    /// `k(u)` with one logarithm equals the definition `−(2u/π)(ln(1 + √(1−u²)) − ln|u|)`
    /// to round-off across (−1, 1) (measured 1.1e−16 at worst, k being at most 0.47; bound
    /// 1e−15), and is 0 at and beyond the ends, at 0, and below 1e−300, where the definition
    /// is at most 4.4e−298 and the quotient would overflow.
    #[test]
    fn kink_density_with_one_logarithm_is_the_definition() {
        let two_logs = |u: f64| {
            -2.0 * u / std::f64::consts::PI * ((1.0 + (1.0 - u * u).sqrt()).ln() - u.abs().ln())
        };
        let mut worst: f64 = 0.0;
        for k in 1..2000 {
            let u = -1.0 + k as f64 / 1000.0;
            for u in [u, u * 1e-3, u * 1e-9, u * 1e-150, u * 1e-299] {
                worst = worst.max((kink_density(u) - two_logs(u)).abs());
            }
        }
        assert!(worst < 1e-15, "{worst:e}");
        for u in [-1.0, 1.0, 1.5, 0.0, 1e-301, -3e-310, 5e-324] {
            assert!(kink_density(u).abs() <= 0.0, "at {u:e}");
        }
    }
}
