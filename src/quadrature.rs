//! Gauss–Chebyshev collocation for Cauchy singular integral equations (Erdogan & Gupta 1972),
//! Chebyshev transforms, and closed-form Cauchy transforms of the Chebyshev representations.
//!
//! Everything here lives on the normalised interval [−1, 1] and depends only on the number of
//! nodes M, so a [`BoundedGrid`] or [`UnboundedGrid`] is built and LU-factored once per run
//! (faer) and reused by every solve. Geometry enters through the affine map to the physical
//! interval, which leaves `(1/π)⨍ f(θ)/(θ − τ) dθ` unchanged. For iterations that solve the
//! same system many times, right-hand side → coefficients is in closed form: by the discrete
//! orthogonality of the Chebyshev polynomials over the collocation points it is a cosine
//! (bounded) or sine (unbounded) transform, done by real FFTs ([`crate::transforms`];
//! `solve_coefficients`), as is a bounded series' density at the collocation points
//! (`densities_at_collocation`). The series provide evaluation rows (`density_row`,
//! `cauchy_row`, [`ColumnMatrix`]) to assemble products at other points.
//!
//! # Bounded at both ends (seed eqs. 36–38, 56, 58)
//! `f(θ) = √(1 − θ²) ψ(θ)`, `ψ = Σ_{n=1}^{M} β_n U_{n−1}`. Nodes `θ_l = cos(lπ/(M+1))`,
//! `l = 1..M` (zeros of U_M); collocation `τ_r = cos((2r−1)π/(2(M+1)))`, `r = 1..M+1`
//! (zeros of T_{M+1}):
//!
//! ```text
//! (1/π)⨍ √(1−t²) U_{n−1}(t)/(t − τ) dt = −T_n(τ)              (|τ| < 1)
//!                                      = −z^n, z = τ − sgn(τ)√(τ²−1)   (|τ| > 1)
//! Σ_l (1−θ_l²) ψ_l /((M+1)(θ_l − τ_r)) = h(τ_r),   r = 1..M+1
//! ```
//!
//! The M+1 equations in M unknowns are consistent only if the discrete Chebyshev mean
//! `h̄ = Σ_r h(τ_r)/(M+1)` vanishes (the columns of the matrix sum to zero because
//! `Σ_r 1/(θ_l − τ_r) = T'_{M+1}(θ_l)/T_{M+1}(θ_l) = 0`). We solve the square system
//! `[A | 1](ψ; λ) = h`, which returns `λ = h̄`: the consistency residual that fixes a free
//! geometric parameter (seed eq. 35).
//!
//! # Unbounded at both ends (seed eqs. 41–42)
//! `f(θ) = ϑ(θ)/√(1 − θ²)`, `ϑ = Σ_{n=0}^{M−1} γ_n T_n`. Nodes `θ_l = cos((2l−1)π/(2M))`
//! (zeros of T_M); collocation `τ_r = cos(rπ/M)`, `r = 1..M−1` (zeros of U_{M−1}), plus the
//! resultant `∫ f dθ = πγ_0 = (π/M) Σ_l ϑ_l`:
//!
//! ```text
//! (1/π)⨍ T_n(t)/(√(1−t²)(t − τ)) dt = U_{n−1}(τ)  (n ≥ 1),  0  (n = 0)      (|τ| < 1)
//!                                   = −sgn(τ) z^n / √(τ²−1)                 (|τ| > 1)
//! ```

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

use crate::transforms::{HalfAngleTransforms, WholeAngleSines};
use std::f64::consts::PI;

/// A dense row-major matrix, for the matrix–vector products repeated by an iteration at fixed
/// geometry (the products replace per-point Clenshaw sums, which are latency-bound).
#[derive(Debug, Clone, Default)]
pub struct RowMatrix {
    cols: usize,
    data: Vec<f64>,
}

impl RowMatrix {
    /// A `rows × cols` matrix of zeros.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// Make this a `rows × cols` matrix of zeros, keeping the allocation (a matrix rebuilt at
    /// every residual evaluation would otherwise be mapped afresh by the allocator).
    pub fn reset(&mut self, rows: usize, cols: usize) {
        self.cols = cols;
        self.data.clear();
        self.data.resize(rows * cols, 0.0);
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.len().checked_div(self.cols).unwrap_or(0)
    }

    /// Row i.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// Row i, mutable.
    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// `y = A x`.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        debug_assert_eq!(x.len(), self.cols);
        self.products(x, Out::Set(y));
    }

    /// The products of the first rows with `x` (as many as `out` has entries) into `out`, in
    /// one SIMD dispatch for all of them.
    fn products(&self, x: &[f64], out: Out) {
        let (Out::Set(y) | Out::Add(y, _)) = &out;
        debug_assert!(
            self.cols == 0 || y.len() <= self.rows(),
            "more outputs than rows"
        );
        if self.cols == 0 {
            if let Out::Set(y) = out {
                y.fill(0.0);
            }
            return;
        }
        pulp::Arch::new().dispatch(Dots {
            rows: &self.data,
            cols: self.cols,
            x,
            out,
        });
    }

    /// `y += factor · A x`; nothing for a matrix without rows (an absent map).
    pub fn add_apply(&self, x: &[f64], factor: f64, y: &mut [f64]) {
        if self.rows() == 0 {
            return;
        }
        debug_assert_eq!(x.len(), self.cols);
        self.products(x, Out::Add(y, factor));
    }
}

