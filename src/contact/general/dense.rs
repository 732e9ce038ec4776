//! Cholesky factors of the element kernel `G = s·L` (symmetric positive definite for the scale
//! `s < 0` the solver uses, module docs of [`super`]) on subsets of the elements. An active-set
//! change of a few elements updates the factor by row insertions and deletions, O(m²) each,
//! instead of a new factorization, O(m³); a larger change refactors.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    LltRegularization, cholesky_in_place, cholesky_in_place_scratch,
};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{ColMut, Mat, MatMut, MatRef, Par};

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
        f.refactor(kernel, set)?;
        Ok(f)
    }

    /// Make this the factor on `target` (distinct mesh indices), by updates if few elements
    /// change, else by a new factorization.
    pub fn update(&mut self, kernel: Kernel, target: &[usize]) -> Result<(), NotPositiveDefinite> {
        let mut wanted = vec![false; self.cap];
        for &i in target {
            wanted[i] = true;
        }
        let mut present = vec![false; self.cap];
        for &i in &self.set {
            present[i] = true;
        }
        let remove: Vec<usize> = (0..self.set.len())
            .filter(|&k| !wanted[self.set[k]])
            .collect();
        let add: Vec<usize> = target.iter().copied().filter(|&i| !present[i]).collect();
        let changes = remove.len() + add.len();
        if changes == 0 {
            return Ok(());
        }
        // An insertion or deletion costs O(m²), a factorization O(m³/3) at a higher rate.
        if changes > 4 + target.len() / 16 {
            return self.refactor(kernel, target);
        }
        for &k in remove.iter().rev() {
            self.delete(k);
        }
        for &j in &add {
            if self.append(kernel, j).is_err() {
                return self.refactor(kernel, target);
            }
        }
        Ok(())
    }

    /// `x = G_SS⁻¹ b` for each `b`, on mesh-indexed vectors (entries outside S: ignored in
    /// `b`, zero in x).
    pub fn solve<const K: usize>(&self, b: [&[f64]; K]) -> [Vec<f64>; K] {
        let m = self.set.len();
        let mut y = Mat::<f64>::from_fn(m, K, |r, k| b[k][self.set[r]]);
        if m > 0 {
            let r = self.factor();
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

    /// R (its lower triangle).
    fn factor(&self) -> MatRef<'_, f64> {
        let m = self.set.len();
        MatRef::from_column_major_slice_with_stride(&self.r[..], m, m, self.cap)
    }

    fn refactor(&mut self, kernel: Kernel, set: &[usize]) -> Result<(), NotPositiveDefinite> {
        let (m, cap) = (set.len(), self.cap);
        self.set.clear();
        for (s, &j) in set.iter().enumerate() {
            let col = kernel.log.col_as_slice(j);
            let dst = &mut self.r[s * cap..s * cap + m];
            for (d, &i) in dst.iter_mut().zip(set).skip(s) {
                *d = kernel.scale * col[i];
            }
        }
        if m > 0 {
            let a = MatMut::from_column_major_slice_with_stride_mut(&mut self.r[..], m, m, cap);
            let mut buf = MemBuffer::new(cholesky_in_place_scratch::<f64>(
                m,
                Par::Seq,
                Default::default(),
            ));
            cholesky_in_place(
                a,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut buf),
                Default::default(),
            )
            .map_err(|_| NotPositiveDefinite)?;
        }
        self.set.extend_from_slice(set);
        Ok(())
    }

    /// Append element `j` as the last row: `R y = G_Sj`, `ρ = √(G_jj − yᵀy)`.
    fn append(&mut self, kernel: Kernel, j: usize) -> Result<(), NotPositiveDefinite> {
        let (m, cap) = (self.set.len(), self.cap);
        let col = kernel.log.col_as_slice(j);
        let mut y: Vec<f64> = self.set.iter().map(|&i| kernel.scale * col[i]).collect();
        if m > 0 {
            solve_lower_triangular_in_place(
                self.factor(),
                ColMut::from_slice_mut(&mut y).as_mat_mut(),
                Par::Seq,
            );
        }
        let d2 = kernel.at(j, j) - y.iter().map(|v| v * v).sum::<f64>();
        if !(d2 > 0.0 && d2.is_finite()) {
            return Err(NotPositiveDefinite);
        }
        for (s, v) in y.iter().enumerate() {
            self.r[s * cap + m] = *v;
        }
        self.r[m * cap + m] = d2.sqrt();
        self.set.push(j);
        Ok(())
    }

    /// Delete the element in position `k`: the trailing block takes the rank-one update by
    /// the deleted column below the diagonal (Givens form), then the row and column go.
    fn delete(&mut self, k: usize) {
        let (m, cap) = (self.set.len(), self.cap);
        let mut v: Vec<f64> = self.r[k * cap + k + 1..k * cap + m].to_vec();
        for (t, j) in (k + 1..m).enumerate() {
            let col = &mut self.r[j * cap..j * cap + m];
            let rjj = col[j];
            let rho = rjj.hypot(v[t]);
            let (c, s) = (rho / rjj, v[t] / rjj);
            col[j] = rho;
            for (x, vi) in col[j + 1..m].iter_mut().zip(&mut v[t + 1..]) {
                *x = (*x + s * *vi) / c;
                *vi = c * *vi - s * *x;
            }
        }
        for j in 0..k {
            self.r
                .copy_within(j * cap + k + 1..j * cap + m, j * cap + k);
        }
        for j in k + 1..m {
            self.r
                .copy_within(j * cap + j..j * cap + m, (j - 1) * cap + j - 1);
        }
        self.set.remove(k);
    }
}

/// Factors kept through the outer iterations of one step.
#[derive(Debug, Default)]
pub(super) struct Workspace {
    /// `−L/π` on the contact set.
    pub normal: Option<SubsetCholesky>,
    /// The tangential stiffness on the free set.
    pub tangential: Option<SubsetCholesky>,
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

    /// Updates by insertion and deletion solve as a new factorization of the same set does.
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
