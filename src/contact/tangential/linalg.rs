//! The small dense algebra of the two iterations: Anderson acceleration of the inner
//! fixed-point iteration, the pivoted solves of systems of up to five unknowns, and the
//! secant updates of the outer quasi-Newton iteration on `(lo, hi, a, c)`
//! (`J + (y − J s) dᵀ/(dᵀ s)`, projected or Broyden's).

use std::collections::VecDeque;

use crate::quadrature::dot;

/// Anderson acceleration (type II) of a fixed-point iteration `x ← F(x)`: the next iterate
/// combines the last `depth` values of F so that the combined residual `F(x) − x` is least
/// squares. For the affine map of the inner iteration it converges in a few steps where the
/// plain iteration contracts only by the coupling factor per step.
pub(super) struct Anderson {
    depth: usize,
    /// Whether `last_res` and `last_f` hold a previous pass.
    started: bool,
    /// Previous residual `F(x) − x` and `F(x)`.
    last_res: Vec<f64>,
    last_f: Vec<f64>,
    /// Differences of residuals and of F values, newest last; the oldest pair's buffers are
    /// reused for the newest once `depth` are held.
    d_res: VecDeque<Vec<f64>>,
    d_f: VecDeque<Vec<f64>>,
    /// `gram[i][j] = d_res[i] · d_res[j]`, kept from pass to pass: a pass adds the newest
    /// difference's row, not the whole matrix again.
    gram: [[f64; SMALL]; SMALL],
    /// This pass's residual.
    res: Vec<f64>,
}

impl Anderson {
    pub(super) fn new(depth: usize) -> Self {
        assert!(depth <= SMALL, "Anderson depth at most {SMALL}");
        Self {
            depth,
            started: false,
            last_res: Vec::new(),
            last_f: Vec::new(),
            d_res: VecDeque::with_capacity(depth + 1),
            d_f: VecDeque::with_capacity(depth + 1),
            gram: [[0.0; SMALL]; SMALL],
            res: Vec::new(),
        }
    }

    /// Replace `x` by the next iterate given `fx = F(x)`.
    pub(super) fn next(&mut self, x: &mut [f64], fx: &[f64]) {
        self.res.clear();
        self.res.extend(fx.iter().zip(x.iter()).map(|(f, v)| f - v));
        if self.started {
            let (mut dr, mut df) = if self.d_res.len() >= self.depth {
                // The oldest difference leaves the Gram matrix too.
                for i in 1..self.depth {
                    for j in 1..self.depth {
                        self.gram[i - 1][j - 1] = self.gram[i][j];
                    }
                }
                (
                    self.d_res.pop_front().unwrap_or_default(),
                    self.d_f.pop_front().unwrap_or_default(),
                )
            } else {
                (Vec::new(), Vec::new())
            };
            dr.clear();
            dr.extend(self.res.iter().zip(&self.last_res).map(|(a, b)| a - b));
            df.clear();
            df.extend(fx.iter().zip(&self.last_f).map(|(a, b)| a - b));
            let newest = self.d_res.len();
            for (i, di) in self.d_res.iter().enumerate() {
                let g = dot(di, &dr);
                (self.gram[i][newest], self.gram[newest][i]) = (g, g);
            }
            self.gram[newest][newest] = dot(&dr, &dr);
            self.d_res.push_back(dr);
            self.d_f.push_back(df);
        }
        self.started = true;
        self.last_res.clone_from(&self.res);
        self.last_f.clear();
        self.last_f.extend_from_slice(fx);
        x.copy_from_slice(fx);
        let k = self.d_res.len();
        if k == 0 {
            return;
        }
        // Normal equations of min |res − ΔR γ| (k ≤ depth), lightly regularised; the dot
        // products in SIMD lanes (as scalar sums, a chain of dependent additions each, they
        // took a third of a pass at M = 128).
        let mut gram = [[0.0; SMALL + 1]; SMALL];
        for ((row, kept), di) in gram.iter_mut().zip(&self.gram).zip(&self.d_res) {
            row[..k].copy_from_slice(&kept[..k]);
            row[k] = dot(di, &self.res);
        }
        let trace: f64 = (0..k).map(|i| gram[i][i]).sum::<f64>().max(1e-300);
        for (i, row) in gram.iter_mut().take(k).enumerate() {
            row[i] += 1e-12 * trace;
        }
        let Some(gamma) = solve_small(gram, k) else {
            return;
        };
        for (i, gi) in gamma[..k].iter().enumerate() {
            for (v, d) in x.iter_mut().zip(&self.d_f[i]) {
                *v -= gi * d;
            }
        }
    }
}