/// The evaluation rows of a Chebyshev series at many points ([`BoundedSeries::density_row`],
/// `cauchy_row` inside, [`UnboundedSeries::density_row`]), stored by columns: the matrices
/// that the tangential solver rebuilds at every residual evaluation and applies a few times.
///
/// Stored by columns, the recurrence `v_{n+1} = 2τ_i v_n − v_{n−1}` runs across the points
/// in SIMD lanes and each column is written in one sweep; stored by rows, the rows were
/// filled four at a time, a chain of dependent operations per row, about three times slower.
/// The product `y = A x` is a sum of columns, `y += x_n A[:, n]`, the rows in blocks of SIMD
/// accumulators, as fast as the rows' dot products. Rows are padded to whole SIMD vectors of
/// four with zeros.
#[derive(Debug, Clone, Default)]
pub struct ColumnMatrix {
    rows: usize,
    /// Rows rounded up to a multiple of four: the length of a stored column.
    stride: usize,
    cols: usize,
    data: Vec<f64>,
}

/// Lanes the columns of a [`ColumnMatrix`] are padded to (AVX2's four; SSE2 takes two per
/// vector of four).
const COLUMN_PAD: usize = 4;

impl ColumnMatrix {
    /// Make this the `taus.len() × cols` matrix with row i `scale_i · v_n(τ_i)`,
    /// n = 0 … cols − 1, `v_{n+1} = 2τ_i v_n − v_{n−1}` from `(v_{−1}, v_0, scale_i) =
    /// start(τ_i)`: the one-point rows' entries to the bit (the same multiplications and
    /// subtractions, unfused). A zero scale gives a zero row (τ is then not used, so the
    /// recurrence cannot overflow). Keeps the allocation; every entry is written.
    pub fn refill(&mut self, cols: usize, taus: &[f64], start: impl Fn(f64) -> [f64; 3]) {
        let rows = taus.len();
        let stride = rows.div_ceil(COLUMN_PAD) * COLUMN_PAD;
        // The recurrences' state, one entry per (padded) row.
        let mut state = vec![0.0; 4 * stride];
        let (two_tau, rest) = state.split_at_mut(stride);
        let (prev, rest) = rest.split_at_mut(stride);
        let (cur, scale) = rest.split_at_mut(stride);
        for (i, &tau) in taus.iter().enumerate() {
            let [p, c, sc] = start(tau);
            if sc.abs() > 0.0 {
                (two_tau[i], prev[i], cur[i], scale[i]) = (2.0 * tau, p, c, sc);
            }
        }
        self.rows = rows;
        self.stride = stride;
        self.cols = cols;
        let len = stride * cols;
        self.data.truncate(len);
        self.data.resize(len, 0.0);
        pulp::Arch::new().dispatch(FillColumns {
            data: &mut self.data,
            stride,
            two_tau,
            prev,
            cur,
            scale,
        });
    }

    /// Make this a matrix without rows (an absent map), keeping the allocation.
    pub fn clear(&mut self) {
        self.refill(0, &[], |_| [0.0; 3]);
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Column n (its `rows` entries).
    pub fn column(&self, n: usize) -> &[f64] {
        &self.data[n * self.stride..n * self.stride + self.rows]
    }

    /// `y = A x` (the first `y.len()` rows).
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.products(x, y, None);
    }

    /// `y += factor · A x`; nothing for a matrix without rows (an absent map).
    pub fn add_apply(&self, x: &[f64], factor: f64, y: &mut [f64]) {
        if self.rows > 0 {
            self.products(x, y, Some(factor));
        }
    }

    /// `y_k = A x_k` for both k (the first `y_k.len()` rows), reading the matrix once.
    pub fn apply_pair(&self, x: [&[f64]; 2], y: [&mut [f64]; 2]) {
        debug_assert!(y.iter().all(|y| y.len() <= self.rows));
        self.with_sums(x, |sums| {
            for (y, sums) in y.into_iter().zip(sums.chunks_exact(self.stride)) {
                y.copy_from_slice(&sums[..y.len()]);
            }
        });
    }

    fn products(&self, x: &[f64], y: &mut [f64], factor: Option<f64>) {
        debug_assert!(y.len() <= self.rows);
        self.with_sums([x], |sums| match factor {
            None => y.copy_from_slice(&sums[..y.len()]),
            Some(f) => {
                for (yi, s) in y.iter_mut().zip(sums.iter()) {
                    *yi += f * s;
                }
            }
        });
    }

    /// `f` of the padded sums `A x_k`, one after the other a stride apart, in this thread's
    /// buffer: the products run at every pass of the tangential solver's inner iteration,
    /// which allocates nothing per pass.
    fn with_sums<const K: usize>(&self, x: [&[f64]; K], f: impl FnOnce(&[f64])) {
        debug_assert!(x.iter().all(|x| x.len() == self.cols));
        thread_local! {
            static SUMS: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        SUMS.with_borrow_mut(|sums| {
            sums.clear();
            sums.resize(K * self.stride, 0.0);
            pulp::Arch::new().dispatch(SumColumns {
                data: &self.data,
                stride: self.stride,
                x,
                sums,
            });
            f(sums);
        });
    }
}

/// The column sweep of [`ColumnMatrix::refill`]: column n gets `scale · cur`, then every
/// recurrence advances; four vectors of rows at a time, whose recurrences stay in registers
/// while the columns are swept (rows left over from the vectors, none when the stride is a
/// multiple of the lanes, one at a time).
struct FillColumns<'a> {
    data: &'a mut [f64],
    stride: usize,
    two_tau: &'a [f64],
    prev: &'a mut [f64],
    cur: &'a mut [f64],
    scale: &'a [f64],
}

