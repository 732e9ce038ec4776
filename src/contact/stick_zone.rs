//! The stick zone `[lo, hi]` and its bounded correction q̃ ([`StickZone`]): its own series and
//! centre kink, the chain of corrections it inherits from earlier zones ([`Inherited`]), and
//! the piecewise Chebyshev tables (`ChainTable`) of q̃ and `H'q̃` that make a long chain cheap
//! to evaluate.

use serde::{Deserialize, Serialize};

use crate::quadrature::BoundedSeries;

use super::inherited::sign_blend;
use super::rules::piece_ends;
use super::{
    Inherited, half_ellipse, half_ellipse_cauchy, half_ellipse_integral, kink_cauchy, kink_density,
};

/// The stick zone `[lo, hi]` and the bounded correction `q̃` on it.
///
/// Written as plain data: its tables as the number of points they were built with, rebuilt
/// from the zone when it is read (`StickZoneData`), so a zone read back evaluates to the bit
/// as the one written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "StickZoneData")]
pub struct StickZone {
    /// Left end (m).
    pub lo: f64,
    /// Right end (m).
    pub hi: f64,
    /// Smooth part of `q̃((x − mid)/half)` (Pa).
    pub correction: BoundedSeries,
    /// Amplitude A of the kink part `A·k(u)` of q̃ (Pa), see [`kink_density`]; non-zero only
    /// for the normal-loading state, whose memory `C|x|` has a kink at the centre.
    pub kink: f64,
    /// Correction inherited from the state that began the phase; it carries the exact
    /// square-root structure of the memory at old stick ends (see [`Inherited`]).
    #[serde(with = "crate::shared::option")]
    pub inherited: Option<std::sync::Arc<Inherited>>,
    /// The square-root coefficients `[k_lo, k_hi]` of the whole q̃ at the ends,
    /// `q̃ ≈ k_lo √(x − lo)` and `q̃ ≈ k_hi √(hi − x)` (Pa/√m): they fix the kinks of p and w
    /// here and, once the zone is remembered, at its ends inside later stick zones. Zero for a
    /// zone solved without kinks (normal loading, uncoupled contacts).
    pub end_roots: [f64; 2],
    /// The slip signs beside the ends when the zone was solved (left, right).
    pub end_signs: [f64; 2],
    /// Closed-form parts of q̃ that carry the kinks of remembered stick ends inside the zone:
    /// `amplitude · √((x − u)(v − x))` on `[u, v]`, as `(u, v, amplitude)` (tangential module
    /// docs, "Kinks at the stick ends").
    pub extras: Vec<(f64, f64, f64)>,
    /// `H'q̃` tabulated once the zone begins a phase ([`StickZone::tabulate`]).
    pub(super) cauchy_table: TableCache,
    /// q̃ tabulated with it.
    #[serde(skip_serializing)]
    pub(super) value_table: TableCache,
    /// Which of the tables above the zone may build (written only when not all).
    #[serde(skip_serializing_if = "ZoneTables::all")]
    pub tables: ZoneTables,
}

/// Which tables a [`StickZone`] may build: [`StickZone::tabulate`]'s piecewise tables of
/// `H'q̃` and q̃ (`chain`), in [`Default`]; a zone that may not evaluates its chain directly
/// ([`crate::contact::tangential::Accelerations`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ZoneTables {
    /// [`StickZone::tabulate`]'s tables.
    pub chain: bool,
}

impl Default for ZoneTables {
    fn default() -> Self {
        Self { chain: true }
    }
}

impl ZoneTables {
    /// Whether every table is allowed.
    fn all(&self) -> bool {
        self.chain
    }
}

/// A [`StickZone`] as written: its data, and whether [`StickZone::tabulate`]'s tables were
/// built (the points per piece), rebuilt on reading.
/// A table is a function of the zone and of its chain, whose zones are read (and tabulated)
/// first and were tabulated before any zone inherited from them.
#[derive(Deserialize)]
struct StickZoneData {
    lo: f64,
    hi: f64,
    correction: BoundedSeries,
    kink: f64,
    #[serde(with = "crate::shared::option")]
    inherited: Option<std::sync::Arc<Inherited>>,
    end_roots: [f64; 2],
    end_signs: [f64; 2],
    extras: Vec<(f64, f64, f64)>,
    cauchy_table: Option<usize>,
    #[serde(default)]
    tables: ZoneTables,
}

