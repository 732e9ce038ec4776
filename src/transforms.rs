//! Fast cosine and sine transforms on the Gauss–Chebyshev grids of [`crate::quadrature`], by
//! real FFTs (`realfft`).
//!
//! At the grids' points the Chebyshev sums the collocation solves need are discrete cosine and
//! sine transforms:
//!
//! ```text
//! half-angle points θ_j = (2j+1)π/(2N), j = 0..N−1 (the bounded grid's collocation, N = M+1):
//!   C_k = Σ_j x_j cos(k θ_j)        (DCT-II: T_k(cos θ_j) = cos(k θ_j))
//!   S_j = Σ_{n=1}^{N−1} b_n sin(n θ_j)   (√(1−τ²) U_{n−1}(τ) = sin(nθ) at τ = cos θ)
//! whole-angle points φ_r = rπ/L, r = 1..L−1 (the unbounded grid's collocation, L = M):
//!   D_k = Σ_{r=1}^{L−1} s_r sin(k φ_r)   (DST-I)
//! ```
//!
//! Each is one real FFT of length 2N or 2L of the even or odd extension of the data:
//! with `y = (x_0 … x_{N−1}, x_{N−1} … x_0)`, `Y_k = 2 e^{iπk/(2N)} C_k`; with
//! `z = (0, s_1 … s_{L−1}, 0, −s_{L−1} … −s_1)`, `Z_k = −2i D_k`; and S is the real inverse
//! FFT of the one-sided spectrum `−(i/2) b_n e^{iπn/(2N)}`. O(N log N) operations on a few
//! kilobytes, where the same sums as matrix–vector products stream an N × N matrix each
//! (133 kB at M = 128) through the cache at every pass of the tangential solver's inner
//! iteration.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

/// Buffers of one thread's transforms, grown to the largest size used
/// ([`crate::cache::with_transform_work`]).
#[derive(Default)]
pub(crate) struct Work {
    real: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

/// Run `f` with this thread's buffers: `real` of length `real_len`, `spectrum` of
/// `real_len/2 + 1` entries, `scratch` of `scratch_len`.
fn with_work<R>(
    real_len: usize,
    scratch_len: usize,
    f: impl FnOnce(&mut [f64], &mut [Complex<f64>], &mut [Complex<f64>]) -> R,
) -> R {
    crate::cache::with_transform_work(|w| {
        let zero = Complex::new(0.0, 0.0);
        w.real.resize(real_len.max(w.real.len()), 0.0);
        w.spectrum
            .resize((real_len / 2 + 1).max(w.spectrum.len()), zero);
        w.scratch.resize(scratch_len.max(w.scratch.len()), zero);
        f(
            &mut w.real[..real_len],
            &mut w.spectrum[..real_len / 2 + 1],
            &mut w.scratch[..scratch_len],
        )
    })
}

/// The cosine and sine sums at the N half-angle points `θ_j = (2j+1)π/(2N)`.
#[derive(Clone)]
pub struct HalfAngleTransforms {
    n: usize,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
    /// `e^{−iπk/(2N)}`, k = 0..N−1.
    twiddle: Vec<Complex<f64>>,
}

impl std::fmt::Debug for HalfAngleTransforms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HalfAngleTransforms")
            .field("n", &self.n)
            .finish()
    }
}

impl HalfAngleTransforms {
    /// The transforms on `n ≥ 1` points.
    pub fn new(n: usize) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        let angle = |k: usize| -std::f64::consts::PI * k as f64 / (2 * n) as f64;
        Self {
            n,
            forward: planner.plan_fft_forward(2 * n),
            inverse: planner.plan_fft_inverse(2 * n),
            twiddle: (0..n).map(|k| Complex::from_polar(1.0, angle(k))).collect(),
        }
    }

    /// `C_k = Σ_j x_j cos(k θ_j)` for the N values `x`: writes `C_1 … C_{N−1}` into `out`
    /// (N − 1 entries) and returns `C_0`.
    pub fn cosines(&self, x: &[f64], out: &mut [f64]) -> f64 {
        let n = self.n;
        debug_assert!(x.len() == n && out.len() == n - 1);
        let scratch = self.forward.get_scratch_len();
        with_work(2 * n, scratch, |y, spectrum, scratch| {
            y[..n].copy_from_slice(x);
            for (yj, &xj) in y[n..].iter_mut().zip(x.iter().rev()) {
                *yj = xj;
            }
            self.forward
                .process_with_scratch(y, spectrum, scratch)
                .expect("buffers of the planned lengths");
            // Y_k = 2 e^{iπk/(2N)} C_k.
            for ((o, s), t) in out.iter_mut().zip(&spectrum[1..n]).zip(&self.twiddle[1..]) {
                *o = 0.5 * (s * t).re;
            }
            0.5 * spectrum[0].re
        })
    }

    /// `S_j = Σ_{n=1}^{N−1} b_n sin(n θ_j)` for the N − 1 values `b` (`b[n − 1]` = b_n):
    /// writes the N sums into `out`.
    pub fn sines(&self, b: &[f64], out: &mut [f64]) {
        let n = self.n;
        debug_assert!(b.len() == n - 1 && out.len() == n);
        let scratch = self.inverse.get_scratch_len();
        with_work(2 * n, scratch, |x, spectrum, scratch| {
            // x_j = Σ_k X_k e^{2πijk/(2N)} over the Hermitian spectrum with X_k = −(i/2) w_k,
            // w_k = b_k e^{iπk/(2N)}: x_j = Im Σ_k w_k e^{iπk j/N} = S_j.
            let zero = Complex::new(0.0, 0.0);
            spectrum[0] = zero;
            spectrum[n] = zero;
            for ((s, &bk), t) in spectrum[1..n].iter_mut().zip(b).zip(&self.twiddle[1..]) {
                let w = t.conj() * bk;
                *s = Complex::new(0.5 * w.im, -0.5 * w.re);
            }
            self.inverse
                .process_with_scratch(spectrum, x, scratch)
                .expect("buffers of the planned lengths, a real first and last entry");
            out.copy_from_slice(&x[..n]);
        })
    }
}