impl pulp::WithSimd for FillColumns<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self {
            data,
            stride,
            two_tau,
            prev,
            cur,
            scale,
        } = self;
        let (t, t_tail) = S::as_simd_f64s(two_tau);
        let (sc, sc_tail) = S::as_simd_f64s(scale);
        let (p, p_tail) = S::as_mut_simd_f64s(prev);
        let (c, c_tail) = S::as_mut_simd_f64s(cur);
        let whole = t.len();
        let mut first = 0;
        while first + 4 <= whole {
            fill_block::<S, 4>(simd, data, stride, first, t, sc, p, c);
            first += 4;
        }
        while first < whole {
            fill_block::<S, 1>(simd, data, stride, first, t, sc, p, c);
            first += 1;
        }
        let tail = stride - t_tail.len();
        for (k, ((&t, &sc), (p, c))) in t_tail
            .iter()
            .zip(sc_tail)
            .zip(p_tail.iter_mut().zip(c_tail.iter_mut()))
            .enumerate()
        {
            for column in data.chunks_exact_mut(stride) {
                column[tail + k] = sc * *c;
                (*p, *c) = (*c, t * *c - *p);
            }
        }
    }
}

/// B vectors of rows from vector `first` on, swept over every column of [`FillColumns`] with
/// their recurrences in registers (`2τ` and the scale read from memory at each column: kept
/// in registers too, they spilled, and the chains ran through the stack).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn fill_block<S: pulp::Simd, const B: usize>(
    simd: S,
    data: &mut [f64],
    stride: usize,
    first: usize,
    two_tau: &[S::f64s],
    scale: &[S::f64s],
    prev: &[S::f64s],
    cur: &[S::f64s],
) {
    let (t, sc) = (&two_tau[first..first + B], &scale[first..first + B]);
    let mut p: [S::f64s; B] = std::array::from_fn(|v| prev[first + v]);
    let mut c: [S::f64s; B] = std::array::from_fn(|v| cur[first + v]);
    for column in data.chunks_exact_mut(stride) {
        let (out, _) = S::as_mut_simd_f64s(column);
        let out = &mut out[first..first + B];
        for v in 0..B {
            out[v] = simd.mul_f64s(sc[v], c[v]);
            let next = simd.sub_f64s(simd.mul_f64s(t[v], c[v]), p[v]);
            p[v] = c[v];
            c[v] = next;
        }
    }
}

/// The column sums of [`ColumnMatrix::products`] for K vectors at once, `sums_k = Σ_n x_{k,n}
/// A[:, n]` (`sums` holds the K sums one after the other, a stride apart): each column is read
/// once for all K, in blocks of `8/K` vectors of rows (8 accumulators), rows left over from the
/// vectors one at a time. The products are bandwidth-bound (the matrix streams from the
/// cache), so two vectors at once cost much less than two products.
struct SumColumns<'a, const K: usize> {
    data: &'a [f64],
    stride: usize,
    x: [&'a [f64]; K],
    sums: &'a mut [f64],
}

impl<const K: usize> pulp::WithSimd for SumColumns<'_, K> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self {
            data,
            stride,
            x,
            sums,
        } = self;
        let mut out: [&mut [f64]; K] = {
            let mut rest = Some(sums);
            std::array::from_fn(|_| {
                let (head, tail) = rest.take().expect("K sums").split_at_mut(stride);
                rest = Some(tail);
                head
            })
        };
        let whole = stride / S::F64_LANES;
        let mut first = 0;
        if K == 1 {
            while first + 8 <= whole {
                sum_block::<S, 8, K>(simd, data, stride, &x, first, &mut out);
                first += 8;
            }
        } else {
            while first + 4 <= whole {
                sum_block::<S, 4, K>(simd, data, stride, &x, first, &mut out);
                first += 4;
            }
        }
        while first + 2 <= whole {
            sum_block::<S, 2, K>(simd, data, stride, &x, first, &mut out);
            first += 2;
        }
        if first < whole {
            sum_block::<S, 1, K>(simd, data, stride, &x, first, &mut out);
        }
        let tail = whole * S::F64_LANES;
        for (sums, x) in out.iter_mut().zip(&x) {
            for (k, o) in sums[tail..].iter_mut().enumerate() {
                *o = data
                    .chunks_exact(stride)
                    .zip(*x)
                    .fold(0.0, |acc, (column, xn)| acc + column[tail + k] * xn);
            }
        }
    }
}

/// The sums of B vectors of rows from vector `first` on, over every column of [`SumColumns`],
/// for each of its K vectors, in B·K accumulators.
#[inline(always)]
fn sum_block<S: pulp::Simd, const B: usize, const K: usize>(
    simd: S,
    data: &[f64],
    stride: usize,
    x: &[&[f64]; K],
    first: usize,
    out: &mut [&mut [f64]; K],
) {
    let mut acc = [[simd.splat_f64s(0.0); B]; K];
    for (n, column) in data.chunks_exact(stride).take(x[0].len()).enumerate() {
        let (col, _) = S::as_simd_f64s(column);
        let col = &col[first..first + B];
        for (acc, x) in acc.iter_mut().zip(x) {
            let xn = simd.splat_f64s(x[n]);
            for v in 0..B {
                acc[v] = simd.mul_add_e_f64s(col[v], xn, acc[v]);
            }
        }
    }
    for (acc, out) in acc.iter().zip(out.iter_mut()) {
        let (out, _) = S::as_mut_simd_f64s(out);
        out[first..first + B].copy_from_slice(acc);
    }
}

