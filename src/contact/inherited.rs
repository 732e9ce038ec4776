//! An earlier stick zone's correction carried into a new zone ([`Inherited`]; tangential
//! module docs, "Inherited corrections"): faded out by C² quintic ramps where the new zone ends
//! inside the old one, with its values and Cauchy transform summed over fade tables (and in
//! SIMD lanes); and the remembered stick ends inside a new zone whose square-root kinks it
//! carries ([`RememberedRoot`]).

use super::StickZone;
use super::rules::{FADE_RULE_NODES, graded_rule_with};

/// An earlier stick zone's correction carried into a new zone, faded out smoothly where the
/// new zone ends inside it: `χ(x) q̃_E(x)` with `χ` rising from 0 at `ramp_lo.0` to 1 at
/// `ramp_lo.1` and falling from 1 at `ramp_hi.0` to 0 at `ramp_hi.1` (C² quintic ramps).
/// The memory inside the new zone has square-root kinks at the old zone's ends, which the old
/// correction reproduces exactly; the fade only matters near the new ends, where q̃ must vanish.
///
/// Written as plain data: the fade table as whether it was built, rebuilt on reading.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(from = "InheritedData")]
pub struct Inherited {
    /// The earlier zone (with its own chain).
    #[serde(with = "crate::shared")]
    pub zone: std::sync::Arc<StickZone>,
    /// Left ramp `(start, end)`, or `None` when the earlier zone lies inside on that side.
    pub ramp_lo: Option<(f64, f64)>,
    /// Right ramp `(start, end)`.
    pub ramp_hi: Option<(f64, f64)>,
    /// Quadrature table of the fade integral, built on first use.
    #[serde(serialize_with = "table_built")]
    table: std::sync::OnceLock<FadeTable>,
}

/// Whether the fade table was built.
fn table_built<S: serde::Serializer>(
    table: &std::sync::OnceLock<FadeTable>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&table.get().is_some(), serializer)
}

/// An [`Inherited`] as written.
#[derive(serde::Deserialize)]
struct InheritedData {
    #[serde(with = "crate::shared")]
    zone: std::sync::Arc<StickZone>,
    ramp_lo: Option<(f64, f64)>,
    ramp_hi: Option<(f64, f64)>,
    table: TableWritten,
}

/// How a fade table was written: whether it was built, or (an earlier form) the ramps its
/// nodes were placed for, `null` when not built.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum TableWritten {
    Built(bool),
    Ramps(Option<[Option<(f64, f64)>; 2]>),
}

impl From<InheritedData> for Inherited {
    fn from(d: InheritedData) -> Self {
        let link = Self::new(d.zone, d.ramp_lo, d.ramp_hi);
        if matches!(
            d.table,
            TableWritten::Built(true) | TableWritten::Ramps(Some(_))
        ) {
            link.table();
        }
        link
    }
}

/// Quadrature nodes `(t, w q̃_E(t), χ(t))` of the fade integral of an [`Inherited`], all of
/// them and, in the same order, those with χ ≠ 1 and those with χ ≠ 0: at a point x where
/// χ(x) is 1 (or 0) the nodes with the same χ contribute exactly zero to the sum of
/// [`Inherited::cauchy`] and are skipped.
#[derive(Debug, Clone, Default)]
struct FadeTable {
    all: Vec<(f64, f64, f64)>,
    not_one: Vec<(f64, f64, f64)>,
    not_zero: Vec<(f64, f64, f64)>,
}

impl FadeTable {
    /// The table of the nodes `(t, w q̃_E(t), χ(t))` in increasing t.
    fn new(all: Vec<(f64, f64, f64)>) -> Self {
        // `FadeSums` finds the nodes near a point by bisection.
        debug_assert!(all.is_sorted_by(|a, b| a.0 <= b.0), "nodes in increasing t");
        let except = |v: f64| {
            all.iter()
                .copied()
                .filter(|e| (e.2 - v).abs() > 0.0)
                .collect()
        };
        Self {
            not_one: except(1.0),
            not_zero: except(0.0),
            all,
        }
    }

