//! The quadrature over the contact's pieces: the points where a state or a step is not smooth
//! (the pieces' ends), the nodes per piece for M collocation points, and the sine-graded
//! Gauss–Legendre rules (`u = sin(πv/2)`, nodes clustered at both piece ends for the square-root
//! end behaviour), with their running integrals ([`graded_cumulative`]).

use super::ContactState;

/// Where the strain change between two states is not smooth: both states' traction
/// breakpoints and both contact ends (the old end lies inside a slip zone of the new state
/// when the contact grows or shifts).
pub fn step_breakpoints(old: &ContactState, new: &ContactState) -> Vec<f64> {
    let mut breaks = new.traction_breakpoints();
    breaks.extend(old.traction_breakpoints());
    for s in [old, new] {
        breaks.extend([s.centre - s.half_width, s.centre + s.half_width]);
    }
    breaks
}

/// The ends of the quadrature pieces: `points` sorted and deduplicated, then every piece more
/// than three times as long as a neighbour halved until none is. A singular point at the end
/// of a short piece lies just outside its long neighbour, at a distance small against that
/// neighbour's length, where a fixed rule converges slowly (measured: 1.6e−3 between the 32-
/// and 96-node rules on such a piece of the dissipation integral, 0.048a long with the
/// neighbouring stick end 0.003a beyond it); after halving, every singular point is at least
/// about a third of a piece length away from the pieces it does not end.
pub(super) fn piece_ends(points: Vec<f64>) -> Vec<f64> {
    balanced_ends(points).into_iter().map(|(x, _)| x).collect()
}