/// `Σ a_i b_i` over the common length, in the SIMD lanes of the processor it runs on
/// (`simd_dot`).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    struct Dot<'a>(&'a [f64], &'a [f64]);
    impl pulp::WithSimd for Dot<'_> {
        type Output = f64;
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, simd: S) -> f64 {
            simd_dot(simd, self.0, self.1)
        }
    }
    pulp::Arch::new().dispatch(Dot(a, b))
}

/// `Σ a_i b_i` with four vector accumulators (sixteen lanes with AVX2, chosen at run time by
/// `pulp`), fused multiply–adds where the processor has them. Four scalar partial sums were
/// four chains of dependent additions, latency-bound, and the products with the iteration's
/// matrices are a large part of a tangential step. The accumulators are summed pairwise at
/// the end, then the lanes,
/// then the products left over from the lanes. The round-off therefore depends on the
/// processor's lane width and on FMA; [`RowMatrix::apply`] gives each row's [`dot`] to the
/// bit.
#[inline(always)]
fn simd_dot<S: pulp::Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a_lanes, a_tail) = S::as_simd_f64s(&a[..n]);
    let (b_lanes, b_tail) = S::as_simd_f64s(&b[..n]);
    let zero = simd.splat_f64s(0.0);
    let mut acc = [zero; 4];
    let (a4, b4) = (a_lanes.chunks_exact(4), b_lanes.chunks_exact(4));
    let (a_rest, b_rest) = (a4.remainder(), b4.remainder());
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            acc[k] = simd.mul_add_e_f64s(x[k], y[k], acc[k]);
        }
    }
    for (k, (x, y)) in a_rest.iter().zip(b_rest).enumerate() {
        acc[k] = simd.mul_add_e_f64s(*x, *y, acc[k]);
    }
    let sum = simd.add_f64s(simd.add_f64s(acc[0], acc[2]), simd.add_f64s(acc[1], acc[3]));
    let tail: f64 = a_tail.iter().zip(b_tail).map(|(x, y)| x * y).sum();
    simd.reduce_sum_f64s(sum) + tail
}

/// Where [`Dots`] writes its row products.
enum Out<'a> {
    /// `y_i = row_i · x`.
    Set(&'a mut [f64]),
    /// `y_i += factor · row_i · x`.
    Add(&'a mut [f64], f64),
}

/// The products of the rows of a row-major block (`cols` columns) with `x`, dispatched once
/// for all rows ([`simd_dot`] inlined into the processor's SIMD instruction set).
struct Dots<'a> {
    rows: &'a [f64],
    cols: usize,
    x: &'a [f64],
    out: Out<'a>,
}

impl pulp::WithSimd for Dots<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self { rows, cols, x, out } = self;
        let rows = rows.chunks_exact(cols);
        match out {
            Out::Set(y) => {
                for (yi, row) in y.iter_mut().zip(rows) {
                    *yi = simd_dot(simd, row, x);
                }
            }
            Out::Add(y, factor) => {
                for (yi, row) in y.iter_mut().zip(rows) {
                    *yi += factor * simd_dot(simd, row, x);
                }
            }
        }
    }
}

/// Grid and factored collocation matrix for densities bounded at both ends.
#[derive(Debug, Clone)]
pub struct BoundedGrid {
    m: usize,
    /// Nodes θ_l = cos(lπ/(M+1)), l = 1..M.
    pub nodes: Vec<f64>,
    /// Collocation points τ_r = cos((2r−1)π/(2(M+1))), r = 1..M+1.
    pub collocation: Vec<f64>,
    /// `sin(t_l) sin(n t_l)` table for the U-coefficient transform, row n−1.
    transform: Vec<f64>,
    lu: PartialPivLu<f64>,
    /// The cosine and sine sums at the collocation points (`solve_coefficients`,
    /// `densities_at_collocation`).
    transforms: HalfAngleTransforms,
}

/// Grid and factored collocation matrix for densities unbounded (inverse square root) at both ends.
#[derive(Debug, Clone)]
pub struct UnboundedGrid {
    m: usize,
    /// Nodes θ_l = cos((2l−1)π/(2M)), l = 1..M.
    pub nodes: Vec<f64>,
    /// Collocation points τ_r = cos(rπ/M), r = 1..M−1.
    pub collocation: Vec<f64>,
    /// `T_n(θ_l)` table, row n.
    transform: Vec<f64>,
    lu: PartialPivLu<f64>,
    /// The sine sums at the collocation points `rπ/M` (`solve_coefficients`).
    sines: WholeAngleSines,
    /// `sin(rπ/M)` at the collocation points.
    collocation_sines: Vec<f64>,
}