impl From<StickZoneData> for StickZone {
    fn from(d: StickZoneData) -> Self {
        let zone = Self {
            inherited: d.inherited,
            end_roots: d.end_roots,
            end_signs: d.end_signs,
            extras: d.extras,
            tables: d.tables,
            ..Self::new(d.lo, d.hi, d.correction, d.kink)
        };
        if let Some(nodes) = d.cauchy_table {
            zone.tabulate(nodes);
        }
        zone
    }
}

/// `H'q̃` of a zone with its whole chain, interpolated piecewise: on each piece between the
/// points where q̃ is not smooth (the zone's ends, its chain's zone ends and ramp points, a
/// centre kink), and on two outer pieces of the zone's width on either side, by a Chebyshev
/// series in the graded variable v (`x = mid + half sin(πv/2)`, which absorbs the square
/// roots at the piece ends). Outside the outer pieces the transform is evaluated directly.
/// The same form holds q̃ itself on the zone's pieces, less its centre kinks
/// (`StickZone::chain_kinks`), for a zone with a chain: one sum of `M + 32` terms instead of
/// one of M terms for every zone of the chain (in a steady cycle, four).
#[derive(Debug, Clone, Default)]
pub(super) struct ChainTable {
    /// Piece ends, increasing.
    ends: Vec<f64>,
    /// Chebyshev coefficients in v, one series per piece.
    coefficients: Vec<Vec<f64>>,
}

impl ChainTable {
    /// The table of f on the pieces between `ends`, `nodes` Chebyshev points per piece in the
    /// graded variable.
    fn interpolating(ends: Vec<f64>, nodes: usize, f: impl Fn(f64) -> f64) -> Self {
        let ChebyshevPoints { v, transforms } = ChebyshevPoints::of(nodes);
        let all: Vec<f64> = ends
            .windows(2)
            .flat_map(|w| {
                let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
                v.iter()
                    .map(move |v| mid + half * (std::f64::consts::FRAC_PI_2 * v).sin())
            })
            .map(f)
            .collect();
        // The coefficients `c_j = (2 − δ_j0)/N Σ_k f_k cos(j θ_k)`: a discrete cosine transform.
        let coefficients = all
            .chunks_exact(nodes)
            .map(|values| {
                let mut c = vec![0.0; nodes];
                c[0] = transforms.cosines(values, &mut c[1..]) / nodes as f64;
                for cj in &mut c[1..] {
                    *cj *= 2.0 / nodes as f64;
                }
                c
            })
            .collect();
        Self { ends, coefficients }
    }

    /// Chebyshev points per piece.
    fn nodes(&self) -> usize {
        self.coefficients.first().map_or(0, Vec::len)
    }

    /// The interpolated value at x, `None` outside the tabulated range.
    fn at(&self, x: f64) -> Option<f64> {
        let k = self.piece(x)?;
        Some(crate::quadrature::chebyshev_t_sum(
            &self.coefficients[k],
            self.graded(k, x),
        ))
    }

    /// The piece that holds x, `None` outside the tabulated range.
    fn piece(&self, x: f64) -> Option<usize> {
        let (first, last) = (*self.ends.first()?, *self.ends.last()?);
        if !(x >= first && x <= last) {
            return None;
        }
        Some(
            self.ends
                .partition_point(|e| *e <= x)
                .clamp(1, self.ends.len() - 1)
                - 1,
        )
    }

    /// The graded variable v of x on piece k.
    fn graded(&self, k: usize, x: f64) -> f64 {
        let (mid, half) = (
            0.5 * (self.ends[k] + self.ends[k + 1]),
            0.5 * (self.ends[k + 1] - self.ends[k]),
        );
        ((x - mid) / half).clamp(-1.0, 1.0).asin() / std::f64::consts::FRAC_PI_2
    }

