//! The solution at one instant ([`ContactState`]): the contact half-width and centre, the
//! pressure and charge series, the punch potential and the shear [`Traction`]
//! `q = η p S(x) + q̃(x)`; and its fields along the surface: p, w and q with their Cauchy
//! transforms, the slip shape S and the strains (eq. (A) of the module docs of
//! [`crate::contact`]).

use serde::{Deserialize, Serialize};

use crate::quadrature::{BoundedSeries, UnboundedSeries};

use super::inherited::sign_blend;
use super::stick_zone::{OWN_LANES, in_chunks};
use super::{
    ChargeSplit, ContactModel, Kinks, StickZone, graded_rule, half_ellipse, half_ellipse_cauchy,
    half_ellipse_integral, kink_domain,
};

/// The shear traction on the contact: `q = η p S(x) + q̃(x)` (see module docs of the solvers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Traction {
    /// Friction coefficient η used in the slip zones.
    pub friction: f64,
    /// Sign of `q/(ηp)` in the left slip zone `[c − a, lo)`.
    pub left_sign: f64,
    /// Sign of `q/(ηp)` in the right slip zone `(hi, c + a]`.
    pub right_sign: f64,
    /// Stick zone and its correction, `None` when the contact is frictionless.
    pub stick: Option<StickZone>,
}

/// The solution at one instant.
///
/// Written as plain data; its shape table as whether it was built, rebuilt on reading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self")]
pub struct ContactState {
    /// Normal load P (N/m).
    pub normal_load: f64,
    /// Tangential load Q (N/m).
    pub tangential_load: f64,
    /// Resultant charge Γ on the punch (C/m).
    pub charge: f64,
    /// Contact potential φ0 relative to the datum (V), conducting punch only.
    pub potential: Option<f64>,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Contact centre c in the material frame (m); eccentricity e = −c.
    pub centre: f64,
    /// Pressure on the contact, `p(x) = density((x − c)/a) + kinks` (Pa): the series part.
    pub pressure: BoundedSeries,
    /// The pressure's square-root kinks at the stick ends ([`Kinks`]).
    pub pressure_kinks: Kinks,
    /// Charge split.
    pub split: ChargeSplit,
    /// Constant-potential charge `w(x) = density((x − c)/a) + kinks` (C/m²): the series part;
    /// empty unless conducting.
    pub potential_charge: UnboundedSeries,
    /// The square-root kinks of w at the stick ends ([`Kinks`]).
    pub charge_kinks: Kinks,
    /// Shear traction.
    pub traction: Traction,
    /// Quadrature table `(t, w p(t), S(t))` of [`ContactState::shape_cauchy`] for a stored
    /// state whose slip zones have opposite signs (built by [`ContactState::frozen`]).
    #[serde(serialize_with = "built", deserialize_with = "to_build")]
    pub shape_table: Option<std::sync::Arc<Vec<(f64, f64, f64)>>>,
}

impl Serialize for ContactState {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        Self::serialize(self, serializer)
    }
}

impl<'de> Deserialize<'de> for ContactState {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let mut state = Self::deserialize(deserializer)?;
        if state.shape_table.is_some() {
            state.tabulate_shape();
        }
        Ok(state)
    }
}

/// Whether a table was built.
fn built<S: serde::Serializer, T>(
    table: &Option<std::sync::Arc<T>>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.serialize_bool(table.is_some())
}

/// An empty table where one was built, to be rebuilt.
fn to_build<'de, D: serde::Deserializer<'de>, T: Default>(
    deserializer: D,
) -> Result<Option<std::sync::Arc<T>>, D::Error> {
    Ok(bool::deserialize(deserializer)?.then(Default::default))
}

impl ContactState {
    /// Normalised position on the contact.
    fn tau(&self, x: f64) -> f64 {
        (x - self.centre) / self.half_width
    }

    /// Whether x lies inside the contact.
    pub fn in_contact(&self, x: f64) -> bool {
        self.tau(x).abs() < 1.0
    }

    /// Pressure p(x) (Pa).
    pub fn pressure_at(&self, x: f64) -> f64 {
        self.pressure.density(self.tau(x)) + self.kinks_at(&self.pressure_kinks, x)
    }

    /// The part `w` of the charge held by the constant potential (C/m²).
    pub fn potential_charge_at(&self, x: f64) -> f64 {
        self.potential_charge.density(self.tau(x)) + self.kinks_at(&self.charge_kinks, x)
    }

    /// `Σ amplitude · f(u, v)/a` over the kink terms (stretches `[u, v]`, [`kink_domain`]):
    /// with the half-ellipse, its transform or its integral as f.
    fn kinks_with(&self, kinks: &Kinks, f: impl Fn(f64, f64) -> f64) -> f64 {
        kinks
            .0
            .iter()
            .map(|k| {
                let (u, v) = kink_domain(k.at, k.side, self.centre, self.half_width);
                k.amplitude * f(u, v)
            })
            .sum::<f64>()
            / self.half_width
    }