impl BoundedGrid {
    /// Build and factor for `m ≥ 2` nodes.
    pub fn new(m: usize) -> Self {
        assert!(m >= 2, "at least two collocation nodes");
        let nodes: Vec<f64> = (1..=m)
            .map(|l| (l as f64 * PI / (m as f64 + 1.0)).cos())
            .collect();
        let collocation: Vec<f64> = (1..=m + 1)
            .map(|r| ((2 * r - 1) as f64 * PI / (2.0 * (m as f64 + 1.0))).cos())
            .collect();
        let a = Mat::<f64>::from_fn(m + 1, m + 1, |r, l| {
            if l == m {
                1.0
            } else {
                (1.0 - nodes[l] * nodes[l]) / ((m as f64 + 1.0) * (nodes[l] - collocation[r]))
            }
        });
        let lu = a.partial_piv_lu();
        let mut transform = vec![0.0; m * m];
        for n in 1..=m {
            for l in 1..=m {
                let t = l as f64 * PI / (m as f64 + 1.0);
                transform[(n - 1) * m + (l - 1)] =
                    2.0 / (m as f64 + 1.0) * t.sin() * (n as f64 * t).sin();
            }
        }
        Self {
            m,
            nodes,
            collocation,
            transform,
            lu,
            transforms: HalfAngleTransforms::new(m + 1),
        }
    }

    /// Number of nodes M.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Always false (M ≥ 2).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Solve `(1/π)⨍ √(1−θ²)ψ(θ)/(θ − τ) dθ = h(τ)` from `h` at the M+1 collocation points.
    /// Writes ψ at the nodes into `psi` and returns the consistency residual `h̄`.
    pub fn solve(&self, rhs: &[f64], psi: &mut [f64]) -> f64 {
        debug_assert_eq!(rhs.len(), self.m + 1);
        let mut x = rhs.to_vec();
        self.lu.solve_in_place(faer::ColMut::from_slice_mut(&mut x));
        psi.copy_from_slice(&x[..self.m]);
        x[self.m]
    }

    /// `∫_{−1}^{1} √(1−θ²) ψ dθ = π/(M+1) Σ (1−θ_l²) ψ_l` (seed eq. 38).
    pub fn integral(&self, psi: &[f64]) -> f64 {
        let s: f64 = self
            .nodes
            .iter()
            .zip(psi)
            .map(|(t, p)| (1.0 - t * t) * p)
            .sum();
        PI / (self.m as f64 + 1.0) * s
    }

    /// [`Self::solve`] followed by [`Self::coefficients`] in closed form: writes β and
    /// returns λ. With `ψ = Σ β_n U_{n−1}` the collocation equations read
    /// `−Σ_{n=1}^{M} β_n T_n(τ_r) + λ = h_r` (module docs), and the T_n, n ≤ M, are orthogonal
    /// over the M + 1 points τ_r (`Σ_r T_n T_k = (M+1)/2 δ_nk`, `Σ_r T_n = 0` for n ≥ 1), so
    ///
    /// ```text
    /// β_n = −(2/(M+1)) Σ_r h_r T_n(τ_r),    λ = (1/(M+1)) Σ_r h_r,
    /// ```
    ///
    /// a discrete cosine transform ([`HalfAngleTransforms::cosines`]).
    pub fn solve_coefficients(&self, rhs: &[f64], beta: &mut [f64]) -> f64 {
        debug_assert_eq!(rhs.len(), self.m + 1);
        let n = (self.m + 1) as f64;
        let sum = self.transforms.cosines(rhs, beta);
        for b in beta.iter_mut() {
            *b *= -2.0 / n;
        }
        sum / n
    }

    /// The density `√(1−τ²) Σ β_n U_{n−1}(τ) = Σ β_n sin(n t_r)` of the series with
    /// coefficients `beta` at the M + 1 collocation points `τ_r = cos t_r` into `out` (a
    /// discrete sine transform, [`HalfAngleTransforms::sines`]).
    pub fn densities_at_collocation(&self, beta: &[f64], out: &mut [f64]) {
        self.transforms.sines(beta, out);
    }

    /// Coefficients β_n, n = 1..M, of `ψ = Σ β_n U_{n−1}` from nodal values (index n−1).
    pub fn coefficients(&self, psi: &[f64], beta: &mut [f64]) {
        for (n, b) in beta.iter_mut().enumerate() {
            let row = &self.transform[n * self.m..(n + 1) * self.m];
            *b = row.iter().zip(psi).map(|(a, p)| a * p).sum();
        }
    }
}

impl UnboundedGrid {
    /// Build and factor for `m ≥ 2` nodes.
    pub fn new(m: usize) -> Self {
        assert!(m >= 2, "at least two collocation nodes");
        let nodes: Vec<f64> = (1..=m)
            .map(|l| ((2 * l - 1) as f64 * PI / (2.0 * m as f64)).cos())
            .collect();
        let collocation: Vec<f64> = (1..m).map(|r| (r as f64 * PI / m as f64).cos()).collect();
        let a = Mat::<f64>::from_fn(m, m, |r, l| {
            if r == m - 1 {
                PI / m as f64
            } else {
                1.0 / (m as f64 * (nodes[l] - collocation[r]))
            }
        });
        let lu = a.partial_piv_lu();
        let mut transform = vec![0.0; m * m];
        for n in 0..m {
            for l in 0..m {
                let scale = if n == 0 { 1.0 } else { 2.0 } / m as f64;
                transform[n * m + l] = scale * (n as f64 * nodes[l].acos()).cos();
            }
        }
        Self {
            m,
            collocation_sines: (1..m).map(|r| (r as f64 * PI / m as f64).sin()).collect(),
            nodes,
            collocation,
            transform,
            lu,
            sines: WholeAngleSines::new(m),
        }
    }