    /// [`Self::at`] at each of `xs` into `out`, `fallback(x)` outside the table (bit-identical;
    /// eight, else four, consecutive points on one piece share one sum, their recurrences
    /// interleaved, because the recurrences are latency-bound; each point's piece is found
    /// once).
    fn values_into(&self, xs: &[f64], fallback: impl Fn(f64) -> f64, out: &mut Vec<f64>) {
        let pieces: Vec<Option<usize>> = xs.iter().map(|&x| self.piece(x)).collect();
        let run = |k: usize, len: usize| {
            pieces[k].is_some()
                && k + len <= xs.len()
                && pieces[k + 1..k + len].iter().all(|p| *p == pieces[k])
        };
        let mut k = 0;
        while k < xs.len() {
            match pieces[k] {
                Some(p) if run(k, 8) => {
                    let v: [f64; 8] = std::array::from_fn(|l| self.graded(p, xs[k + l]));
                    out.extend(crate::quadrature::chebyshev_t_sums(
                        &self.coefficients[p],
                        v,
                    ));
                    k += 8;
                }
                Some(p) if run(k, 4) => {
                    let v: [f64; 4] = std::array::from_fn(|l| self.graded(p, xs[k + l]));
                    out.extend(crate::quadrature::chebyshev_t_sums(
                        &self.coefficients[p],
                        v,
                    ));
                    k += 4;
                }
                _ => {
                    out.push(self.at(xs[k]).unwrap_or_else(|| fallback(xs[k])));
                    k += 1;
                }
            }
        }
    }
}

/// The Chebyshev points `v_k = cos θ_k`, `θ_k = (2k+1)π/(2N)`, of a [`ChainTable`]'s pieces
/// and the fast transform of its cosine sums, built once per N ([`crate::cache`]): computing
/// the N² cosines for every table would cost far more than the transform that uses them.
pub(crate) struct ChebyshevPoints {
    v: Vec<f64>,
    transforms: crate::transforms::HalfAngleTransforms,
}

impl ChebyshevPoints {
    fn of(nodes: usize) -> &'static Self {
        crate::cache::chebyshev_points(nodes)
    }

    /// The points and transform for N = `n`.
    pub(crate) fn new(n: usize) -> Self {
        let theta = |k: usize| (2 * k + 1) as f64 * std::f64::consts::PI / (2 * n) as f64;
        Self {
            v: (0..n).map(|k| theta(k).cos()).collect(),
            transforms: crate::transforms::HalfAngleTransforms::new(n),
        }
    }
}

/// A cache filled at most once that takes no part in comparisons.
#[derive(Debug, Clone)]
pub(super) struct TableCache<T = ChainTable>(std::sync::OnceLock<T>);

impl<T> Default for TableCache<T> {
    fn default() -> Self {
        Self(std::sync::OnceLock::new())
    }
}

impl<T> PartialEq for TableCache<T> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Written as the points per piece it was built with (`null` when not built).
impl Serialize for TableCache {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.0.get().map(ChainTable::nodes).serialize(serializer)
    }
}

/// Collocation points a fade ramp over a short overlap must hold ([`StickZone::inheritance_for`]):
/// enough for the series to absorb the ramp's shape. At M = 48 a quarter-overlap ramp with about
/// five points made steps worse than leaving the remembered kink to the series.
const FADE_POINTS: f64 = 6.0;

/// Points whose Chebyshev sums are interleaved in the batched evaluations of a zone's own part
/// ([`StickZone::own_parts_into`]) and of the contact's series
/// ([`ContactState::pressures_into`] and the like): the Clenshaw recurrences are
/// latency-bound, so eight independent points keep more of them in flight than four (sixteen
/// gain nothing more), with the same bits.
///
/// [`ContactState::pressures_into`]: super::ContactState::pressures_into
pub(super) const OWN_LANES: usize = 8;

