//! The tangential subproblem at fixed pressure and charge (module docs of [`super`]): a
//! strictly convex quadratic programme with box constraints and one equality, solved by the
//! primal–dual active-set method (Hintermüller, Ito & Kunisch 2003) and, if that does not
//! settle, by the primal active-set method (Nocedal & Wright, *Numerical Optimization*,
//! Algorithm 16.3).

use faer::{Accum, ColMut, ColRef, MatRef, Par};

use super::dense::{Kernel, Workspace};
use super::normal::not_definite;

use crate::error::SolveFailure;

/// The programme `min ½ qᵀK q + cᵀq` subject to `−u ≤ q ≤ u` and, under a prescribed
/// tangential load, `wᵀq = Q`, on the contact elements. Under a prescribed displacement of the
/// punch the equality is absent and c carries the displacement (`c − Δδx w`): the programme
/// is then box-constrained only, and has a minimiser with every element at a bound (gross
/// slip).
pub(super) struct Programme<'a> {
    /// `L` on the contact elements, `K = kernel.scale · L` (symmetric positive definite).
    pub l: MatRef<'a, f64>,
    /// `c`, the displacement of the fixed loads minus the reference, integrated per element.
    pub c: &'a [f64],
    /// Element widths `w`.
    pub w: &'a [f64],
    /// `u = η p ≥ 0`.
    pub bound: &'a [f64],
    /// Q (N/m) under a prescribed tangential load; `None` under a prescribed displacement.
    pub total: Option<f64>,
    /// The mesh indices of the contact elements.
    pub elements: &'a [usize],
    /// `K` over the whole mesh (`K = kernel` on `elements`), for the factors of its free
    /// blocks, which are kept by mesh index through the changes of the contact set.
    pub kernel: Kernel<'a>,
}

/// Status of one element in the working set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Bound {
    Free,
    Upper,
    Lower,
}

/// The minimiser with its multipliers.
#[derive(Debug, Clone)]
pub(super) struct Minimiser {
    pub q: Vec<f64>,
    /// Multiplier of `wᵀq = Q`: the rigid tangential displacement increment of the punch (m);
    /// 0 without the equality.
    pub shift: f64,
    /// Mean incremental slip per element, `(1/w)(∂J/∂q) − shift` (zero on free elements).
    pub slip: Vec<f64>,
    pub status: Vec<Bound>,
    /// Slip below which an element counts as not slipping (m).
    pub slip_tolerance: f64,
    pub iterations: usize,
}

/// A feasible start near `start`: clip to the box, then spread `Q − wᵀq` over the elements in
/// proportion to their room.
fn feasible_start(p: &Programme, start: &[f64]) -> Result<Vec<f64>, SolveFailure> {
    let mut q: Vec<f64> = start
        .iter()
        .zip(p.bound)
        .map(|(q, u)| q.clamp(-u, *u))
        .collect();
    let Some(total) = p.total else {
        return Ok(q);
    };
    let excess = total - q.iter().zip(p.w).map(|(q, w)| q * w).sum::<f64>();
    if excess == 0.0 {
        return Ok(q);
    }
    let room: Vec<f64> = q
        .iter()
        .zip(p.bound)
        .map(|(q, u)| if excess > 0.0 { u - q } else { q + u })
        .collect();
    let capacity: f64 = room.iter().zip(p.w).map(|(r, w)| r * w).sum();
    if capacity <= excess.abs() {
        let limit: f64 = p.bound.iter().zip(p.w).map(|(u, w)| u * w).sum();
        return Err(SolveFailure::NoAdmissibleState {
            reason: format!(
                "gross slip: |Q| = {:.6e} N/m ≥ ηP = {limit:.6e} N/m",
                total.abs()
            ),
        });
    }
    for (qi, r) in q.iter_mut().zip(&room) {
        *qi += excess / capacity * r;
    }
    Ok(q)
}

fn status_of(q: &[f64], bound: &[f64]) -> Vec<Bound> {
    q.iter()
        .zip(bound)
        .map(|(&q, &u)| {
            if q >= u * (1.0 - 1e-13) {
                Bound::Upper
            } else if q <= -u * (1.0 - 1e-13) {
                Bound::Lower
            } else {
                Bound::Free
            }
        })
        .collect()
}