/// The sine sums at the whole-angle points `φ_r = rπ/L`, r = 1..L−1 (DST-I).
#[derive(Clone)]
pub struct WholeAngleSines {
    l: usize,
    forward: Arc<dyn RealToComplex<f64>>,
}

impl std::fmt::Debug for WholeAngleSines {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WholeAngleSines")
            .field("l", &self.l)
            .finish()
    }
}

impl WholeAngleSines {
    /// The transform with `l ≥ 2`.
    pub fn new(l: usize) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        Self {
            l,
            forward: planner.plan_fft_forward(2 * l),
        }
    }

    /// `D_k = Σ_{r=1}^{L−1} s_r sin(k φ_r)` for the L − 1 values `s` (`s[r − 1]` = s_r):
    /// writes `D_1 … D_{L−1}` into `out`.
    pub fn sines(&self, s: &[f64], out: &mut [f64]) {
        let l = self.l;
        debug_assert!(s.len() == l - 1 && out.len() == l - 1);
        let scratch = self.forward.get_scratch_len();
        with_work(2 * l, scratch, |z, spectrum, scratch| {
            z[0] = 0.0;
            z[l] = 0.0;
            z[1..l].copy_from_slice(s);
            for (zj, &sj) in z[l + 1..].iter_mut().zip(s.iter().rev()) {
                *zj = -sj;
            }
            self.forward
                .process_with_scratch(z, spectrum, scratch)
                .expect("buffers of the planned lengths");
            // Z_k = −2i D_k.
            for (o, zk) in out.iter_mut().zip(&spectrum[1..l]) {
                *o = -0.5 * zk.im;
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn values(n: usize, seed: f64) -> Vec<f64> {
        (0..n).map(|i| (seed * (i as f64 + 0.3)).sin()).collect()
    }

    /// Every transform against its direct sum, at sizes with small and large prime factors
    /// (the grids' M + 1 and M), to round-off relative to the sums' scale.
    #[test]
    fn transforms_equal_the_direct_sums() {
        for n in [2, 3, 17, 25, 65, 129, 130] {
            let t = HalfAngleTransforms::new(n);
            let theta = |j: usize| (2 * j + 1) as f64 * PI / (2 * n) as f64;
            let x = values(n, 1.7);
            let mut c = vec![0.0; n - 1];
            let c0 = t.cosines(&x, &mut c);
            let scale: f64 = x.iter().map(|v| v.abs()).sum();
            assert!((c0 - x.iter().sum::<f64>()).abs() < 1e-14 * scale);
            for k in 1..n {
                let direct: f64 = (0..n).map(|j| x[j] * (k as f64 * theta(j)).cos()).sum();
                assert!(
                    (c[k - 1] - direct).abs() < 1e-14 * scale,
                    "n = {n}, k = {k}"
                );
            }
            let b = values(n - 1, 0.9);
            let mut s = vec![0.0; n];
            t.sines(&b, &mut s);
            let scale: f64 = b.iter().map(|v| v.abs()).sum::<f64>().max(1e-300);
            for (j, &sj) in s.iter().enumerate() {
                let direct: f64 = (1..n).map(|k| b[k - 1] * (k as f64 * theta(j)).sin()).sum();
                assert!((sj - direct).abs() < 1e-14 * scale, "n = {n}, j = {j}");
            }
        }
        for l in [2, 3, 24, 64, 128, 129] {
            let t = WholeAngleSines::new(l);
            let s = values(l - 1, 1.3);
            let mut d = vec![0.0; l - 1];
            t.sines(&s, &mut d);
            let scale: f64 = s.iter().map(|v| v.abs()).sum();
            for k in 1..l {
                let direct: f64 = (1..l)
                    .map(|r| s[r - 1] * (k as f64 * r as f64 * PI / l as f64).sin())
                    .sum();
                assert!(
                    (d[k - 1] - direct).abs() < 1e-14 * scale,
                    "l = {l}, k = {k}"
                );
            }
        }
    }
}