    /// The nodes whose terms can be non-zero at a point where χ is `cx`.
    fn nodes_for(&self, cx: f64) -> &[(f64, f64, f64)] {
        // χ is exactly 1 (or 0) away from the ramps; only exact zeros are skipped.
        if (cx - 1.0).abs() <= 0.0 {
            &self.not_one
        } else if cx.abs() <= 0.0 {
            &self.not_zero
        } else {
            &self.all
        }
    }
}

/// [`fade_sum`] at each point `x` (with χ there `cx`) into `sums` (which start at −0), the
/// points in SIMD lanes chosen at run time by `pulp` (four-wide AVX2 where the processor has
/// it, else two-wide SSE2: the 256-bit divisions that bound these sums halve their time;
/// points left over from the lanes by [`fade_sum`] itself). Each lane adds the same terms in
/// the same order as [`fade_sum`], with the same operations, so the sums are its own to the
/// bit on every processor: a group of nodes none of which lies within twice `tiny` of a
/// lane's point (the nodes increase, so the others are found by bisection; a point rarely has
/// any) skips nothing, and its terms are summed without the masks of the skipped nodes, which
/// give the same bits where nothing is skipped.
struct FadeSums<'a> {
    nodes: &'a [(f64, f64, f64)],
    x: &'a [f64],
    cx: &'a [f64],
    tiny: f64,
    sums: &'a mut [f64],
}

impl pulp::WithSimd for FadeSums<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        let (x_lanes, x_tail) = S::as_simd_f64s(self.x);
        let (cx_lanes, cx_tail) = S::as_simd_f64s(self.cx);
        let (sum_lanes, sum_tail) = S::as_mut_simd_f64s(self.sums);
        let tiny = simd.splat_f64s(self.tiny);
        let (zero, one) = (simd.splat_f64s(0.0), simd.splat_f64s(1.0));
        let groups = self.nodes.chunks_exact(FADE_GROUP);
        let (count, single) = (groups.len(), groups.remainder());
        let mul = |a, b| simd.mul_f64s(a, b);
        let add = |a, b| simd.add_f64s(a, b);
        // The (vector, group) pairs with a node within twice `tiny` of one of the vector's
        // points, increasing (a point rarely has any). The nodes increase; for points in
        // order (the stick points, the rules' nodes) one walk along both finds each point's
        // first node at or beyond `x − 2 tiny`, otherwise a bisection per point does (the
        // bisections took 1.8 % of the bench's forward step at M = 128).
        let lanes = S::F64_LANES;
        let reach = 2.0 * self.tiny;
        let points = &self.x[..x_lanes.len() * lanes];
        let mut near_all: Vec<(usize, usize)> = Vec::new();
        let mut mark_from = |i: usize, from: usize| {
            for (k, node) in self.nodes.iter().enumerate().skip(from) {
                if node.0 > points[i] + reach {
                    break;
                }
                if k / FADE_GROUP < count {
                    near_all.push((i / lanes, k / FADE_GROUP));
                }
            }
        };
        let increasing = points.is_sorted();
        if increasing || points.iter().rev().is_sorted() {
            let mut from = 0;
            for j in 0..points.len() {
                let i = if increasing { j } else { points.len() - 1 - j };
                while from < self.nodes.len() && self.nodes[from].0 < points[i] - reach {
                    from += 1;
                }
                mark_from(i, from);
            }
        } else {
            for (i, &xi) in points.iter().enumerate() {
                mark_from(i, self.nodes.partition_point(|n| n.0 < xi - reach));
            }
        }
        near_all.sort_unstable();
        near_all.dedup();
        let mut near_rest = near_all.as_slice();
        for (v, ((x, cx), sum)) in x_lanes.iter().zip(cx_lanes).zip(sum_lanes).enumerate() {
            let here = near_rest.iter().take_while(|n| n.0 == v).count();
            let (near, rest) = near_rest.split_at(here);
            near_rest = rest;
            // A node's numerator and distance; masked, a skipped node's as 0 and 1. (Macros,
            // not closures: a closure that is not inlined is compiled without the lanes'
            // instruction set, and each SIMD operation becomes a call.)
            macro_rules! term {
                ($node:expr) => {{
                    let (t, wq, chi) = $node;
                    let d = simd.sub_f64s(simd.splat_f64s(t), *x);
                    let weight = simd.sub_f64s(simd.splat_f64s(chi), *cx);
                    (simd.mul_f64s(simd.splat_f64s(wq), weight), d)
                }};
                ($node:expr, masked) => {{
                    let (n, d) = term!($node);
                    let keep = simd.greater_than_f64s(simd.abs_f64s(d), tiny);
                    (
                        simd.select_f64s(keep, n, zero),
                        simd.select_f64s(keep, d, one),
                    )
                }};
            }
            let mut acc = *sum;
            // The groups up to the next near one without masks, that one with them (two loops:
            // one with a branch between the two forms is compiled with the masks in both).
            let (mut first, mut near) = (0, near.iter());
            loop {
                let stop = near.next().map_or(count, |&(_, g)| g);
                for group in
                    self.nodes[first * FADE_GROUP..stop * FADE_GROUP].chunks_exact(FADE_GROUP)
                {
                    let (num, den) = group_quotient!([term!(group[0]), term!(group[1])], mul, add);
                    acc = simd.add_f64s(acc, simd.div_f64s(num, den));
                }
                if stop == count {
                    break;
                }
                let group = &self.nodes[stop * FADE_GROUP..(stop + 1) * FADE_GROUP];
                let terms = [term!(group[0], masked), term!(group[1], masked)];
                let (num, den) = group_quotient!(terms, mul, add);
                acc = simd.add_f64s(acc, simd.div_f64s(num, den));
                first = stop + 1;
            }
            for &node in single {
                let (n, d) = term!(node, masked);
                acc = simd.add_f64s(acc, simd.div_f64s(n, d));
            }
            *sum = acc;
        }
        for ((&x, &cx), sum) in x_tail.iter().zip(cx_tail).zip(sum_tail) {
            *sum = fade_sum(self.nodes, x, cx, self.tiny);
        }
    }
}

