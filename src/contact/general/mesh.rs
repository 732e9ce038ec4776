//! The element mesh: a non-uniform partition of a band of the surface into intervals.

use serde::{Deserialize, Serialize};

/// Element edges `x_0 < x_1 < … < x_N` (m); element `i` is `[x_i, x_{i+1}]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    /// The N + 1 element edges, increasing.
    pub edges: Vec<f64>,
}

/// Where the mesh is refined: element size `size` at `at`, growing geometrically away from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Focus {
    /// Position (m).
    pub at: f64,
    /// Element size there (m).
    pub size: f64,
}

impl Mesh {
    /// A graded mesh of `[lo, hi]`: the local size is
    /// `h(x) = min(max_size, min_f (size_f + (growth − 1)|x − at_f|))`, so element sizes grow by
    /// about the factor `growth` per element away from each focus point, up to `max_size`.
    ///
    /// # Panics
    /// If `lo ≥ hi`, `growth ≤ 1`, or a size is not positive.
    pub fn graded(lo: f64, hi: f64, focus: &[Focus], growth: f64, max_size: f64) -> Self {
        assert!(lo < hi && growth > 1.0 && max_size > 0.0, "mesh parameters");
        assert!(focus.iter().all(|f| f.size > 0.0), "focus sizes");
        let size = |x: f64| {
            focus
                .iter()
                .map(|f| f.size + (growth - 1.0) * (x - f.at).abs())
                .fold(max_size, f64::min)
        };
        let mut edges = vec![lo];
        let mut x = lo;
        loop {
            // The size at the element's far end, by one fixed-point pass, so that elements
            // shrink on approach to a focus point as they grow after it.
            let h0 = size(x);
            let h = size(x + h0).min(h0);
            if x + h >= hi - 0.3 * h {
                break;
            }
            x += h;
            edges.push(x);
        }
        edges.push(hi);
        Self { edges }
    }

    /// A mesh of `[−half, half]` symmetric about 0: [`Self::graded`] on `[0, half]` with the
    /// focus points given for x > 0, mirrored.
    pub fn symmetric(half: f64, focus: &[Focus], growth: f64, max_size: f64) -> Self {
        let right = Self::graded(0.0, half, focus, growth, max_size);
        let mut edges: Vec<f64> = right.edges.iter().rev().map(|x| -x).collect();
        edges.extend_from_slice(&right.edges[1..]);
        Self { edges }
    }

    /// The width of the element that holds x (the nearest element outside the mesh) (m).
    pub fn width_at(&self, x: f64) -> f64 {
        let k = self.edges.partition_point(|&e| e <= x);
        self.width(k.clamp(1, self.len()) - 1)
    }

    /// A uniform mesh of `[lo, hi]` with `n` elements.
    pub fn uniform(lo: f64, hi: f64, n: usize) -> Self {
        let edges = (0..=n)
            .map(|i| lo + (hi - lo) * i as f64 / n as f64)
            .collect();
        Self { edges }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.edges.len() - 1
    }

    /// Whether the mesh has no element.
    pub fn is_empty(&self) -> bool {
        self.edges.len() < 2
    }

    /// Centre of element `i` (m).
    pub fn centre(&self, i: usize) -> f64 {
        0.5 * (self.edges[i] + self.edges[i + 1])
    }

    /// Width of element `i` (m).
    pub fn width(&self, i: usize) -> f64 {
        self.edges[i + 1] - self.edges[i]
    }

    /// All widths.
    pub fn widths(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.width(i)).collect()
    }

    /// All centres.
    pub fn centres(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.centre(i)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graded_mesh_is_fine_at_the_focus_and_coarse_between() {
        let focus = [
            Focus {
                at: -1.0,
                size: 1e-4,
            },
            Focus {
                at: 1.0,
                size: 1e-4,
            },
        ];
        let m = Mesh::graded(-1.1, 1.1, &focus, 1.1, 1e-2);
        let w = m.widths();
        assert!(w.iter().all(|&h| h > 0.0 && h <= 1e-2 * 1.31));
        let near = |x: f64| {
            (0..m.len())
                .find(|&i| m.edges[i] <= x && x <= m.edges[i + 1])
                .map(|i| m.width(i))
                .unwrap()
        };
        assert!(near(1.0) < 2.2e-4 && near(-1.0) < 2.2e-4);
        assert!(near(0.0) > 0.9e-2);
        // Neighbouring sizes change by at most the growth factor (and the last, merged element).
        for p in w[..w.len() - 1].windows(2) {
            assert!(p[1] / p[0] < 1.11 && p[0] / p[1] < 1.11, "{p:?}");
        }
        assert!(m.len() < 400);
    }
}