/// The step on the free set to the minimiser there: with the equality,
/// `[K_FF −w_F; w_Fᵀ 0](d; λ) = (−∇_F; 0)`, by the factor of `K_FF`:
/// `d = λ K_FF⁻¹w_F − K_FF⁻¹∇_F` with `λ = w_Fᵀ K_FF⁻¹∇_F / w_Fᵀ K_FF⁻¹w_F`; without it
/// (a prescribed displacement), `d = −K_FF⁻¹∇_F` and λ = 0.
fn free_step(
    p: &Programme,
    free: &[usize],
    grad: &[f64],
    work: &mut Workspace,
) -> Result<(Vec<f64>, f64), SolveFailure> {
    let set: Vec<usize> = free.iter().map(|&r| p.elements[r]).collect();
    let factor = Workspace::factor(&mut work.tangential, p.kernel, &set).map_err(not_definite)?;
    let size = p.kernel.log.nrows();
    let mut b = vec![0.0; size];
    let mut w = vec![0.0; size];
    for (&r, &i) in free.iter().zip(&set) {
        b[i] = grad[r];
        w[i] = p.w[r];
    }
    let [kg, kw] = factor.solve([&b, &w]);
    let shift = if p.total.is_some() {
        let (wkg, wkw) = set.iter().fold((0.0, 0.0), |(a, b), &i| {
            (a + w[i] * kg[i], b + w[i] * kw[i])
        });
        wkg / wkw
    } else {
        0.0
    };
    let d: Vec<f64> = set.iter().map(|&i| shift * kw[i] - kg[i]).collect();
    if !(shift.is_finite() && d.iter().all(|x| x.is_finite())) {
        return Err(SolveFailure::NonFinite {
            field: "tangential step",
        });
    }
    Ok((d, shift))
}

/// The minimiser, started from the working set `start` (the previous solution's), to the
/// slip tolerance 1e−10 of the slip scale of the first programme on the same contact set
/// solved with `work` (the bounds move little over a step's outer iterations): first by
/// the primal–dual active-set method (a semismooth Newton method on the complementarity
/// conditions, which changes many elements at once), then, if that does not settle within a
/// few iterations or ends infeasible, by the primal active-set method, which terminates.
pub(super) fn minimise(
    p: &Programme,
    start: &[f64],
    start_status: &[Bound],
    work: &mut Workspace,
) -> Result<Minimiser, SolveFailure> {
    let tol = match &work.slip_tolerance {
        Some((set, tol)) if set == p.elements => *tol,
        _ => {
            let tol = 1e-10 * slip_scale(p);
            work.slip_tolerance = Some((p.elements.to_vec(), tol));
            tol
        }
    };
    if let Some(m) = primal_dual(p, start_status, tol, work)? {
        return Ok(m);
    }
    primal(p, start, tol, work)
}

/// The largest mean displacement an admissible traction of `p` produces,
/// `max_i Σ_j |K_ij| u_j / w_i`.
fn slip_scale(p: &Programme) -> f64 {
    (0..p.c.len())
        .map(|i| {
            let col = p.l.col(i).try_as_col_major().expect("columns of L are contiguous");
            p.kernel.scale.abs() * abs_dot(col.as_slice(), p.bound) / p.w[i]
        })
        .fold(0.0, f64::max)
}

/// `Σ |a_i| b_i`, summed in eight independent lanes (the compiler vectorises it; a single
/// running sum is a chain of dependent additions).
fn abs_dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; 8];
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f64 = a8
        .remainder()
        .iter()
        .zip(b8.remainder())
        .map(|(x, y)| x.abs() * y)
        .sum();
    for (x, y) in a8.zip(b8) {
        for ((lane, x), y) in lanes.iter_mut().zip(x).zip(y) {
            *lane += x.abs() * y;
        }
    }
    lanes.iter().sum::<f64>() + tail
}