    /// Number of nodes M.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Always false (M ≥ 2).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Solve `(1/π)⨍ ϑ(θ)/(√(1−θ²)(θ − τ)) dθ = h(τ_r)` (M−1 values) with
    /// `∫ ϑ/√(1−θ²) dθ = resultant`; writes ϑ at the nodes.
    pub fn solve(&self, rhs: &[f64], resultant: f64, theta: &mut [f64]) {
        debug_assert_eq!(rhs.len(), self.m - 1);
        theta[..self.m - 1].copy_from_slice(rhs);
        theta[self.m - 1] = resultant;
        self.lu.solve_in_place(faer::ColMut::from_slice_mut(theta));
    }

    /// [`Self::solve`] followed by [`Self::coefficients`] in closed form: writes γ. With
    /// `ϑ = Σ γ_n T_n` the collocation equations read `Σ_{n=1}^{M−1} γ_n U_{n−1}(τ_r) = h_r`
    /// (module docs), i.e. `Σ_n γ_n sin(nrπ/M) = h_r sin(rπ/M)`, and the resultant
    /// `(π/M) Σ_l ϑ_l = π γ_0` (`Σ_l T_n(θ_l) = 0` for 1 ≤ n < M); by the orthogonality of the
    /// sines over r = 1..M−1 (`Σ_r sin(nrπ/M) sin(krπ/M) = (M/2) δ_nk`),
    ///
    /// ```text
    /// γ_n = (2/M) Σ_r h_r sin(rπ/M) sin(nrπ/M),    γ_0 = resultant/π,
    /// ```
    ///
    /// a discrete sine transform ([`WholeAngleSines::sines`]).
    pub fn solve_coefficients(&self, rhs: &[f64], resultant: f64, gamma: &mut [f64]) {
        debug_assert_eq!(rhs.len(), self.m - 1);
        let weighted: Vec<f64> = rhs
            .iter()
            .zip(&self.collocation_sines)
            .map(|(h, s)| h * s)
            .collect();
        self.sines.sines(&weighted, &mut gamma[1..]);
        let scale = 2.0 / self.m as f64;
        for g in gamma[1..].iter_mut() {
            *g *= scale;
        }
        gamma[0] = resultant / PI;
    }

    /// The density `√(1−τ²) Σ_{n=1}^{M} β_n U_{n−1}(τ) = Σ β_n sin(nrπ/M)` of a bounded
    /// series with M coefficients `beta` at the M − 1 collocation points `τ_r = cos(rπ/M)`
    /// into `out` (the n = M term vanishes there; [`WholeAngleSines::sines`]).
    pub fn bounded_densities_at_collocation(&self, beta: &[f64], out: &mut [f64]) {
        debug_assert_eq!(beta.len(), self.m);
        self.sines.sines(&beta[..self.m - 1], out);
    }

