//! Cholesky factors of the element kernel `G = s·L` (symmetric positive definite for the scale
//! `s < 0` the solver uses, module docs of [`super`]) on subsets of the elements, kept through
//! the active-set changes of a step. The factor's order puts the elements far from the middle
//! of the set last, so that the elements an active set changes (at the ends of the contact or
//! of a stick zone) sit in its trailing rows: a change keeps the leading block up to the first
//! element that leaves and appends the rest as one block (a triangular solve, a rank-t
//! product and a t×t factorization), instead of factoring the whole set again.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    LltRegularization, cholesky_in_place, cholesky_in_place_scratch,
};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatRef, Par};

/// The matrix `scale · log` over the whole mesh.
#[derive(Debug, Clone, Copy)]
pub(super) struct Kernel<'a> {
    /// The Galerkin matrix of the logarithmic kernel (m²).
    pub log: &'a Mat<f64>,
    pub scale: f64,
}

impl Kernel<'_> {
    fn at(&self, i: usize, j: usize) -> f64 {
        self.scale * self.log[(i, j)]
    }
}

/// The kernel is not positive definite on the set (the datum d is too small for the band).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct NotPositiveDefinite;

/// `G_SS = R Rᵀ` for a set S of mesh elements, R lower triangular in the order of `set`.
#[derive(Debug, Clone)]
pub(super) struct SubsetCholesky {
    /// Mesh indices in factor order.
    set: Vec<usize>,
    /// Leading dimension of `r`: the number of mesh elements.
    cap: usize,
    /// R column-major (lower triangle only; the upper is not read).
    r: Vec<f64>,
}

impl SubsetCholesky {
    /// The factor of `kernel` on `set`.
    pub fn new(kernel: Kernel, set: &[usize]) -> Result<Self, NotPositiveDefinite> {
        let cap = kernel.log.nrows();
        let mut f = Self {
            set: Vec::new(),
            cap,
            r: vec![0.0; cap * cap],
        };
        f.update(kernel, set)?;
        Ok(f)
    }

    /// Make this the factor on `target` (distinct mesh indices): keep the leading block up to
    /// the first element not in `target`, then append the other elements of `target`, those
    /// nearest the middle of `target` (by mesh index) first.
    pub fn update(&mut self, kernel: Kernel, target: &[usize]) -> Result<(), NotPositiveDefinite> {
        let mut wanted = vec![false; self.cap];
        for &i in target {
            wanted[i] = true;
        }
        let keep = self
            .set
            .iter()
            .position(|&i| !wanted[i])
            .unwrap_or(self.set.len());
        if keep == self.set.len() && keep == target.len() {
            return Ok(());
        }
        self.set.truncate(keep);
        for &i in &self.set {
            wanted[i] = false;
        }
        let mut rest: Vec<usize> = target.iter().copied().filter(|&i| wanted[i]).collect();
        let (lo, hi) = target
            .iter()
            .fold((usize::MAX, 0), |(lo, hi), &i| (lo.min(i), hi.max(i)));
        rest.sort_by_key(|&i| (2 * i).abs_diff(lo + hi));
        self.append(kernel, &rest).inspect_err(|_| self.set.clear())
    }

    /// `x = G_SS⁻¹ b` for each `b`, on mesh-indexed vectors (entries outside S: ignored in
    /// `b`, zero in x).
    pub fn solve<const K: usize>(&self, b: [&[f64]; K]) -> [Vec<f64>; K] {
        let m = self.set.len();
        let mut y = Mat::<f64>::from_fn(m, K, |r, k| b[k][self.set[r]]);
        if m > 0 {
            let r = self.block(0, m);
            solve_lower_triangular_in_place(r, y.as_mut(), Par::Seq);
            solve_upper_triangular_in_place(r.transpose(), y.as_mut(), Par::Seq);
        }
        std::array::from_fn(|k| {
            let mut x = vec![0.0; b[k].len()];
            for (r, &i) in self.set.iter().enumerate() {
                x[i] = y[(r, k)];
            }
            x
        })
    }

    /// The diagonal block of R from row and column `at`, of size `size`.
    fn block(&self, at: usize, size: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice_with_stride(
            &self.r[at * (self.cap + 1)..],
            size,
            size,
            self.cap,
        )
    }