    pub(super) fn kinks_at(&self, kinks: &Kinks, x: f64) -> f64 {
        self.kinks_with(kinks, |u, v| half_ellipse(x, u, v))
    }

    /// `∫ p dx` over the contact (N/m).
    pub fn pressure_force(&self) -> f64 {
        self.half_width * self.pressure.integral()
            + self.kinks_with(&self.pressure_kinks, half_ellipse_integral)
    }

    /// `∫ w dx` over the contact (C/m).
    pub fn potential_charge_force(&self) -> f64 {
        self.half_width * self.potential_charge.integral()
            + self.kinks_with(&self.charge_kinks, half_ellipse_integral)
    }

    /// Charge g(x) = χ p + w (C/m²).
    pub fn charge_at(&self, x: f64) -> f64 {
        self.split.ratio * self.pressure_at(x) + self.potential_charge_at(x)
    }

    /// The slip-direction function S(x): the left/right signs outside the stick zone and the
    /// smoothstep `s_L + (s_R − s_L)(3v² − 2v³)`, `v = (x − lo)/(hi − lo)`, inside it. Its zero
    /// slope at the stick ends makes `q̃ = q − ηpS` vanish like `(b − x)^{3/2}` there (a linear
    /// blend, as in the seed paper's eq. 17, leaves a `(b − x)` term whose square-root quotient
    /// limits the end condition to first order in 1/M).
    pub fn slip_shape(&self, x: f64) -> f64 {
        let t = &self.traction;
        match &t.stick {
            None => 0.0,
            Some(s) if x <= s.lo => t.left_sign,
            Some(s) if x >= s.hi => t.right_sign,
            Some(s) => sign_blend([t.left_sign, t.right_sign], s.lo, s.hi, x),
        }
    }

    /// Shear traction q(x) (Pa).
    pub fn traction_at(&self, x: f64) -> f64 {
        let t = &self.traction;
        let Some(stick) = &t.stick else { return 0.0 };
        let base = t.friction * self.pressure_at(x) * self.slip_shape(x);
        base + stick.correction_at(x)
    }

    /// A series in the contact variable τ plus `extra(x)` at each of `xs` into `out`: the
    /// series [`OWN_LANES`] points at a time by `many`, which must give `one`'s values bit for
    /// bit.
    fn contact_series_into(
        &self,
        xs: &[f64],
        many: impl Fn([f64; OWN_LANES]) -> [f64; OWN_LANES],
        one: impl Fn(f64) -> f64,
        extra: impl Fn(f64) -> f64,
        out: &mut Vec<f64>,
    ) {
        in_chunks(
            xs,
            |x| many(x.map(|x| self.tau(x))),
            |x| one(self.tau(x)),
            out,
        );
        for (o, &x) in out.iter_mut().zip(xs) {
            *o += extra(x);
        }
    }