    /// Coefficients γ_n, n = 0..M−1, of `ϑ = Σ γ_n T_n` from nodal values.
    pub fn coefficients(&self, theta: &[f64], gamma: &mut [f64]) {
        for (n, g) in gamma.iter_mut().enumerate() {
            let row = &self.transform[n * self.m..(n + 1) * self.m];
            *g = row.iter().zip(theta).map(|(a, p)| a * p).sum();
        }
    }
}

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
    pub fn density_start(tau: f64) -> [f64; 3] {
        [0.0, 1.0, (1.0 - tau * tau).max(0.0).sqrt()]
    }

    /// The start of [`Self::cauchy_row`] inside (|τ| < 1) for
    /// [`ColumnMatrix::refill`]: `(T_0, T_1, −1)`.
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

    /// The SIMD products against plain sums, at lengths around the vector blocks (four
    /// vectors of four lanes) and their left-over vectors and lanes: a product that dropped or
    /// repeated a term would be off by that term, about 1/n of the sum.
    #[test]
    fn row_products_are_the_dot_products_of_the_rows() {
        let value = |k: usize| ((k * 7919 % 104_729) as f64 / 104_729.0 - 0.5) * 3.0;
        for cols in [0, 1, 3, 4, 5, 7, 8, 15, 16, 17, 19, 31, 33, 64, 65, 129] {
            let rows = 5;
            let mut a = RowMatrix::zeros(rows, cols);
            for i in 0..rows {
                for (j, v) in a.row_mut(i).iter_mut().enumerate() {
                    *v = value(i * 1000 + j + 1);
                }
            }
            let x: Vec<f64> = (0..cols).map(|j| value(50_000 + j)).collect();
            let mut y = vec![f64::NAN; rows];
            a.apply(&x, &mut y);
            let mut z: Vec<f64> = (0..rows).map(|i| value(90_000 + i)).collect();
            let before = z.clone();
            a.add_apply(&x, 0.5, &mut z);
            for i in 0..rows {
                let terms: Vec<f64> = a.row(i).iter().zip(&x).map(|(p, q)| p * q).collect();
                let plain: f64 = terms.iter().sum();
                let size: f64 = terms.iter().map(|t| t.abs()).sum();
                assert!(
                    (y[i] - plain).abs() <= 1e-15 * size,
                    "cols {cols}, row {i}: {} against {plain}",
                    y[i]
                );
                assert_eq!(y[i].to_bits(), dot(a.row(i), &x).to_bits());
                assert_eq!(z[i].to_bits(), (before[i] + 0.5 * y[i]).to_bits());
            }
        }
    }

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

    fn t(n: usize, x: f64) -> f64 {
        let mut c = vec![0.0; n + 1];
        c[n] = 1.0;
        chebyshev_t_sum(&c, x)
    }
    fn u(n: usize, x: f64) -> f64 {
        let mut c = vec![0.0; n + 1];
        c[n] = 1.0;
        chebyshev_u_sum(&c, x)
    }

    /// The columns' entries are the one-point rows', to the bit (same operations in the same
    /// order), for a count that is not a multiple of four and points inside, on and outside
    /// [−1, 1] (where the density rows vanish); the products are the rows' dot products to
    /// round-off, the products of two vectors at once the single products to the bit, and an
    /// emptied matrix adds nothing.
    #[test]
    fn column_matrix_holds_the_one_point_rows() {
        let m = 37;
        let taus = [
            -1.7, -1.0, -0.999, -0.5, -0.013, 0.0, 0.3, 0.77, 0.9999, 1.0, 25.0,
        ];
        let inside: Vec<f64> = taus
            .iter()
            .copied()
            .filter(|t: &f64| t.abs() < 1.0)
            .collect();
        let mut row = vec![0.0; m];
        let mut a = ColumnMatrix::default();
        let entries =
            |a: &ColumnMatrix, i: usize| (0..m).map(|n| a.column(n)[i]).collect::<Vec<_>>();
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        let x: Vec<f64> = (0..m).map(|n| (0.7 * n as f64 + 0.2).cos()).collect();
        let check = |a: &ColumnMatrix,
                     points: &[f64],
                     one: fn(f64, &mut [f64]),
                     row: &mut [f64],
                     what: &str| {
            let mut y = vec![0.0; points.len()];
            a.apply(&x, &mut y);
            for (i, &t) in points.iter().enumerate() {
                one(t, row);
                assert!(same(&entries(a, i), row), "{what} at {t}");
                let direct: f64 = row.iter().zip(&x).map(|(r, x)| r * x).sum();
                let size: f64 = row.iter().zip(&x).map(|(r, x)| (r * x).abs()).sum();
                assert!(
                    (y[i] - direct).abs() <= 1e-14 * size,
                    "{what} product at {t}"
                );
            }
        };
        a.refill(m, &taus, BoundedSeries::density_start);
        check(
            &a,
            &taus,
            BoundedSeries::density_row,
            &mut row,
            "bounded density",
        );
        a.refill(m, &taus, UnboundedSeries::density_start);
        check(
            &a,
            &taus,
            UnboundedSeries::density_row,
            &mut row,
            "unbounded density",
        );
        a.refill(m, &inside, BoundedSeries::cauchy_start_inside);
        check(
            &a,
            &inside,
            BoundedSeries::cauchy_row,
            &mut row,
            "Cauchy transform",
        );
        // Two vectors at once: each the one-vector product to the bit (the same multiply–adds
        // per row in the same order), over rows in blocks of every size.
        let many: Vec<f64> = (0..45).map(|i| -0.99 + 0.044 * i as f64).collect();
        a.refill(m, &many, UnboundedSeries::density_start);
        let x2: Vec<f64> = x.iter().map(|v| v * v - 0.3).collect();
        let (mut y1, mut y2) = (vec![0.0; many.len()], vec![0.0; many.len()]);
        let (mut z1, mut z2) = (vec![0.0; many.len()], vec![0.0; many.len()]);
        a.apply(&x, &mut y1);
        a.apply(&x2, &mut y2);
        a.apply_pair([&x, &x2], [&mut z1, &mut z2]);
        assert!(same(&y1, &z1) && same(&y2, &z2), "products of two vectors");
        a.clear();
        let mut y = vec![1.5; 3];
        a.add_apply(&x, 2.0, &mut y);
        assert_eq!(a.rows(), 0);
        assert!(y.iter().all(|v| (v - 1.5).abs() <= 0.0));
    }

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

    /// (1/π)⨍ √(1−t²) U_{n−1}(t)/(t−x) dt = −T_n(x), discretely, at the collocation points.
    #[test]
    fn bounded_quadrature_reproduces_minus_t_n() {
        let m = 24;
        let g = BoundedGrid::new(m);
        for n in 1..m {
            for &x in &g.collocation {
                let s: f64 = g
                    .nodes
                    .iter()
                    .map(|&th| (1.0 - th * th) * u(n - 1, th) / ((m as f64 + 1.0) * (th - x)))
                    .sum();
                assert!(
                    (s + t(n, x)).abs() < 1e-12,
                    "n = {n}, x = {x}: {s} vs {}",
                    -t(n, x)
                );
            }
        }
    }

    /// (1/π)⨍ T_n(t)/(√(1−t²)(t−x)) dt = U_{n−1}(x), discretely, at the collocation points.
    #[test]
    fn unbounded_quadrature_reproduces_u_n_minus_1() {
        let m = 24;
        let g = UnboundedGrid::new(m);
        for n in 0..m {
            for &x in &g.collocation {
                let s: f64 = g
                    .nodes
                    .iter()
                    .map(|&th| t(n, th) / (m as f64 * (th - x)))
                    .sum();
                let expected = if n == 0 { 0.0 } else { u(n - 1, x) };
                assert!((s - expected).abs() < 1e-11, "n = {n}, x = {x}");
            }
        }
    }

    #[test]
    fn bounded_solve_inverts_and_reports_consistency() {
        let m = 20;
        let g = BoundedGrid::new(m);
        // h = −T_3 − 0.5 T_1 + 0.25 ⇒ ψ = U_2 + 0.5 U_0, consistency residual 0.25.
        let rhs: Vec<f64> = g
            .collocation
            .iter()
            .map(|&x| -t(3, x) - 0.5 * t(1, x) + 0.25)
            .collect();
        let mut psi = vec![0.0; m];
        let lambda = g.solve(&rhs, &mut psi);
        assert!((lambda - 0.25).abs() < 1e-13);
        for (th, p) in g.nodes.iter().zip(&psi) {
            assert!((p - (u(2, *th) + 0.5)).abs() < 1e-12);
        }
        let series = BoundedSeries::from_nodes(&g, &psi);
        assert!((series.beta[0] - 0.5).abs() < 1e-13 && (series.beta[2] - 1.0).abs() < 1e-13);
        // The same in closed form (the cosine transform).
        let mut beta = vec![0.0; m];
        assert!((g.solve_coefficients(&rhs, &mut beta) - 0.25).abs() < 1e-13);
        for (b, s) in beta.iter().zip(&series.beta) {
            assert!((b - s).abs() < 1e-13);
        }
        assert!((g.integral(&psi) - series.integral()).abs() < 1e-13);
        assert!((series.integral() - PI / 4.0).abs() < 1e-13);
        // Cauchy transform inside and outside, against direct formulas for ψ = 1 (β_1 = 1).
        let one = BoundedSeries { beta: vec![1.0] };
        for &x in &[-0.7, 0.3] {
            assert!((one.cauchy(x) + x).abs() < 1e-15);
        }
        for &x in &[-3.0f64, 1.5] {
            let exact = -x + x.signum() * (x * x - 1.0).sqrt();
            assert!((one.cauchy(x) - exact).abs() < 1e-14);
        }
        assert!((series.psi(1.0) - (3.0 + 0.5)).abs() < 1e-12, "U_2(1) = 3");
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

    /// A bounded series' density at both grids' collocation points by the sine transforms,
    /// against its Clenshaw sums there, for an even and an odd M.
    #[test]
    fn densities_at_collocation_points_by_transforms() {
        for m in [24, 37] {
            let (b, u) = (BoundedGrid::new(m), UnboundedGrid::new(m));
            let series = BoundedSeries {
                beta: (0..m)
                    .map(|n| 1.0 / (n as f64 + 1.0) * (0.3 * n as f64).cos())
                    .collect(),
            };
            let size: f64 = series.beta.iter().map(|v| v.abs()).sum();
            let mut at = vec![0.0; m + 1];
            b.densities_at_collocation(&series.beta, &mut at);
            for (&tau, v) in b.collocation.iter().zip(&at) {
                assert!((v - series.density(tau)).abs() < 1e-14 * size, "τ = {tau}");
            }
            let mut at = vec![0.0; m - 1];
            u.bounded_densities_at_collocation(&series.beta, &mut at);
            for (&tau, v) in u.collocation.iter().zip(&at) {
                assert!((v - series.density(tau)).abs() < 1e-14 * size, "τ = {tau}");
            }
        }
    }

    #[test]
    fn unbounded_solve_inverts() {
        let m = 16;
        let g = UnboundedGrid::new(m);
        // ϑ = 2 + T_2 − 0.5 T_5 ⇒ h = U_1 − 0.5 U_4, resultant 2π.
        let rhs: Vec<f64> = g
            .collocation
            .iter()
            .map(|&x| u(1, x) - 0.5 * u(4, x))
            .collect();
        let mut th = vec![0.0; m];
        g.solve(&rhs, 2.0 * PI, &mut th);
        let series = UnboundedSeries::from_nodes(&g, &th);
        let mut gamma = vec![0.0; m];
        g.solve_coefficients(&rhs, 2.0 * PI, &mut gamma);
        let expected = [2.0, 0.0, 1.0, 0.0, 0.0, -0.5];
        for (n, (g_lu, g_product)) in series.gamma.iter().zip(&gamma).enumerate() {
            let e = expected.get(n).copied().unwrap_or(0.0);
            assert!((g_lu - e).abs() < 1e-12, "γ_{n}");
            assert!((g_product - e).abs() < 1e-12, "γ_{n} by the sine transform");
        }
        assert!((series.integral() - 2.0 * PI).abs() < 1e-12);
        // Outside Cauchy transform of 1/√(1−t²): −sgn(x)/√(x²−1).
        let one = UnboundedSeries { gamma: vec![1.0] };
        assert!((one.cauchy(2.0) + 1.0 / 3f64.sqrt()).abs() < 1e-15);
        assert!((one.cauchy(-2.0) - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        // T_1: 1 − |x|/√(x²−1).
        let t1 = UnboundedSeries {
            gamma: vec![0.0, 1.0],
        };
        assert!((t1.cauchy(1.25) - (1.0 - 1.25 / (1.25f64 * 1.25 - 1.0).sqrt())).abs() < 1e-14);
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

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let (x, w) = gauss_legendre(12);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(10)).sum();
        assert!((s - 2.0 / 11.0).abs() < 1e-14);
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14);
    }
}