/// [`piece_ends`], each end with whether it was made by the halving (`true`) rather than
/// given.
fn balanced_ends(points: Vec<f64>) -> Vec<(f64, bool)> {
    let mut points: Vec<(f64, bool)> = points.into_iter().map(|x| (x, false)).collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points.dedup_by(|a, b| (a.0 - b.0).abs() <= 0.0);
    loop {
        let lengths: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
        let too_long = |i: usize| {
            let neighbour = [i.checked_sub(1), (i + 1 < lengths.len()).then_some(i + 1)]
                .into_iter()
                .flatten()
                .map(|j| lengths[j])
                .fold(f64::INFINITY, f64::min);
            lengths[i] > 3.0 * neighbour
        };
        let split: Vec<(f64, bool)> = (0..lengths.len())
            .filter(|&i| too_long(i))
            .map(|i| (0.5 * (points[i].0 + points[i + 1].0), true))
            .collect();
        if split.is_empty() {
            return points;
        }
        points.extend(split);
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
}

/// A function tabulated on the nodes of a graded rule's pieces, with running integrals.
#[derive(Debug, Clone, Default)]
pub struct GradedTable {
    /// `(x, weight, f(x), ∫ f from the first point to x)` for every node, in increasing x.
    pub nodes: Vec<(f64, f64, f64, f64)>,
    /// `∫ f` over all pieces.
    pub total: f64,
}

/// The most nodes a piece of the contact integrals' rule takes (δ, δn, the arcsine moment, the
/// shape force of mixed states; `contact_piece_nodes` gives short pieces fewer):
/// `max(32, M/2)`, since a piece holds a share of the M-term series and the stick zone, one
/// long piece, holds q̃'s whole series. Measured on the default history, M = 64 … 512, against
/// four times the nodes: δ within 9e−11 of its range (over the 22-run regression batch 1.5e−6,
/// in the insulating Figure-3 histories at M = 64). A fixed 32-node rule let δ err by 3e−7 of
/// its range at M = 128 and 1e−5 at M = 256, as much as the discretisation error of δ there.
pub fn field_rule_nodes(m: usize) -> usize {
    32.max(m / 2)
}

/// Nodes of the contact integrals' rule on the piece `[x0, x1]` of the contact `(c, a)`: in
/// proportion to the piece's share s of the contact in θ (`x = c + a cos θ`, the variable in
/// which the M-term series oscillate evenly), `8 s field_rule_nodes(M)` rounded up to a
/// multiple of 8, at least `CONTACT_PIECE_MIN_NODES` and at most `field_rule_nodes(M)`. The
/// long pieces and those at the contact ends keep the whole rule; the short pieces between
/// the chain's points get fewer. Measured over the 22-run regression batch against four
/// times [`field_rule_nodes`] on every piece (itself within 8.4e−12 of δ's range of eight
/// times): δ within 1.5e−8 of its range at M ≥ 96 (the whole rule: 4.3e−11), the geometry
/// (through φ0's arcsine moment) within 2.4e−11 a and the dissipation within 4e−9 of the
/// largest step dissipation, as with the whole rule (the stalled step 47 of the insulating
/// Figure-3 history at η = 0.4 aside, which moves with any change of round-off), for fewer
/// nodes on the pieces far from the contact ends.
pub(super) fn contact_piece_nodes(x0: f64, x1: f64, (c, a): (f64, f64), m: usize) -> usize {
    let most = field_rule_nodes(m);
    let theta = |x: f64| ((x - c) / a).clamp(-1.0, 1.0).acos();
    let share = (theta(x0) - theta(x1)).abs() / std::f64::consts::PI;
    ((8.0 * share * most as f64).ceil() as usize)
        .next_multiple_of(8)
        .clamp(CONTACT_PIECE_MIN_NODES.min(most), most)
}

/// The fewest nodes of a piece of the contact integrals' rule ([`contact_piece_nodes`]): a
/// short piece still carries square-root and logarithmic behaviour at its ends, so the rule
/// changes nothing at M ≤ 64. Measured over the regression batch against four times the whole
/// rule: with 16, δ erred by up to 2.2e−5 of its range (the insulating Figure-3 history at
/// M = 64) whatever the proportion (4, 8 or 16 × the share); with 24, by up to 6.1e−8 in
/// runs where the whole rule errs by 4.3e−11 or less; with 32, by up to 1.5e−8 (at M = 256;
/// 9.6e−9 at M = 128). δ's discretisation error is 1.5e−6 of its range at M = 128 (the
/// default history against M = 256).
const CONTACT_PIECE_MIN_NODES: usize = 32;

/// Nodes per piece of the graded rule over the slip zones (the dissipation):
/// `max(32, M/4)`; the slip zones are split into shorter pieces than the contact. Measured on
/// the default history, M = 64 … 512, against four times the nodes: step dissipations within
/// 5e−9 of themselves (the cycle's friction work the same to ten digits).
pub fn slip_zone_rule_nodes(m: usize) -> usize {
    32.max(m / 4)
}

/// Nodes of the plain Gauss–Legendre rule on the smooth pieces of the dissipation's rule (both
/// ends made by the balancing, [`graded_cumulative`]): half of [`slip_zone_rule_nodes`], 16
/// at M ≤ 128.
pub fn slip_zone_smooth_nodes(m: usize) -> usize {
    smooth_piece_nodes(slip_zone_rule_nodes(m))
}

/// Nodes per piece of the slip check's rule (the slip increments whose sign the step's check
/// reads, [`tangential::assess_step`]): a quarter of [`slip_zone_rule_nodes`], 8 at M ≤ 128.
/// The check only needs the sign, to 1e−2 of the largest slip of the step. Measured over the
/// 22 scenarios of the regression batch (M = 64 … 256, coupled and uncoupled, many cycles and
/// variable amplitude) against eight times the nodes: the worst check measure within 1.2e−4,
/// every state unchanged; half of [`slip_zone_rule_nodes`] gave 1.3e−7 at 8 % more of a
/// forward step's solve at M = 128 (test `the_slip_check_rule_reads_the_sign_to_a_small_error`).
///
/// [`tangential::assess_step`]: super::tangential::assess_step
pub fn slip_check_rule_nodes(m: usize) -> usize {
    slip_zone_rule_nodes(m) / 4
}

/// The nodes and weights of a graded rule over the balanced pieces between `points` (none more
/// than three times as long as a neighbour, `piece_ends`), in increasing x, so that
/// `∫ f ≈ Σ weight f(node)` from the smallest to the largest of `points`: each piece `[x0, x1]`
/// by a `nodes(x0, x1)`-point sine-graded Gauss–Legendre rule (nodes clustered like Chebyshev
/// points at both ends, which absorbs square-root and logarithmic behaviour there: every point
/// where f is not smooth must be among `points`); a piece whose two ends the balancing made
/// by the plain rule of `smooth_piece_nodes` (as in [`graded_cumulative`]). Measured over
/// the regression batch against eight times the nodes on every piece: δ unchanged to two
/// digits in every run (1.5e−6 of its range at worst, the insulating Figure-3 histories at
/// M = 64; 9.6e−9 at M = 128); test `the_contact_rule_gives_the_displacements_to_a_small_error`.
pub fn graded_nodes(points: Vec<f64>, nodes: impl Fn(f64, f64) -> usize) -> (Vec<f64>, Vec<f64>) {
    let (mut at, mut weights) = (Vec::new(), Vec::new());
    for w in balanced_ends(points).windows(2) {
        let n = nodes(w[0].0, w[1].0);
        let rule = if w[0].1 && w[1].1 {
            plain_rule_with(smooth_piece_nodes(n))
        } else {
            graded_rule_with(n)
        };
        let (mid, half) = (0.5 * (w[0].0 + w[1].0), 0.5 * (w[1].0 - w[0].0));
        at.extend(rule.nodes.iter().map(|u| mid + half * u));
        weights.extend(rule.weights.iter().map(|wt| half * wt));
    }
    (at, weights)
}

/// Tabulate f on the `nodes`-point graded rule over the balanced pieces between `points` (as
/// [`graded_nodes`]) together with the running integral up to each node, from the
/// cumulative Gauss–Legendre matrix in the graded variable
/// ([`crate::quadrature::gauss_legendre_cumulative`]). Nested integrals such as
/// `∫ g(t) ∫_t^R f ds dt` then cost one evaluation of f per node: f is evaluated at all the
/// pieces' nodes in one call, `f(xs, out)` pushing the values at `xs` onto `out` (passed
/// empty).
///
/// With `smooth_nodes`, a piece whose two ends were both made by the balancing (`piece_ends`)
/// takes a plain Gauss–Legendre rule of that many nodes instead: no point where f is not
/// smooth ends it, and after the balancing every such point lies at least a third of the
/// piece's length beyond its ends (two thirds of its half-length), so f is analytic inside
/// the Bernstein ellipse with `ρ ≥ 5/3 + √(25/9 − 1) = 3` about the piece, and the n-point
/// rule errs by about `ρ^(−2n)` (5e−16 for 16 nodes). The sine-graded rule, whose clustering
/// at both ends pulls such a point towards the piece in its variable, needs more
/// (`piece_ends`' test: 1.3e−8 with 32 nodes for a logarithm at a third of the length).
pub fn graded_cumulative(
    points: Vec<f64>,
    nodes: usize,
    smooth_nodes: Option<usize>,
    f: &mut dyn FnMut(&[f64], &mut Vec<f64>),
) -> GradedTable {
    let graded = graded_rule_with(nodes);
    let pieces: Vec<(f64, f64, &GradedRule)> = balanced_ends(points)
        .windows(2)
        .map(|w| {
            let rule = match smooth_nodes {
                Some(n) if w[0].1 && w[1].1 => plain_rule_with(n),
                _ => graded,
            };
            (0.5 * (w[0].0 + w[1].0), 0.5 * (w[1].0 - w[0].0), rule)
        })
        .collect();
    let at: Vec<f64> = pieces
        .iter()
        .flat_map(|&(mid, half, rule)| rule.nodes.iter().map(move |u| mid + half * u))
        .collect();
    let mut all = Vec::with_capacity(at.len());
    f(&at, &mut all);
    let mut table = GradedTable::default();
    let mut values = all.as_slice();
    for &(mid, half, rule) in &pieces {
        let n = rule.nodes.len();
        let (here, rest) = values.split_at(n);
        values = rest;
        for k in 0..n {
            let row = &rule.cumulative[k * n..(k + 1) * n];
            let before: f64 = half * row.iter().zip(here).map(|(c, v)| c * v).sum::<f64>();
            table.nodes.push((
                mid + half * rule.nodes[k],
                rule.weights[k] * half,
                here[k],
                table.total + before,
            ));
        }
        table.total += half
            * rule
                .weights
                .iter()
                .zip(here)
                .map(|(w, v)| w * v)
                .sum::<f64>();
    }
    table
}

/// The graded rule with `nodes` points and its cumulative matrix, built once per size
/// ([`crate::cache`]).
pub(super) fn graded_rule_with(nodes: usize) -> &'static GradedRule {
    crate::cache::graded_rule(nodes)
}