/// Primal–dual active set (Hintermüller, Ito & Kunisch 2003): fix the bound elements at their
/// bounds, solve for the free ones with zero slip; a free element beyond its bound joins that
/// bound, a bound element whose slip contradicts its friction is released; stop when nothing
/// changes. `None` if it has not settled in 30 iterations, or if the free set empties under a
/// prescribed load (the equality then has no free element to hold it).
fn primal_dual(
    p: &Programme,
    start: &[Bound],
    tol: f64,
    work: &mut Workspace,
) -> Result<Option<Minimiser>, SolveFailure> {
    let n = p.c.len();
    let mut status = start.to_vec();
    for iteration in 1..=30 {
        let free: Vec<usize> = (0..n).filter(|&i| status[i] == Bound::Free).collect();
        if free.is_empty() && p.total.is_some() {
            return Ok(None);
        }
        let mut q: Vec<f64> = (0..n)
            .map(|i| match status[i] {
                Bound::Upper => p.bound[i],
                Bound::Lower => -p.bound[i],
                Bound::Free => 0.0,
            })
            .collect();
        // A particular free traction meeting the equality (Q − the bound part on the free
        // elements), then the free step from it.
        if let Some(total) = p.total {
            let bound_part: f64 = q.iter().zip(p.w).map(|(q, w)| q * w).sum();
            let wf: f64 = free.iter().map(|&i| p.w[i] * p.w[i]).sum();
            let t = (total - bound_part) / wf;
            for &i in &free {
                q[i] = t * p.w[i];
            }
        }
        let is_free: Vec<bool> = status.iter().map(|&s| s == Bound::Free).collect();
        let (d, shift) = if free.is_empty() {
            (Vec::new(), 0.0)
        } else {
            free_step(p, &free, &gradient_on(p, &q, &is_free, true), work)?
        };
        for (k, &i) in free.iter().enumerate() {
            q[i] += d[k];
        }
        // The slip of the bound elements (the free ones do not slip).
        let grad = gradient_on(p, &q, &is_free, false);
        let slip: Vec<f64> = (0..n)
            .map(|i| match status[i] {
                Bound::Free => 0.0,
                _ => grad[i] / p.w[i] - shift,
            })
            .collect();
        let mut changed = false;
        for i in 0..n {
            let next = match status[i] {
                Bound::Free if q[i] > p.bound[i] => Bound::Upper,
                Bound::Free if q[i] < -p.bound[i] => Bound::Lower,
                Bound::Upper if slip[i] > tol => Bound::Free,
                Bound::Lower if slip[i] < -tol => Bound::Free,
                s => s,
            };
            changed |= next != status[i];
            status[i] = next;
        }
        if !changed {
            return Ok(Some(Minimiser {
                q,
                shift,
                slip,
                status,
                slip_tolerance: tol,
                iterations: iteration,
            }));
        }
    }
    Ok(None)
}

/// The primal active-set method from a start near `start`. Each iteration either moves to the
/// minimiser on the current free set (stopping at the first bound met, which joins the working
/// set) or, at that minimiser, releases the bound element whose slip most contradicts its
/// friction. The objective decreases strictly on every step that moves, so the method
/// terminates (barring degeneracy, guarded by an iteration limit).
fn primal(
    p: &Programme,
    start: &[f64],
    tol: f64,
    work: &mut Workspace,
) -> Result<Minimiser, SolveFailure> {
    let n = p.c.len();
    let mut q = feasible_start(p, start)?;
    let mut status = status_of(&q, p.bound);
    let limit = 20 * n + 20;
    for iteration in 1..=limit {
        let mut grad = gradient(p, &q);
        let free: Vec<usize> = (0..n).filter(|&i| status[i] == Bound::Free).collect();
        let shift = if free.is_empty() {
            if p.total.is_some() {
                shift_without_free(p, &grad, &status)
            } else {
                0.0
            }
        } else {
            let (d, shift) = free_step(p, &free, &grad, work)?;
            let mut alpha = 1.0;
            let mut blocking = None;
            for (k, &i) in free.iter().enumerate() {
                let to = if d[k] > 0.0 {
                    (p.bound[i] - q[i]) / d[k]
                } else if d[k] < 0.0 {
                    (-p.bound[i] - q[i]) / d[k]
                } else {
                    f64::INFINITY
                };
                if to < alpha {
                    alpha = to.max(0.0);
                    blocking = Some((i, d[k] > 0.0));
                }
            }
            for (k, &i) in free.iter().enumerate() {
                q[i] += alpha * d[k];
            }
            if let Some((i, up)) = blocking {
                q[i] = if up { p.bound[i] } else { -p.bound[i] };
                status[i] = if up { Bound::Upper } else { Bound::Lower };
                continue;
            }
            grad = gradient(p, &q);
            shift
        };
        let slip: Vec<f64> = (0..n)
            .map(|i| match status[i] {
                Bound::Free => 0.0,
                _ => grad[i] / p.w[i] - shift,
            })
            .collect();
        // At q = +u the half-plane must slip along −x relative to the punch (s ≤ 0), at −u
        // along +x.
        let worst = (0..n)
            .filter_map(|i| match status[i] {
                Bound::Upper if slip[i] > tol => Some((i, slip[i])),
                Bound::Lower if slip[i] < -tol => Some((i, -slip[i])),
                _ => None,
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((i, _)) => status[i] = Bound::Free,
            None => {
                return Ok(Minimiser {
                    q,
                    shift,
                    slip,
                    status,
                    slip_tolerance: tol,
                    iterations: iteration,
                });
            }
        }
    }
    Err(SolveFailure::NoConvergence {
        what: "tangential active set",
        iterations: limit,
        residual: f64::NAN,
    })
}

/// With every element at a bound the shift is any value in `[max over upper of ∇/w, min over
/// lower of ∇/w]`; take the middle of that interval (or of the violated one, which then
/// releases an element).
fn shift_without_free(p: &Programme, grad: &[f64], status: &[Bound]) -> f64 {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for (i, s) in status.iter().enumerate() {
        let v = grad[i] / p.w[i];
        match s {
            Bound::Upper => lo = lo.max(v),
            Bound::Lower => hi = hi.min(v),
            Bound::Free => {}
        }
    }
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) => 0.5 * (lo + hi),
        (true, false) => lo,
        (false, true) => hi,
        (false, false) => 0.0,
    }
}