/// Nodes over one denominator in the fade sums ([`fade_sum`]).
const FADE_GROUP: usize = 2;

/// `n₁/d₁ + n₂/d₂` of two terms `[(n_k, d_k)]` as one numerator and denominator,
/// `(n₁d₂ + n₂d₁, d₁d₂)`, in a fixed order of multiplications and additions (`mul`, `add`),
/// written out where it is used (the one-point and the SIMD sums of [`fade_sum`]).
macro_rules! group_quotient {
    ($terms:expr, $mul:expr, $add:expr) => {{
        let [(n1, d1), (n2, d2)] = $terms;
        ($add($mul(n1, d2), $mul(n2, d1)), $mul(d1, d2))
    }};
}
use group_quotient;

/// `Σ w q̃_E(t) (χ(t) − χ(x))/(t − x)` over `nodes`, skipping a node within `tiny` of x.
///
/// The divisions bound these sums, so the nodes are taken in pairs over a common
/// denominator (`group_quotient`; a skipped node as `n = 0, d = 1`): one division for two
/// terms, with a rounding error of the same order as the two quotients' (the distances are at
/// least `tiny`, so their products stay far above f64's smallest normal number). Where no
/// node is near, the SIMD sums (`FadeSums`) run without the skipped nodes' masks. Pairs are
/// the sweet spot: groups of four over one denominator save no further time.
#[inline(always)]
fn fade_sum(nodes: &[(f64, f64, f64)], x: f64, cx: f64, tiny: f64) -> f64 {
    let term = |&(t, wq, chi): &(f64, f64, f64)| {
        let d = t - x;
        if d.abs() > tiny {
            (wq * (chi - cx), d)
        } else {
            (0.0, 1.0)
        }
    };
    let groups = nodes.chunks_exact(FADE_GROUP);
    let single = groups.remainder();
    let mut acc = -0.0;
    for group in groups {
        let terms: [_; FADE_GROUP] = std::array::from_fn(|k| term(&group[k]));
        let (num, den) = group_quotient!(terms, |a: f64, b| a * b, |a: f64, b| a + b);
        acc += num / den;
    }
    for node in single {
        let (n, d) = term(node);
        acc += n / d;
    }
    acc
}

impl PartialEq for Inherited {
    fn eq(&self, other: &Self) -> bool {
        self.zone == other.zone && self.ramp_lo == other.ramp_lo && self.ramp_hi == other.ramp_hi
    }
}

