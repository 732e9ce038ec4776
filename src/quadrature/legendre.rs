//! Gauss–Legendre rules on [−1, 1] ([`gauss_legendre`]) and the weights of their running
//! integrals `∫_{-1}^{u_k}` ([`gauss_legendre_cumulative`]).

use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on Legendre polynomials).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            if n == 1 {
                p0 = 1.0;
                p1 = z;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// Legendre polynomials `P_0 … P_n` at x (three-term recurrence).
fn legendre_all(n: usize, x: f64) -> Vec<f64> {
    let mut p = vec![1.0; n + 1];
    if n >= 1 {
        p[1] = x;
    }
    for k in 2..=n {
        p[k] = ((2 * k - 1) as f64 * x * p[k - 1] - (k - 1) as f64 * p[k - 2]) / k as f64;
    }
    p
}

/// Cumulative integration matrix on the n Gauss–Legendre nodes `v_k`: row k holds `S_kj` with
/// `∫_{−1}^{v_k} f(v) dv = Σ_j S_kj f(v_j)`, exact for polynomials of degree below n. From the
/// Lagrange basis expanded in Legendre polynomials,
/// `ℓ_j(v) = w_j Σ_m (m + ½) P_m(v_j) P_m(v)`, and `∫_{−1}^{v} P_m = (P_{m+1} − P_{m−1})(v)/(2m + 1)`
/// for m ≥ 1 (`v + 1` for m = 0).
pub fn gauss_legendre_cumulative(n: usize) -> Vec<f64> {
    let (v, w) = gauss_legendre(n);
    let at_nodes: Vec<Vec<f64>> = v.iter().map(|&x| legendre_all(n, x)).collect();
    let mut s = vec![0.0; n * n];
    for k in 0..n {
        let pk = &at_nodes[k];
        for j in 0..n {
            let pj = &at_nodes[j];
            let mut sum = 0.5 * (v[k] + 1.0);
            for m in 1..n {
                sum += 0.5 * pj[m] * (pk[m + 1] - pk[m - 1]);
            }
            s[k * n + j] = w[j] * sum;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cumulative_gauss_legendre_integrates_polynomials() {
        let n = 24;
        let (v, _) = gauss_legendre(n);
        let s = gauss_legendre_cumulative(n);
        for deg in [0, 1, 5, 17, 23] {
            let f: Vec<f64> = v.iter().map(|x| x.powi(deg)).collect();
            for k in 0..n {
                let got: f64 = (0..n).map(|j| s[k * n + j] * f[j]).sum();
                let exact = (v[k].powi(deg + 1) - (-1f64).powi(deg + 1)) / (deg as f64 + 1.0);
                assert!(
                    (got - exact).abs() < 1e-13,
                    "degree {deg}, node {k}: {got} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let (x, w) = gauss_legendre(12);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(10)).sum();
        assert!((s - 2.0 / 11.0).abs() < 1e-14);
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14);
    }
}