/// Nodes of the plain rule on a smooth piece (both ends made by the balancing) of a rule that
/// gives its graded pieces `graded` nodes: half, at least 16 ([`graded_nodes`],
/// [`slip_zone_smooth_nodes`]).
fn smooth_piece_nodes(graded: usize) -> usize {
    (graded / 2).max(16)
}

/// The plain Gauss–Legendre rule with `nodes` points and its cumulative matrix (the smooth
/// pieces of [`graded_nodes`] and [`graded_cumulative`]), built once per size
/// ([`crate::cache`]).
fn plain_rule_with(nodes: usize) -> &'static GradedRule {
    crate::cache::plain_rule(nodes)
}

/// Nodes per piece of the graded rule of [`graded_rule`].
const GRADED_NODES: usize = 96;

/// Nodes per piece of the fade integral's graded rule ([`Inherited::cauchy`]), whose table is
/// rebuilt at every residual evaluation (its pieces end at the fade ramps, which move with the
/// stick ends). Measured on the regression batch of `docs/performance.md` against 192 nodes:
/// 64 nodes move the stick ends by at most 1.5e−9 a at M = 128 and 1.4e−8 a at M = 256
/// (the first loading, whose base zone carries the normal-loading centre kink), every other
/// phase by at most 1e−8 a, and the histories' dissipation by at most 5e−9 of itself; 96 nodes
/// (the other graded rules') 6.5e−9 a at M = 256 and 0 at M = 128. 48 nodes: 8e−8 a at
/// M = 128 and 4e−7 a where a remembered stick end lies close to the new one; 32 nodes
/// changed the dissipation of the insulating Figure-3 history by 7.6e−4. The stall of step 47
/// of its η = 0.4 variant moves with any change of round-off and is left out of these figures.
/// 64 nodes are therefore the fewest that keep the errors below the discretisation's.
///
/// [`Inherited::cauchy`]: super::Inherited::cauchy
pub(super) const FADE_RULE_NODES: usize = 64;