/// The slip shape between the signs `[left, right]` beside a stick zone `[lo, hi]`:
/// `s_L + (s_R − s_L)(3v² − 2v³)`, `v = (x − lo)/(hi − lo)` clamped to [0, 1].
pub(super) fn sign_blend([left, right]: [f64; 2], lo: f64, hi: f64, x: f64) -> f64 {
    let v = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    left + (right - left) * v * v * (3.0 - 2.0 * v)
}

pub(crate) fn smootherstep(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    v * v * v * (v * (6.0 * v - 15.0) + 10.0)
}

impl Inherited {
    /// The earlier zone carried whole or faded by the given ramps.
    pub fn new(
        zone: std::sync::Arc<StickZone>,
        ramp_lo: Option<(f64, f64)>,
        ramp_hi: Option<(f64, f64)>,
    ) -> Self {
        Self {
            zone,
            ramp_lo,
            ramp_hi,
            table: std::sync::OnceLock::new(),
        }
    }

    fn table(&self) -> &FadeTable {
        self.table.get_or_init(|| {
            let rule = graded_rule_with(FADE_RULE_NODES);
            let (nodes, weights) = (&rule.nodes, &rule.weights);
            let mut points = Vec::new();
            let mut scaled_weights = Vec::new();
            // In increasing t: the pieces increase, the rule's nodes decrease.
            for w in self.pieces().windows(2) {
                let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
                for (u, wt) in nodes.iter().zip(weights).rev() {
                    points.push(mid + half * u);
                    scaled_weights.push(wt * half);
                }
            }
            let mut values = Vec::with_capacity(points.len());
            self.zone.corrections_into(&points, &mut values);
            let all: Vec<(f64, f64, f64)> = points
                .iter()
                .zip(&scaled_weights)
                .zip(&values)
                .map(|((&t, &w), &q)| (t, w * q, self.chi(t)))
                .collect();
            FadeTable::new(all)
        })
    }

    /// The fade factor χ(x).
    pub fn chi(&self, x: f64) -> f64 {
        let up = self
            .ramp_lo
            .map_or(1.0, |(a, b)| smootherstep((x - a) / (b - a)));
        let down = self
            .ramp_hi
            .map_or(1.0, |(a, b)| 1.0 - smootherstep((x - a) / (b - a)));
        up * down
    }

    /// The start and end points of the fade ramps.
    pub(super) fn ramp_points(&self) -> impl Iterator<Item = f64> + use<> {
        [self.ramp_lo, self.ramp_hi]
            .into_iter()
            .flatten()
            .flat_map(|r| [r.0, r.1])
    }

    pub(super) fn faded(&self) -> bool {
        self.ramp_lo.is_some() || self.ramp_hi.is_some()
    }

    /// `χ q̃_E` at x.
    pub fn value(&self, x: f64) -> f64 {
        if self.faded() {
            let chi = self.chi(x);
            if chi.abs() > 0.0 {
                chi * self.zone.correction_at(x)
            } else {
                0.0
            }
        } else {
            self.zone.correction_at(x)
        }
    }

