//! The matrices that apply the series' evaluation rows at many points ([`RowMatrix`], and
//! [`ColumnMatrix`], whose columns are filled by the Chebyshev three-term recurrence from a
//! start at each point), with their products summed in SIMD lanes (pulp), and [`dot`].

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

    /// `y += factor · A x` for the first rows (as many as `y` has entries), in one SIMD
    /// dispatch for all of them; nothing for a matrix without rows (an absent map).
    pub fn add_apply(&self, x: &[f64], factor: f64, y: &mut [f64]) {
        if self.rows() == 0 || self.cols == 0 {
            return;
        }
        debug_assert_eq!(x.len(), self.cols);
        debug_assert!(y.len() <= self.rows(), "more outputs than rows");
        pulp::Arch::new().dispatch(Dots {
            rows: &self.data,
            cols: self.cols,
            x,
            y,
            factor,
        });
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
///
/// [`BoundedSeries::density_row`]: super::BoundedSeries::density_row
/// [`UnboundedSeries::density_row`]: super::UnboundedSeries::density_row
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
    #[cfg(test)]
    pub fn column(&self, n: usize) -> &[f64] {
        &self.data[n * self.stride..n * self.stride + self.rows]
    }

    /// `y = A x` (the first `y.len()` rows).
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        debug_assert!(y.len() <= self.rows);
        self.with_sums([x], |sums| y.copy_from_slice(&sums[..y.len()]));
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


    /// `f` of the padded sums `A x_k`, one after the other a stride apart, in this thread's
    /// buffer ([`crate::cache::with_column_sums`]): the products run at every pass of the tangential solver's inner iteration,
    /// which allocates nothing per pass.
    fn with_sums<const K: usize>(&self, x: [&[f64]; K], f: impl FnOnce(&[f64])) {
        debug_assert!(x.iter().all(|x| x.len() == self.cols));
        crate::cache::with_column_sums(|sums| {
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

/// The column sums of [`ColumnMatrix::apply`] for K vectors at once, `sums_k = Σ_n x_{k,n}
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

/// The products of the rows of a row-major block (`cols` columns) with `x`, added to `y`
/// times `factor` (`y_i += factor · row_i · x`), dispatched once for all rows ([`simd_dot`]
/// inlined into the processor's SIMD instruction set).
struct Dots<'a> {
    rows: &'a [f64],
    cols: usize,
    x: &'a [f64],
    y: &'a mut [f64],
    factor: f64,
}

impl pulp::WithSimd for Dots<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self {
            rows,
            cols,
            x,
            y,
            factor,
        } = self;
        for (yi, row) in y.iter_mut().zip(rows.chunks_exact(cols)) {
            *yi += factor * simd_dot(simd, row, x);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::quadrature::{BoundedSeries, UnboundedSeries};

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
            let mut y = vec![0.0; rows];
            a.add_apply(&x, 1.0, &mut y);
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
        assert_eq!(a.rows(), 0);
    }
}