/// A zone's own part in one form (density or Cauchy transform): the series at
/// [`OWN_LANES`] points, at one point, and the kink term ([`StickZone::own_parts_into`]).
type OwnForms = (
    fn(&BoundedSeries, [f64; OWN_LANES]) -> [f64; OWN_LANES],
    fn(&BoundedSeries, f64) -> f64,
    fn(f64) -> f64,
);

/// `f` at each of `xs` into `out`, L points at a time by `fl`, which must give `f`'s values
/// bit for bit (the L-point Chebyshev sums of [`crate::quadrature`]).
pub(super) fn in_chunks<const L: usize>(
    xs: &[f64],
    fl: impl Fn([f64; L]) -> [f64; L],
    f: impl Fn(f64) -> f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    let mut chunks = xs.chunks_exact(L);
    for c in chunks.by_ref() {
        out.extend(fl(std::array::from_fn(|l| c[l])));
    }
    out.extend(chunks.remainder().iter().map(|&x| f(x)));
}

impl StickZone {
    /// A zone with its own correction only.
    pub fn new(lo: f64, hi: f64, correction: BoundedSeries, kink: f64) -> Self {
        Self {
            lo,
            hi,
            correction,
            kink,
            inherited: None,
            end_roots: [0.0; 2],
            end_signs: [0.0; 2],
            extras: Vec::new(),
            cauchy_table: TableCache::default(),
            value_table: TableCache::default(),
            tables: ZoneTables::default(),
        }
    }

    /// The slip-shape S at x from the slip signs beside the ends when the zone was solved
    /// (the smoothstep of [`ContactState::slip_shape`]).
    ///
    /// [`ContactState::slip_shape`]: super::ContactState::slip_shape
    pub fn end_sign_shape(&self, x: f64) -> f64 {
        sign_blend(self.end_signs, self.lo, self.hi, x)
    }

    /// Tabulate `H'q̃` and q̃ (see `ChainTable`) for a zone that will be evaluated many times
    /// (one that a phase inherits from), with `nodes` Chebyshev points per piece. No-op if
    /// already done, or if the zone may not build them ([`ZoneTables::chain`]).
    pub fn tabulate(&self, nodes: usize) {
        if !self.tables.chain {
            return;
        }
        let width = self.hi - self.lo;
        let slack = 1e-12 * width;
        let mut inner = self.chain_points();
        inner.retain(|&x| x > self.lo + slack && x < self.hi - slack);
        self.cauchy_table.0.get_or_init(|| {
            let mut points = vec![self.lo - width, self.lo, self.hi, self.hi + width];
            points.extend(&inner);
            ChainTable::interpolating(piece_ends(points), nodes, |x| self.direct_cauchy(x))
        });
        // A zone without a chain sums its own series faster than a table of more terms.
        if self.inherited.is_none() {
            return;
        }
        self.value_table.0.get_or_init(|| {
            let mut points = vec![self.lo, self.hi];
            points.extend(&inner);
            let smooth = |x| self.direct_correction(x) - self.chain_kinks(x);
            ChainTable::interpolating(piece_ends(points), nodes, smooth)
        });
    }

    /// q̃ at x (Pa), including the inherited chain; zero outside the zone (the zones a chain
    /// carries whole lie inside it, and the faded ones are faded out at its ends).
    pub fn correction_at(&self, x: f64) -> f64 {
        if !(x > self.lo && x < self.hi) {
            return 0.0;
        }
        match self.value_table.0.get() {
            Some(table) => table.at(x).unwrap_or(0.0) + self.chain_kinks(x),
            None => self.direct_correction(x),
        }
    }

    /// The centre kinks' part of q̃ at x inside the zone: `kink · k(u)` of every zone of the
    /// chain that carries one, times the fades of the links above it. Its `u ln|u|` at the
    /// kink point is left out of the value table, which interpolates the smooth rest (with it
    /// the table was off by 1e−8 of the largest q̃ at the kink point, 2e−10 at 1e−3 of the
    /// zone's width from it).
    fn chain_kinks(&self, x: f64) -> f64 {
        let own = |zone: &StickZone| {
            if zone.kink.abs() > 0.0 && x > zone.lo && x < zone.hi {
                zone.kink * kink_density((x - zone.mid()) / zone.half())
            } else {
                0.0
            }
        };
        let mut total = own(self);
        let mut fade = 1.0;
        for link in self.links() {
            if link.faded() {
                fade *= link.chi(x);
            }
            total += fade * own(&link.zone);
        }
        total
    }