/// Most unknowns of [`solve_small`] (and the deepest Anderson history).
const SMALL: usize = 5;

/// Solve the `n × n` system (`n ≤ SMALL`) in the first n rows `[A | b]` of `rows` (b in column
/// n) by Gaussian elimination with partial pivoting; the solution in the first n entries. On
/// the stack: it runs at every pass of the inner iteration.
#[allow(clippy::needless_range_loop)]
fn solve_small(mut rows: [[f64; SMALL + 1]; SMALL], n: usize) -> Option<[f64; SMALL]> {
    debug_assert!(n <= SMALL);
    for col in 0..n {
        let piv = (col..n).max_by(|&x, &y| rows[x][col].abs().total_cmp(&rows[y][col].abs()))?;
        if rows[piv][col].abs() < 1e-300 {
            return None;
        }
        rows.swap(col, piv);
        for row in col + 1..n {
            let f = rows[row][col] / rows[col][col];
            for k in col..=n {
                rows[row][k] -= f * rows[col][k];
            }
        }
    }
    let mut x = [0.0; SMALL];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| rows[row][k] * x[k]).sum();
        x[row] = (rows[row][n] - s) / rows[row][row];
    }
    x[..n].iter().all(|v| v.is_finite()).then_some(x)
}

pub(super) fn norm(r: &[f64; 4]) -> f64 {
    r.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Solve the 4×4 linear system `J dx = −r` (see [`solve_small`]).
pub(super) fn solve4(j: [[f64; 4]; 4], r: [f64; 4]) -> Option<[f64; 4]> {
    let mut rows = [[0.0; SMALL + 1]; SMALL];
    for ((row, ji), ri) in rows.iter_mut().zip(j).zip(r) {
        row[..4].copy_from_slice(&ji);
        row[4] = -ri;
    }
    solve_small(rows, 4).map(|x| [x[0], x[1], x[2], x[3]])
}

/// The secant update of `j` along `direction` d for the step s taken and the change y of the
/// residuals: `J + (y − J s) dᵀ/(dᵀ s)`. The updated Jacobian maps s to y; on vectors
/// orthogonal to d it acts as `j` did. With d = s this is Broyden's update.
#[allow(clippy::needless_range_loop)]
pub(super) fn secant_update(
    j: [[f64; 4]; 4],
    step: [f64; 4],
    change: [f64; 4],
    direction: [f64; 4],
) -> [[f64; 4]; 4] {
    let scale: f64 = (0..4).map(|k| direction[k] * step[k]).sum();
    let mut updated = j;
    for i in 0..4 {
        let predicted: f64 = (0..4).map(|k| j[i][k] * step[k]).sum();
        let miss = change[i] - predicted;
        for k in 0..4 {
            updated[i][k] += miss * direction[k] / scale;
        }
    }
    updated
}

/// The directions of an attempt's accepted steps since its last restart, orthonormal: the
/// projected secant update (Gay and Schnabel, 1978) updates the Jacobian along the part of each
/// new step orthogonal to them, so that it keeps mapping the earlier steps to their changes
/// of the residuals as well as the new one. On a linear problem the Jacobian is exact after
/// four independent steps, where Broyden's update, which updates along the step itself,
/// spoils the earlier secant conditions. Quasi-Newton steps within a phase are nearly
/// parallel (mostly along the stick end that moves), so the update restarts, as Broyden's,
/// when a step has less than a tenth of its length outside the earlier directions (or all
/// four are taken; a tenth took the fewest evaluations over the regression runs). Against
/// Broyden's update it saves residual evaluations and lets steps converge that would
/// otherwise stall near the tolerance.
#[derive(Debug, Default)]
pub(super) struct SecantDirections(Vec<[f64; 4]>);

/// The fraction of a step's length outside the earlier directions below which
/// [`SecantDirections`] restarts.
const RESTART_FRACTION: f64 = 0.1;

impl SecantDirections {
    /// The direction of the update for `step`, which joins the directions.
    pub(super) fn direction(&mut self, step: [f64; 4]) -> [f64; 4] {
        let mut rest = step;
        for d in &self.0 {
            let along: f64 = (0..4).map(|k| d[k] * step[k]).sum();
            for k in 0..4 {
                rest[k] -= along * d[k];
            }
        }
        let length2 = |v: &[f64; 4]| v.iter().map(|x| x * x).sum::<f64>();
        if length2(&rest) < RESTART_FRACTION.powi(2) * length2(&step) || self.0.len() == 4 {
            self.0.clear();
            rest = step;
        }
        let length = length2(&rest).sqrt();
        self.0.push(rest.map(|v| v / length));
        rest
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a linear map `y = A s` the projected secant update reproduces A after four
    /// independent steps (the fourth step's update keeps the three earlier secant conditions),
    /// where Broyden's, from the same start and steps, is still off; a step with less than a
    /// tenth of its length outside the earlier directions restarts them.
    #[test]
    fn projected_updates_recover_a_linear_map_in_four_steps() {
        let a = [
            [4.0, -1.0, 0.5, 2.0],
            [1.0, 3.0, -2.0, 0.0],
            [0.0, 1.5, 5.0, -1.0],
            [-2.0, 0.0, 1.0, 6.0],
        ];
        let apply = |m: &[[f64; 4]; 4], v: [f64; 4]| -> [f64; 4] {
            std::array::from_fn(|i| (0..4).map(|k| m[i][k] * v[k]).sum())
        };
        // Neither orthogonal nor parallel to each other.
        let steps = [
            [1.0, 0.2, 0.0, 0.1],
            [0.8, 1.0, 0.3, 0.0],
            [0.5, -0.4, 1.0, 0.2],
            [0.3, 0.6, -0.5, 1.0],
        ];
        let start = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let (mut projected, mut broyden) = (start, start);
        let mut directions = SecantDirections::default();
        for s in steps {
            let y = apply(&a, s);
            projected = secant_update(projected, s, y, directions.direction(s));
            broyden = secant_update(broyden, s, y, s);
        }
        let miss = |j: &[[f64; 4]; 4]| {
            (0..4)
                .flat_map(|i| (0..4).map(move |k| (i, k)))
                .map(|(i, k)| (j[i][k] - a[i][k]).abs())
                .fold(0.0, f64::max)
        };
        println!(
            "projected {:e}, Broyden {:e}",
            miss(&projected),
            miss(&broyden)
        );
        assert!(miss(&projected) < 1e-12, "{:e}", miss(&projected));
        assert!(miss(&broyden) > 0.1, "{:e}", miss(&broyden));
        // The four directions are taken: the next step restarts them, and its update is
        // Broyden's (along the step itself).
        let bits = |v: [f64; 4]| v.map(f64::to_bits);
        let fifth = [1.0, 1.0, 1.0, 1.0];
        assert_eq!(bits(directions.direction(fifth)), bits(fifth));
        assert_eq!(directions.0.len(), 1);
        // A step with 4 % of its length outside the one direction restarts them too; the next
        // one, with 15 % outside the new direction, does not: its update is along that part.
        let near = [1.0, 1.0, 1.0, 1.1];
        assert_eq!(bits(directions.direction(near)), bits(near));
        let turned = directions.direction([1.0, 1.0, 1.0, 1.5]);
        let along = (3.0 + 1.1 * 1.5) / (3.0 + 1.1 * 1.1);
        let expected = [1.0 - along, 1.0 - along, 1.0 - along, 1.5 - 1.1 * along];
        assert!(
            turned
                .iter()
                .zip(expected)
                .all(|(t, e)| (t - e).abs() < 1e-15),
            "{turned:?}"
        );
        assert_eq!(directions.0.len(), 2);
    }

    /// `solve_small` on every size up to `SMALL`: a system with a known solution whose first
    /// pivot is zero (so rows must be swapped) is solved to round-off, and a singular one is
    /// refused.
    #[test]
    fn small_systems_are_solved_with_pivoting() {
        for n in 1..=SMALL {
            let want: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * i as f64).collect();
            let mut rows = [[0.0; SMALL + 1]; SMALL];
            for (i, row) in rows.iter_mut().take(n).enumerate() {
                for (j, a) in row.iter_mut().take(n).enumerate() {
                    // Zero on the first diagonal entry (n > 1), diagonally heavy elsewhere.
                    *a = if i == j && (i > 0 || n == 1) {
                        4.0 + i as f64
                    } else if i == j {
                        0.0
                    } else {
                        1.0 / (1.0 + (i + 2 * j) as f64)
                    };
                }
                row[n] = (0..n).map(|j| row[j] * want[j]).sum();
            }
            let got = solve_small(rows, n).expect("regular system");
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-13, "n = {n}: {g} against {w}");
            }
            if n > 1 {
                let mut singular = rows;
                singular[1] = singular[0];
                assert!(
                    solve_small(singular, n).is_none(),
                    "n = {n}: singular accepted"
                );
            }
        }
    }
}