/// A sine-graded Gauss–Legendre rule on [−1, 1] (`u = sin(πv/2)`, see [`graded_rule`]) with
/// its cumulative matrix.
pub(crate) struct GradedRule {
    pub(super) nodes: Vec<f64>,
    pub(super) weights: Vec<f64>,
    /// Row k: the weights of `∫_{-1}^{u_k}` in the graded variable, row-major n × n.
    cumulative: Vec<f64>,
}

impl GradedRule {
    pub(crate) fn new(n: usize) -> Self {
        let (v, w) = crate::quadrature::gauss_legendre(n);
        let s = crate::quadrature::gauss_legendre_cumulative(n);
        let half_pi = std::f64::consts::FRAC_PI_2;
        // Row k: ∫_{-1}^{v_k} h(v) dv with h = f(x(v)) x'(v), x'(v) = half (π/2) cos(πv/2).
        let cumulative = (0..n * n)
            .map(|kj| s[kj] * half_pi * (half_pi * v[kj % n]).cos())
            .collect();
        Self {
            nodes: v.iter().map(|v| (half_pi * v).sin()).collect(),
            weights: v
                .iter()
                .zip(&w)
                .map(|(v, w)| w * half_pi * (half_pi * v).cos())
                .collect(),
            cumulative,
        }
    }

    /// The plain n-point Gauss–Legendre rule with its cumulative matrix (no grading).
    pub(crate) fn plain(n: usize) -> Self {
        let (nodes, weights) = crate::quadrature::gauss_legendre(n);
        Self {
            nodes,
            weights,
            cumulative: crate::quadrature::gauss_legendre_cumulative(n),
        }
    }
}

/// Sine-graded Gauss–Legendre rule on [−1, 1] with `GRADED_NODES` nodes: `u = sin(πv/2)`,
/// nodes clustered like Chebyshev points at both ends (resolves √ end behaviour and
/// near-singular quotients). Returns `(nodes, weights)`.
pub fn graded_rule() -> (&'static [f64], &'static [f64]) {
    let rule = graded_rule_with(GRADED_NODES);
    (&rule.nodes, &rule.weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piece_ends_keep_every_point_and_balance_neighbours() {
        // A long piece next to a short one (a stick end 0.003 beyond a ramp end) is halved
        // until no piece is more than three times as long as a neighbour.
        let given = vec![-0.569840, -0.522144, -0.518976, 0.4, 0.4, -0.988128];
        let ends = piece_ends(given.clone());
        for p in &given {
            assert!(ends.contains(p), "{p} kept");
        }
        assert!(
            ends.windows(2).all(|w| w[1] > w[0]),
            "sorted, no duplicates"
        );
        let lengths: Vec<f64> = ends.windows(2).map(|w| w[1] - w[0]).collect();
        for pair in lengths.windows(2) {
            assert!(
                pair[0] <= 3.0 * pair[1] && pair[1] <= 3.0 * pair[0],
                "{pair:?}"
            );
        }
        // Halving only: a few extra points per decade of length ratio, not a uniform grid.
        assert!(ends.len() < 30, "{} ends", ends.len());
        // What the balance is for: ∫ ln|x − x0| over the pieces, x0 the end of the short piece
        // and so just outside the long one. 32-node rule: relative error 1.3e−8 balanced,
        // 1.1e−6 with the given pieces (measured); the bound is 1e−7.
        let x0 = -0.518976;
        let primitive = |x: f64| (x - x0) * (x - x0).abs().ln() - (x - x0);
        let want = primitive(0.4) - primitive(-0.988128);
        let mut log = |xs: &[f64], out: &mut Vec<f64>| {
            out.extend(xs.iter().map(|x| (x - x0).abs().ln()));
        };
        let table = graded_cumulative(given, 32, None, &mut log);
        let error = ((table.total - want) / want).abs();
        assert!(error < 1e-7, "relative error {error:e}");
    }
}