    /// [`Self::value`] at each of `xs` into `out` (bit-identical, the zone's values in a batch,
    /// [`StickZone::corrections_into`], at the points where χ ≠ 0 only).
    pub fn values_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        if !self.faded() {
            self.zone.corrections_into(xs, out);
            return;
        }
        let chis: Vec<f64> = xs.iter().map(|&x| self.chi(x)).collect();
        *out = faded(xs, &chis, |points, values| {
            self.zone.corrections_into(points, values)
        });
    }

    /// The remembered stick ends strictly inside `(lo, hi)` where this link's q̃ (with its
    /// chain) starts like a square root ([`RememberedRoot`]). A point already listed by an
    /// outer zone (a return to a remembered end) is not repeated.
    pub fn interior_roots(&self, lo: f64, hi: f64) -> Vec<RememberedRoot> {
        let mut out: Vec<RememberedRoot> = Vec::new();
        let slack = 1e-9 * (hi - lo);
        let outer = &self.zone;
        let mut factors: Vec<&Inherited> = Vec::new();
        let mut link = Some(self);
        while let Some(l) = link {
            factors.push(l);
            let z = &l.zone;
            for (j, (x0, side)) in [(z.lo, -1.0), (z.hi, 1.0)].into_iter().enumerate() {
                let root = z.end_roots[j] * factors.iter().map(|f| f.chi(x0)).product::<f64>();
                if x0 > lo + slack
                    && x0 < hi - slack
                    && root.abs() > 0.0
                    && out.iter().all(|o| (o.at - x0).abs() > slack)
                {
                    out.push(RememberedRoot {
                        at: x0,
                        side,
                        root,
                        sign: z.end_signs[j],
                        carried_sign: if factors.len() == 1 {
                            z.end_signs[j]
                        } else {
                            outer.end_sign_shape(x0)
                        },
                    });
                }
            }
            link = z.inherited.as_deref();
        }
        out
    }

    /// Breakpoints of the quadrature over the earlier zone.
    fn pieces(&self) -> Vec<f64> {
        let mut pts = vec![self.zone.lo];
        let mut inner = self.zone.chain_points();
        inner.extend(self.ramp_points());
        let (lo, hi) = (self.zone.lo, self.zone.hi);
        let gap = 1e-9 * (hi - lo);
        for v in inner {
            if v > lo + gap && v < hi - gap {
                pts.push(v);
            }
        }
        pts.push(self.zone.hi);
        pts.sort_by(f64::total_cmp);
        pts.dedup_by(|x, y| (*x - *y).abs() <= gap);
        pts
    }

    /// `H'(χ q̃_E)(x) = χ(x) H'q̃_E(x) + (1/π)∫ (χ(t) − χ(x)) q̃_E(t)/(t − x) dt`.
    pub fn cauchy(&self, x: f64) -> f64 {
        if !self.faded() {
            return self.zone.correction_cauchy(x);
        }
        let cx = self.chi(x);
        let sum = fade_sum(self.table().nodes_for(cx), x, cx, self.fade_tiny());
        let own = if cx.abs() > 0.0 {
            cx * self.zone.correction_cauchy(x)
        } else {
            0.0
        };
        own + sum / std::f64::consts::PI
    }

    /// Nodes closer than this to a point are left out of its fade sum.
    fn fade_tiny(&self) -> f64 {
        1e-14 * (self.zone.hi - self.zone.lo)
    }

    /// [`Self::cauchy`] at each of `xs` into `out` (bit-identical: the points whose χ picks
    /// the same node list share one pass over it in SIMD lanes, `FadeSums`, each point's
    /// terms summed in the same order; a skipped node adds −0, which leaves any sum
    /// unchanged; the test `batched_fields_equal_the_one_point_fields` compares the bits).
    pub fn cauchy_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if !self.faded() {
            self.zone.correction_cauchys_into(xs, out);
            return;
        }
        let (tiny, table) = (self.fade_tiny(), self.table());
        let chis: Vec<f64> = xs.iter().map(|&x| self.chi(x)).collect();
        // The fade sums first (left in `out`): the points grouped by the node list their χ
        // picks, each group's sums in SIMD lanes (`FadeSums`), ...
        out.resize(xs.len(), 0.0);
        let arch = pulp::Arch::new();
        for list in [&table.not_one, &table.not_zero, &table.all] {
            let members: Vec<usize> = (0..xs.len())
                .filter(|&k| std::ptr::eq(table.nodes_for(chis[k]), list.as_slice()))
                .collect();
            if members.is_empty() {
                continue;
            }
            let x: Vec<f64> = members.iter().map(|&k| xs[k]).collect();
            let cx: Vec<f64> = members.iter().map(|&k| chis[k]).collect();
            let mut sums = vec![-0.0; members.len()];
            arch.dispatch(FadeSums {
                nodes: list,
                x: &x,
                cx: &cx,
                tiny,
                sums: &mut sums,
            });
            for (&k, sum) in members.iter().zip(sums) {
                out[k] = sum;
            }
        }
        // ... then χ H'q̃_E where χ ≠ 0, the zone's transform in one batch.
        let own = faded(xs, &chis, |points, transforms| {
            self.zone.correction_cauchys_into(points, transforms)
        });
        for (sum, own) in out.iter_mut().zip(own) {
            *sum = own + *sum / std::f64::consts::PI;
        }
    }

    /// `∫ χ q̃_E dx`.
    pub fn integral(&self) -> f64 {
        if !self.faded() {
            return self.zone.correction_integral();
        }
        // The fade table holds `w q̃_E` and χ on the same graded nodes.
        self.table().all.iter().map(|(_, wq, chi)| wq * chi).sum()
    }
}