    /// Append the elements `add` as a block: with R₁₁ the current factor,
    /// `R₂₁ = G₂₁ R₁₁⁻ᵀ` and `R₂₂ R₂₂ᵀ = G₂₂ − R₂₁ R₂₁ᵀ`.
    fn append(&mut self, kernel: Kernel, add: &[usize]) -> Result<(), NotPositiveDefinite> {
        let (m, t, cap) = (self.set.len(), add.len(), self.cap);
        if t == 0 {
            return Ok(());
        }
        // X = R₁₁⁻¹ G₁₂ = R₂₁ᵀ.
        let mut x = Mat::<f64>::from_fn(m, t, |r, k| kernel.at(self.set[r], add[k]));
        let mut c = Mat::<f64>::from_fn(t, t, |r, k| kernel.at(add[r], add[k]));
        if m > 0 {
            solve_lower_triangular_in_place(self.block(0, m), x.as_mut(), Par::Seq);
            matmul(
                c.as_mut(),
                Accum::Add,
                x.transpose(),
                x.as_ref(),
                -1.0,
                Par::Seq,
            );
        }
        let mut buf = MemBuffer::new(cholesky_in_place_scratch::<f64>(
            t,
            Par::Seq,
            Default::default(),
        ));
        cholesky_in_place(
            c.as_mut(),
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut buf),
            Default::default(),
        )
        .map_err(|_| NotPositiveDefinite)?;
        for b in 0..m {
            let col = &mut self.r[b * cap + m..b * cap + m + t];
            for (a, v) in col.iter_mut().enumerate() {
                *v = x[(b, a)];
            }
        }
        for b in 0..t {
            let col = &mut self.r[(m + b) * cap + m..(m + b) * cap + m + t];
            col[b..].copy_from_slice(&c.col_as_slice(b)[b..]);
        }
        self.set.extend_from_slice(add);
        Ok(())
    }
}

/// What one step keeps through its outer iterations: factors, L on the contact set, the
/// previous state's gaps and the tangential slip tolerance.
#[derive(Debug, Default)]
pub(super) struct Workspace {
    /// `−L/π` on the contact set.
    pub normal: Option<SubsetCholesky>,
    /// The tangential stiffness on the free set.
    pub tangential: Option<SubsetCholesky>,
    /// L on the contact set where it is gathered (its mesh indices, L).
    pub gathered_log: Option<(Vec<usize>, Mat<f64>)>,
    /// The gaps of the step's previous state, once a step needs them (elements that enter
    /// the contact).
    pub previous_gaps: Option<Vec<f64>>,
    /// The slip below which an element of the tangential programme counts as not slipping
    /// (m), set by the first programme on the contact set (its mesh indices, the tolerance).
    pub slip_tolerance: Option<(Vec<usize>, f64)>,
}

impl Workspace {
    /// The factor in `slot`, brought to `set`.
    pub fn factor<'w>(
        slot: &'w mut Option<SubsetCholesky>,
        kernel: Kernel,
        set: &[usize],
    ) -> Result<&'w SubsetCholesky, NotPositiveDefinite> {
        match slot {
            Some(f) => f.update(kernel, set)?,
            None => *slot = Some(SubsetCholesky::new(kernel, set)?),
        }
        Ok(slot.as_ref().expect("set above"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::general::influence::Influence;
    use crate::contact::general::mesh::Mesh;

    /// Updated factors (elements leaving inside and at the end of the order, elements
    /// entering) solve as a new factorization of the same set does.
    #[test]
    fn updated_factor_solves_like_a_new_one() {
        let mesh = Mesh::uniform(-1.0, 1.0, 60);
        let inf = Influence::new(&mesh, 10.0);
        let kernel = Kernel {
            log: &inf.log,
            scale: -1.0 / std::f64::consts::PI,
        };
        let b: Vec<f64> = (0..60).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut f = SubsetCholesky::new(kernel, &(10..50).collect::<Vec<_>>()).unwrap();
        for target in [
            (8..49).collect::<Vec<_>>(),
            (5..20).chain(22..52).collect(),
            (5..19).chain(23..55).collect(),
        ] {
            f.update(kernel, &target).unwrap();
            let [x] = f.solve([&b]);
            let [fresh] = SubsetCholesky::new(kernel, &target).unwrap().solve([&b]);
            let scale = fresh.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
            for (i, (u, v)) in x.iter().zip(&fresh).enumerate() {
                assert!((u - v).abs() < 1e-10 * scale, "{i}: {u} vs {v}");
            }
            // The residual of G_SS x = b on the set.
            for &i in &target {
                let r: f64 = target.iter().map(|&j| kernel.at(i, j) * x[j]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-12 * scale, "{r}");
            }
        }
    }
}