    /// [`Self::pressure_at`] at each of `xs` into `out` (bit-identical, the series
    /// eight (`OWN_LANES`) points at a time).
    pub fn pressures_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let (series, kinks) = (&self.pressure, &self.pressure_kinks);
        let many = |t| series.densities(t);
        let one = |t| series.density(t);
        self.contact_series_into(xs, many, one, |x| self.kinks_at(kinks, x), out);
    }

    /// [`Self::potential_charge_at`] at each of `xs` into `out` (bit-identical).
    pub fn potential_charges_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let (series, kinks) = (&self.potential_charge, &self.charge_kinks);
        let many = |t| series.densities(t);
        let one = |t| series.density(t);
        self.contact_series_into(xs, many, one, |x| self.kinks_at(kinks, x), out);
    }

    /// [`Self::pressure_cauchy`] at each of `xs` into `out` (bit-identical; the transform of
    /// [`Self::pressures_and_cauchys_into`], one code path for both).
    pub fn pressure_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        self.pressures_and_cauchys_into(xs, &mut Vec::new(), out);
    }

    /// [`Self::pressures_into`] and [`Self::pressure_cauchys_into`] at once (bit-identical to
    /// each), the series' sums from one run of their chains
    /// ([`BoundedSeries::densities_and_cauchys`]).
    pub fn pressures_and_cauchys_into(&self, xs: &[f64], p: &mut Vec<f64>, h: &mut Vec<f64>) {
        let (series, kinks) = (&self.pressure, &self.pressure_kinks);
        p.clear();
        h.clear();
        let mut chunks = xs.chunks_exact(OWN_LANES);
        for c in chunks.by_ref() {
            let tau: [f64; OWN_LANES] = std::array::from_fn(|l| self.tau(c[l]));
            let (density, cauchy) = series.densities_and_cauchys(tau);
            p.extend(density);
            h.extend(cauchy);
        }
        for &x in chunks.remainder() {
            let ([density], [cauchy]) = series.densities_and_cauchys([self.tau(x)]);
            p.push(density);
            h.push(cauchy);
        }
        for ((p, h), &x) in p.iter_mut().zip(h.iter_mut()).zip(xs) {
            *p += self.kinks_at(kinks, x);
            *h += self.kinks_with(kinks, |u, v| half_ellipse_cauchy(x, u, v));
        }
    }

    /// [`Self::traction_at`] at each of `xs` into `out` (bit-identical, in batches).
    pub fn tractions_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let mut p = Vec::new();
        self.pressures_into(xs, &mut p);
        self.tractions_with(xs, &p, out);
    }

    /// [`Self::tractions_into`] given the pressure `p` at `xs` (as from
    /// [`Self::pressures_into`]).
    pub fn tractions_with(&self, xs: &[f64], p: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let t = &self.traction;
        let Some(stick) = &t.stick else {
            out.resize(xs.len(), 0.0);
            return;
        };
        let mut chain = Vec::new();
        stick.corrections_into(xs, &mut chain);
        for ((&x, p), c) in xs.iter().zip(p).zip(chain) {
            let base = t.friction * p * self.slip_shape(x);
            out.push(base + c);
        }
    }

    /// `H'p(x) = (1/π)⨍ p(s)/(s − x) ds` from the representation (Pa), any x off the ends.
    pub fn pressure_cauchy(&self, x: f64) -> f64 {
        self.pressure.cauchy(self.tau(x))
            + self.kinks_with(&self.pressure_kinks, |u, v| half_ellipse_cauchy(x, u, v))
    }

    /// `H'g(x)` (C/m²).
    pub fn charge_cauchy(&self, x: f64) -> f64 {
        self.charge_cauchy_with(x, self.pressure_cauchy(x))
    }

    /// [`Self::charge_cauchy`] given `H'p(x)`.
    pub fn charge_cauchy_with(&self, x: f64, pressure_cauchy: f64) -> f64 {
        self.split.ratio * pressure_cauchy
            + self.potential_charge.cauchy(self.tau(x))
            + self.kinks_with(&self.charge_kinks, |u, v| half_ellipse_cauchy(x, u, v))
    }

    /// `H'(pS)(x) = S(x) H'p(x) + (1/π)∫ p(t)(S(t) − S(x))/(t − x) dt`: the Cauchy transform of
    /// the friction-limited part of the traction per unit η. The integrand is a bounded
    /// difference quotient; it is integrated piecewise over the slip and stick intervals with
    /// sine-graded Gauss–Legendre rules (which also absorb the √ at the contact ends). When
    /// both slip zones have the same sign S is constant and the integral vanishes.
    pub fn shape_cauchy(&self, x: f64) -> f64 {
        let Some(stick) = &self.traction.stick else {
            return 0.0;
        };
        self.shape_cauchy_with(stick, x, self.pressure_cauchy(x))
    }

    /// [`Self::shape_cauchy`] at x in the stick zone `stick`'s state, given `H'p(x)`.
    fn shape_cauchy_with(&self, stick: &StickZone, x: f64, pressure_cauchy: f64) -> f64 {
        let t = &self.traction;
        let sx = self.slip_shape(x);
        let value = sx * pressure_cauchy;
        if (t.left_sign - t.right_sign).abs() <= 0.0 && self.shape_table.is_none() {
            return value;
        }
        let built;
        let table = match &self.shape_table {
            Some(table) => table.as_slice(),
            None => {
                built = self.shape_nodes(stick);
                built.as_slice()
            }
        };
        let sum: f64 = table
            .iter()
            .filter(|(tt, _, _)| (tt - x).abs() > 1e-14 * self.half_width)
            .map(|(tt, wp, st)| wp * (st - sx) / (tt - x))
            .sum();
        value + sum / std::f64::consts::PI
    }

    /// Quadrature nodes `(t, w p(t), S(t))` over the left slip, stick and right slip pieces.
    fn shape_nodes(&self, stick: &StickZone) -> Vec<(f64, f64, f64)> {
        let mut table = self.shape_quadrature(stick);
        for (t, w, _) in table.iter_mut() {
            *w *= self.pressure_at(*t);
        }
        table
    }

    /// The nodes `(t, w, S(t))` of [`Self::shape_nodes`] without the pressure factor.
    pub(crate) fn shape_quadrature(&self, stick: &StickZone) -> Vec<(f64, f64, f64)> {
        let ends = [
            self.centre - self.half_width,
            stick.lo,
            stick.hi,
            self.centre + self.half_width,
        ];
        let (nodes, weights) = graded_rule();
        let mut table = Vec::with_capacity(3 * nodes.len());
        for seg in ends.windows(2) {
            let (mid, half) = (0.5 * (seg[0] + seg[1]), 0.5 * (seg[1] - seg[0]));
            for (u, w) in nodes.iter().zip(weights) {
                let tt = mid + half * u;
                table.push((tt, w * half, self.slip_shape(tt)));
            }
        }
        table
    }

    /// This state with the quadrature of [`Self::shape_cauchy`] tabulated, for states that
    /// are stored and evaluated many times (the memory).
    pub fn frozen(mut self) -> Self {
        self.tabulate_shape();
        self
    }

    /// (Re)build the shape quadrature table for the current pressure and stick zone (no-op
    /// when both slip zones have the same sign).
    pub fn tabulate_shape(&mut self) {
        self.shape_table = None;
        let t = &self.traction;
        if let (Some(stick), true) = (&t.stick, (t.left_sign - t.right_sign).abs() > 0.0) {
            self.shape_table = Some(std::sync::Arc::new(self.shape_nodes(stick)));
        }
    }

    /// Replace the stick zone's own correction by none when all its coefficients are below
    /// 1e−14 of `η p(c)`, i.e. far below the residual tolerance of a step (1e−13): the traction
    /// changes by less than that, and every later evaluation of the chain skips the series.
    pub fn drop_negligible_correction(&mut self, friction: f64) {
        let scale = 1e-14 * friction * self.pressure_at(self.centre).abs();
        if let Some(stick) = self.traction.stick.as_mut()
            && stick.kink.abs() <= 0.0
            && stick.correction.beta.iter().all(|b| b.abs() <= scale)
        {
            stick.correction = BoundedSeries::default();
        }
    }

    /// `H'q(x) = η H'(pS)(x) + H'q̃(x)` (Pa), on and off the contact.
    pub fn traction_cauchy(&self, x: f64) -> f64 {
        let t = &self.traction;
        let Some(stick) = &t.stick else { return 0.0 };
        t.friction * self.shape_cauchy(x) + stick.correction_cauchy(x)
    }

    /// Surface strain `∂ux/∂x` from eq. (A): `−(w12 + χ w13) p − w13 w + y11 H'q`.
    pub fn strain_at(&self, model: &ContactModel, x: f64) -> f64 {
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        -model.local_pressure_strain(self.split) * self.pressure_at(x)
            - w13 * self.potential_charge_at(x)
            + model.compliance.y11 * self.traction_cauchy(x)
    }

    /// [`Self::strain_at`] at each of `xs` into `out` (bit-identical; `H'q̃` of the stick
    /// zone's chain in a batch, [`StickZone::correction_cauchys_into`]).
    pub fn strains_into(&self, model: &ContactModel, xs: &[f64], out: &mut Vec<f64>) {
        let (mut p, mut p_cauchy) = (Vec::new(), Vec::new());
        self.pressures_and_cauchys_into(xs, &mut p, &mut p_cauchy);
        self.strains_with(model, xs, (&p, &p_cauchy), out);
    }

    /// [`Self::strains_into`] given the pressure and its Cauchy transform at `xs` (as from
    /// [`Self::pressures_and_cauchys_into`]).
    pub fn strains_with(
        &self,
        model: &ContactModel,
        xs: &[f64],
        (p, p_cauchy): (&[f64], &[f64]),
        out: &mut Vec<f64>,
    ) {
        out.clear();
        let mut w = Vec::new();
        self.potential_charges_into(xs, &mut w);
        let mut chain = Vec::new();
        if let Some(stick) = &self.traction.stick {
            stick.correction_cauchys_into(xs, &mut chain);
        }
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        let local = model.local_pressure_strain(self.split);
        for (k, &x) in xs.iter().enumerate() {
            // `traction_cauchy` with its parts from the batches.
            let traction_cauchy = match &self.traction.stick {
                None => 0.0,
                Some(stick) => {
                    let shape = self.shape_cauchy_with(stick, x, p_cauchy[k]);
                    self.traction.friction * shape + chain[k]
                }
            };
            out.push(-local * p[k] - w13 * w[k] + model.compliance.y11 * traction_cauchy);
        }
    }

    /// The strain change from `old` to this state, `ε − ε_old`, at each of `xs` into `out`
    /// ([`Self::strains_into`] of both).
    pub fn strain_changes_into(
        &self,
        model: &ContactModel,
        old: &ContactState,
        xs: &[f64],
        out: &mut Vec<f64>,
    ) {
        let mut before = Vec::with_capacity(xs.len());
        self.strains_into(model, xs, out);
        old.strains_into(model, xs, &mut before);
        for (n, o) in out.iter_mut().zip(before) {
            *n -= o;
        }
    }
}