/// `χ f` at each of `xs` (with χ there `chis`): `zone(points, out)`, a batch evaluation of
/// the zone's part, is called once with the points where χ ≠ 0; elsewhere the value is zero.
fn faded(xs: &[f64], chis: &[f64], zone: impl FnOnce(&[f64], &mut Vec<f64>)) -> Vec<f64> {
    let points: Vec<f64> = xs
        .iter()
        .zip(chis)
        .filter(|(_, chi)| chi.abs() > 0.0)
        .map(|(&x, _)| x)
        .collect();
    let mut values = Vec::with_capacity(points.len());
    zone(&points, &mut values);
    let mut values = values.into_iter();
    chis.iter()
        .map(|&chi| {
            if chi.abs() > 0.0 {
                chi * values.next().expect("one value per point with χ ≠ 0")
            } else {
                0.0
            }
        })
        .collect()
}

/// A remembered stick end inside a new stick zone, where q̃ starts like a square root (the
/// tangential module docs, "Kinks at the stick ends").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RememberedRoot {
    /// The point (m).
    pub at: f64,
    /// −1 at a remembered zone's left end (`q̃ ≈ root √(x − at)`), +1 at its right end.
    pub side: f64,
    /// The root coefficient (Pa/√m), times the fades of the links in between.
    pub root: f64,
    /// The slip sign beside the end when the root formed.
    pub sign: f64,
    /// The slip sign S at the point of the outermost inherited zone, whose q̃ already carries
    /// the root `(sign − S) η A` of p's kink beyond the point.
    pub carried_sign: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fade sums in SIMD lanes are the one-point sums to the bit, with points that lie on
    /// a node, within `tiny` of one, within twice `tiny` (the masked groups) and elsewhere, in
    /// vectors and in the lanes' tail, in no order and in increasing and decreasing order (the
    /// two ways of finding the near nodes); a node on a point is left out (the sum stays
    /// finite).
    #[test]
    fn fade_sums_in_lanes_equal_the_one_point_sums() {
        let tiny = 1e-14;
        let nodes: Vec<(f64, f64, f64)> = (0..37)
            .map(|k| {
                let t = -1.0 + 2.0 * (k as f64 + 0.5) / 37.0;
                (t, 0.05 * (1.0 + t * t), 0.5 + 0.5 * (2.0 * t).sin())
            })
            .collect();
        let on = |k: usize| nodes[k].0;
        let x = vec![
            on(3),
            on(10) + 0.5 * tiny,
            on(11) - 1.5 * tiny,
            0.123,
            on(36),
            on(0) - 0.7 * tiny,
            -0.45,
            0.9,
            on(20) + 3.0 * tiny,
            0.31,
            on(17),
        ];
        let chi = |t: f64| 0.4 + 0.3 * t;
        let lanes = |x: &[f64]| {
            let cx: Vec<f64> = x.iter().map(|&t| chi(t)).collect();
            let mut sums = vec![-0.0; x.len()];
            pulp::Arch::new().dispatch(FadeSums {
                nodes: &nodes,
                x,
                cx: &cx,
                tiny,
                sums: &mut sums,
            });
            sums
        };
        // In no order (a bisection per point), increasing and decreasing (one walk).
        let mut increasing = x.clone();
        increasing.sort_by(f64::total_cmp);
        let decreasing: Vec<f64> = increasing.iter().rev().copied().collect();
        for points in [&x, &increasing, &decreasing] {
            for (&xi, &sum) in points.iter().zip(&lanes(points)) {
                let one = fade_sum(&nodes, xi, chi(xi), tiny);
                assert_eq!(sum.to_bits(), one.to_bits(), "at {xi}: {sum} vs {one}");
                assert!(sum.is_finite(), "at {xi}");
            }
        }
        // The skipped node is really left out: against the sum without it.
        let rest: Vec<_> = [&nodes[..3], &nodes[4..]].concat();
        let without = fade_sum(&rest, x[0], chi(x[0]), tiny);
        let with_lanes = lanes(&x)[0];
        assert!(
            (with_lanes - without).abs() < 1e-13 * without.abs(),
            "{with_lanes} vs {without}"
        );
    }
}