/// `(∇J)_i = (K q + c)_i` for the elements with `rows[i] == on` (0 for the others): by the
/// symmetry of K each run of them is a block of its columns, transposed, times q.
fn gradient_on(p: &Programme, q: &[f64], rows: &[bool], on: bool) -> Vec<f64> {
    let n = q.len();
    let mut grad = vec![0.0; n];
    let mut start = 0;
    while start < n {
        if rows[start] != on {
            start += 1;
            continue;
        }
        let end = (start..n).find(|&i| rows[i] != on).unwrap_or(n);
        grad[start..end].copy_from_slice(&p.c[start..end]);
        faer::linalg::matmul::matmul(
            ColMut::from_slice_mut(&mut grad[start..end]).as_mat_mut(),
            Accum::Add,
            p.l.subcols(start, end - start).transpose(),
            ColRef::from_slice(q).as_mat(),
            p.kernel.scale,
            Par::Seq,
        );
        start = end;
    }
    grad
}

/// `∇J = K q + c`.
fn gradient(p: &Programme, q: &[f64]) -> Vec<f64> {
    let mut grad = p.c.to_vec();
    faer::linalg::matmul::matmul(
        ColMut::from_slice_mut(&mut grad).as_mat_mut(),
        Accum::Add,
        p.l,
        ColRef::from_slice(q).as_mat(),
        p.kernel.scale,
        Par::Seq,
    );
    grad
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::general::influence::Influence;
    use crate::contact::general::mesh::Mesh;

    /// Both methods reach the same minimiser of a programme with slip zones of both signs, and
    /// it satisfies the KKT conditions (Coulomb's law) to the slip tolerance.
    #[test]
    fn primal_and_primal_dual_agree_and_satisfy_coulomb() {
        let mesh = Mesh::uniform(-1.0, 1.0, 40);
        let inf = Influence::new(&mesh, 10.0);
        let n = mesh.len();
        let x = mesh.centres();
        let w = mesh.widths();
        // A linear term that drives opposite slips at the two ends, and Hertzian bounds.
        let c: Vec<f64> = x.iter().zip(&w).map(|(x, w)| w * 0.3 * x * x * x).collect();
        let bound: Vec<f64> = x.iter().map(|x| 0.3 * (1.0 - x * x).sqrt()).collect();
        let elements: Vec<usize> = (0..n).collect();
        let p = Programme {
            l: inf.log.as_ref(),
            c: &c,
            w: &w,
            bound: &bound,
            total: Some(0.1),
            elements: &elements,
            kernel: Kernel {
                log: &inf.log,
                scale: -1.0 / std::f64::consts::PI,
            },
        };
        let tol = 1e-12;
        let a = primal(&p, &vec![0.0; n], tol, &mut Workspace::default()).unwrap();
        let b = primal_dual(&p, &vec![Bound::Free; n], tol, &mut Workspace::default())
            .unwrap()
            .expect("settles");
        let diff =
            a.q.iter()
                .zip(&b.q)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
        assert!(diff < 1e-10, "{diff}");
        assert!((a.shift - b.shift).abs() < 1e-10);
        for m in [&a, &b] {
            let total: f64 = m.q.iter().zip(&w).map(|(q, w)| q * w).sum();
            assert!((total - 0.1).abs() < 1e-12);
            for (i, u) in bound.iter().enumerate() {
                assert!(m.q[i].abs() <= u * (1.0 + 1e-12));
                match m.status[i] {
                    Bound::Upper => assert!(m.slip[i] <= tol),
                    Bound::Lower => assert!(m.slip[i] >= -tol),
                    Bound::Free => assert!(m.q[i].abs() < *u),
                }
            }
            assert!(m.status.contains(&Bound::Upper) && m.status.contains(&Bound::Lower));
            assert!(m.status.contains(&Bound::Free));
        }
    }
}