    /// [`Self::correction_at`] inside the zone from the series and the chain.
    fn direct_correction(&self, x: f64) -> f64 {
        self.own_part(x, BoundedSeries::density, kink_density)
            + self.inherited.as_ref().map_or(0.0, |z| z.value(x))
            + self.extras_with(|u, v| half_ellipse(x, u, v))
    }

    /// [`Self::correction_at`] at each of `xs` into `out` (bit-identical; the own series is
    /// summed eight (`OWN_LANES`) points at a time, [`BoundedSeries::densities`], and the
    /// chain in batches). q̃ is zero outside the zone, so only the points inside are
    /// evaluated (the slip zones' points of a step's checks and integrals, the sample points
    /// beyond the stick ends).
    pub fn corrections_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let inside = |x: f64| x > self.lo && x < self.hi;
        if xs.iter().all(|&x| inside(x)) {
            self.corrections_inside(xs, out);
            return;
        }
        let points: Vec<f64> = xs.iter().copied().filter(|&x| inside(x)).collect();
        let mut values = Vec::with_capacity(points.len());
        self.corrections_inside(&points, &mut values);
        let mut values = values.into_iter();
        out.clear();
        out.extend(xs.iter().map(|&x| {
            if inside(x) {
                values.next().expect("one value per point inside")
            } else {
                0.0
            }
        }));
    }

    /// [`Self::corrections_into`] at points that all lie inside the zone.
    fn corrections_inside(&self, xs: &[f64], out: &mut Vec<f64>) {
        if let Some(table) = self.value_table.0.get() {
            table.values_into(xs, |_| 0.0, out);
            for (o, &x) in out.iter_mut().zip(xs) {
                *o = if x > self.lo && x < self.hi {
                    *o + self.chain_kinks(x)
                } else {
                    0.0
                };
            }
            return;
        }
        let many = BoundedSeries::densities::<OWN_LANES>;
        self.own_parts_into(xs, (many, BoundedSeries::density, kink_density), out);
        if let Some(link) = &self.inherited {
            let mut inner = Vec::with_capacity(xs.len());
            link.values_into(xs, &mut inner);
            for (o, v) in out.iter_mut().zip(inner) {
                *o += v;
            }
        }
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = if x > self.lo && x < self.hi {
                *o + self.extras_with(|u, v| half_ellipse(x, u, v))
            } else {
                0.0
            };
        }
    }

    /// [`Self::own_part`] at each of `xs` into `out` (bit-identical: the series [`OWN_LANES`]
    /// points at a time by `many`, the rest by `one`; the kink term through `kink`).
    fn own_parts_into(&self, xs: &[f64], (many, one, kink): OwnForms, out: &mut Vec<f64>) {
        let (mid, half) = (self.mid(), self.half());
        let own_many = |x: [f64; OWN_LANES]| {
            let u = x.map(|x| (x - mid) / half);
            let series = (!self.correction.beta.is_empty()).then(|| many(&self.correction, u));
            std::array::from_fn(|l| self.own_with(u[l], series.map(|s| s[l]), kink))
        };
        in_chunks(xs, own_many, |x| self.own_part(x, one, kink), out);
    }

    /// [`Self::own_part`] at u from the series' term there (`None` when the zone has no
    /// series) and the kink term through `kink`.
    fn own_with(&self, u: f64, series: Option<f64>, kink: fn(f64) -> f64) -> f64 {
        let mut own = 0.0;
        if let Some(s) = series {
            own += s;
        }
        if self.kink.abs() > 0.0 {
            own += self.kink * kink(u);
        }
        own
    }

    /// `Σ amplitude · f(u, v)` over the closed-form extras.
    fn extras_with(&self, f: impl Fn(f64, f64) -> f64) -> f64 {
        self.extras.iter().map(|&(u, v, amp)| amp * f(u, v)).sum()
    }

    /// `H'q̃(x)` (Pa), including the inherited chain (from [`Self::tabulate`]'s table when
    /// the zone has it).
    pub fn correction_cauchy(&self, x: f64) -> f64 {
        self.cauchy_table
            .0
            .get()
            .and_then(|table| table.at(x))
            .unwrap_or_else(|| self.direct_cauchy(x))
    }

    /// [`Self::correction_cauchy`] at each of `xs` into `out`, bit-identical (the own series
    /// eight (`OWN_LANES`) points at a time, [`BoundedSeries::cauchys`], and the chain's fade
    /// integrals in batches, [`Inherited::cauchy_into`]).
    pub fn correction_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        match self.cauchy_table.0.get() {
            Some(table) => {
                out.clear();
                table.values_into(xs, |x| self.direct_cauchy(x), out);
            }
            None => self.direct_cauchys_into(xs, out),
        }
    }

    /// [`Self::correction_cauchys_into`] from the series and the chain (no table).
    fn direct_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let many = BoundedSeries::cauchys::<OWN_LANES>;
        self.own_parts_into(xs, (many, BoundedSeries::cauchy, kink_cauchy), out);
        if let Some(link) = &self.inherited {
            let mut inner = Vec::with_capacity(xs.len());
            link.cauchy_into(xs, &mut inner);
            for (o, v) in out.iter_mut().zip(inner) {
                *o += v;
            }
        }
        for (o, &x) in out.iter_mut().zip(xs) {
            *o += self.extras_with(|u, v| half_ellipse_cauchy(x, u, v));
        }
    }

    /// `H'q̃(x)` from the series and the chain.
    fn direct_cauchy(&self, x: f64) -> f64 {
        self.own_part(x, BoundedSeries::cauchy, kink_cauchy)
            + self.inherited.as_ref().map_or(0.0, |z| z.cauchy(x))
            + self.extras_with(|u, v| half_ellipse_cauchy(x, u, v))
    }

    /// The zone's own series and kink term through `series` and `kink` (density or Cauchy
    /// transform); terms that are absent (no coefficients, no kink) are not evaluated.
    fn own_part(
        &self,
        x: f64,
        series: fn(&BoundedSeries, f64) -> f64,
        kink: fn(f64) -> f64,
    ) -> f64 {
        let u = (x - self.mid()) / self.half();
        let series = (!self.correction.beta.is_empty()).then(|| series(&self.correction, u));
        self.own_with(u, series, kink)
    }

    /// Whether the zone carries nothing of its own: q̃ is exactly its inherited link's.
    fn carries_nothing(&self) -> bool {
        self.correction.beta.is_empty() && self.kink.abs() <= 0.0 && self.extras.is_empty()
    }

    /// `∫ q̃ dx` (N/m), including the inherited chain (the kink part is odd).
    pub fn correction_integral(&self) -> f64 {
        self.half() * self.correction.integral()
            + self.inherited.as_ref().map_or(0.0, |z| z.integral())
            + self.extras_with(half_ellipse_integral)
    }

    /// What a new zone `[lo, hi]` (solved on `nodes` collocation points) inherits from this
    /// chain. The memory inside the new zone has square-root kinks exactly at the ends of
    /// earlier zones that lie inside it (and a `|x|` kink at the centre of the normal-loading
    /// zone): the outermost earlier zone that lies inside is inherited whole; one with a
    /// single end inside is inherited faded out beyond the new zone's end; one that contains
    /// the new zone is passed over for its inner zones, unless its own centre kink lies
    /// inside.
    ///
    /// The fade ramps over a quarter of the overlap of the two zones while the overlap is at
    /// least a tenth of the new zone. Below that, the ramp covers the whole overlap (from the
    /// new end to the remembered one), provided at least `FADE_POINTS` of the new zone's
    /// collocation points fall within it; otherwise the earlier zone is passed over and its
    /// kink is left to the series.
    ///
    /// Why: where a remembered end lies within a tenth of the zone of the new one (the
    /// insulating Figure-3 history at η = 0.2, steps 57–60), leaving its kink to the series
    /// makes those steps' stick ends and dissipations several times less accurate than the
    /// rest of the history; the ramp brings them back in line.
    pub fn inheritance_for(
        self: &std::sync::Arc<Self>,
        lo: f64,
        hi: f64,
        nodes: usize,
    ) -> Option<std::sync::Arc<Inherited>> {
        let slack = 1e-12 * (hi - lo);
        let inside = |x: f64| x > lo + slack && x < hi - slack;
        // Collocation points of the new zone within `length` of one of its ends (about: the
        // points are `cos((2r − 1)π/(2(M + 1)))` in the zone's variable).
        let points_within = |length: f64| {
            (nodes + 1) as f64 * (1.0 - 2.0 * length / (hi - lo)).clamp(-1.0, 1.0).acos()
                / std::f64::consts::PI
        };
        let mut zone = Some(self.clone());
        while let Some(z) = zone {
            let overlap = z.hi.min(hi) - z.lo.max(lo);
            let wide = overlap >= 0.1 * (hi - lo);
            let short = !wide && points_within(overlap) >= FADE_POINTS;
            let ramp = if wide { 0.25 * overlap } else { overlap };
            let candidate = if z.lo >= lo - slack && z.hi <= hi + slack {
                Some(Inherited::new(z.clone(), None, None))
            } else if (wide || short) && (inside(z.lo) != inside(z.hi)) {
                let ramp_lo = (!inside(z.lo)).then_some((lo, lo + ramp));
                let ramp_hi = (!inside(z.hi)).then_some((hi - ramp, hi));
                Some(Inherited::new(z.clone(), ramp_lo, ramp_hi))
            } else if z.kink.abs() > 0.0 && inside(z.mid()) && overlap >= 0.1 * (hi - lo) {
                Some(Inherited::new(
                    z.clone(),
                    Some((lo, lo + ramp)),
                    Some((hi - ramp, hi)),
                ))
            } else {
                None
            };
            if let Some(mut c) = candidate {
                // A zone that carries nothing of its own and inherits an earlier zone whole
                // has exactly that zone's q̃ (a return to a remembered state, once per cycle):
                // carry the earlier zone instead, so that chains do not grow with the cycles.
                while let Some(inner) = c
                    .zone
                    .inherited
                    .as_ref()
                    .filter(|i| c.zone.carries_nothing() && !i.faded())
                {
                    c.zone = inner.zone.clone();
                }
                return Some(std::sync::Arc::new(c));
            }
            zone = z.inherited.as_ref().map(|i| i.zone.clone());
        }
        None
    }

    /// Number of zones in the chain.
    pub fn chain_len(&self) -> usize {
        1 + self.links().count()
    }

    /// The inherited corrections of the chain, outermost first.
    pub fn links(&self) -> impl Iterator<Item = &Inherited> {
        std::iter::successors(self.inherited.as_deref(), |i| i.zone.inherited.as_deref())
    }

    /// Where q̃ may fail to be smooth besides the zone's ends: the ends of the zones in its
    /// chain (square roots), their fade ramps, and centre kinks (see [`kink_density`]); not
    /// filtered to the zone.
    pub(super) fn chain_points(&self) -> Vec<f64> {
        let mut points: Vec<f64> = self.kink_point().into_iter().collect();
        for i in self.links() {
            points.extend([i.zone.lo, i.zone.hi]);
            points.extend(i.zone.kink_point());
            points.extend(i.ramp_points());
        }
        points
    }

    /// The zone's centre when it carries a centre kink (see [`kink_density`]).
    fn kink_point(&self) -> Option<f64> {
        (self.kink.abs() > 0.0).then_some(self.mid())
    }
}

impl StickZone {
    /// Centre of the zone (m).
    pub fn mid(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }
    /// Half-width (m).
    pub fn half(&self) -> f64 {
        0.5 * (self.hi - self.lo)
    }
}

#[cfg(test)]
mod tests;
