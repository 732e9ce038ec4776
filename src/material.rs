//! Material constants: transversely isotropic piezoelectric ceramics (poled along z) and
//! isotropic elastic solids, with built-in presets and validation.
//!
//! # Conventions
//! Plane strain in the x–z plane, z into the half-plane (along the poling axis), SI units.
//! The constitutive law (stiffness at constant field `c^E`, permittivity at constant strain `ε^S`,
//! electric field `E = −∇φ`) is
//!
//! ```text
//! σxx = c11 ∂x ux + c13 ∂z uz + e31 ∂z φ      Dx = e15 (∂z ux + ∂x uz) − ε11 ∂x φ
//! σzz = c13 ∂x ux + c33 ∂z uz + e33 ∂z φ      Dz = e31 ∂x ux + e33 ∂z uz − ε33 ∂z φ
//! σxz = c44 (∂z ux + ∂x uz) + e15 ∂x φ
//! ```
//!
//! Only the in-plane constants enter a plane problem, so `c12`/`c66` are not needed.
//!
//! # Validity
//! A material is accepted when every constant is finite and physical — `c11, c33, c44` (and
//! `|c13|`) in [1e3, 1e14] Pa, `|e31|, |e33|, |e15| ≤ 1e3` C/m², `ε11, ε33` in [1e−14, 1e−3]
//! C/(V·m) — the in-plane elastic matrix `[[c11, c13], [c13, c33]]` and `c44` are positive
//! definite, and `ε11, ε33 > 0`; an isotropic solid needs `μ` (or `E`) in [1e3, 1e14] Pa and
//! `−1 < ν ≤ 1/2` (`ν = 1/2`, the incompressible limit, is allowed: it is the uncoupled case of
//! Dundurs' β = 0 used for the Cattaneo–Mindlin checks). Constants inside these ranges can still
//! be degenerate for the surface response; [`crate::halfplane::SurfaceCompliance::try_of`]
//! then says why.

use serde::{Deserialize, Serialize};

use crate::error::Issue;

/// Constants of a transversely isotropic piezoelectric solid poled along z (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PiezoConstants {
    /// Elastic stiffness c11 (Pa).
    pub c11: f64,
    /// Elastic stiffness c13 (Pa).
    pub c13: f64,
    /// Elastic stiffness c33 (Pa).
    pub c33: f64,
    /// Elastic stiffness c44 (Pa).
    pub c44: f64,
    /// Piezoelectric constant e31 (C/m²).
    pub e31: f64,
    /// Piezoelectric constant e33 (C/m²).
    pub e33: f64,
    /// Piezoelectric constant e15 (C/m²).
    pub e15: f64,
    /// Permittivity ε11 (C/(V·m)).
    pub eps11: f64,
    /// Permittivity ε33 (C/(V·m)).
    pub eps33: f64,
}

/// Constants of an isotropic elastic solid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsotropicConstants {
    /// Shear modulus μ (Pa).
    pub shear_modulus: f64,
    /// Poisson's ratio ν (–).
    pub poisson_ratio: f64,
}

impl IsotropicConstants {
    /// From Young's modulus `E` (Pa) and Poisson's ratio `ν`.
    pub fn from_youngs(youngs_modulus: f64, poisson_ratio: f64) -> Self {
        Self {
            shear_modulus: youngs_modulus / (2.0 * (1.0 + poisson_ratio)),
            poisson_ratio,
        }
    }

    /// Young's modulus `E = 2μ(1 + ν)` (Pa).
    pub fn youngs_modulus(&self) -> f64 {
        2.0 * self.shear_modulus * (1.0 + self.poisson_ratio)
    }

    /// Plane-strain modulus `E* = E/(1 − ν²)` of the half-plane against a rigid punch (Pa).
    pub fn plane_strain_modulus(&self) -> f64 {
        self.youngs_modulus() / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }

    /// Dundurs' second constant for a rigid punch on this solid: `β = (1 − 2ν)/(2(1 − ν))`.
    pub fn dundurs_beta(&self) -> f64 {
        (1.0 - 2.0 * self.poisson_ratio) / (2.0 * (1.0 - self.poisson_ratio))
    }
}

/// A half-plane material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Material {
    /// Transversely isotropic piezoelectric ceramic, poled along z.
    Piezoelectric(PiezoConstants),
    /// Isotropic elastic solid (no electric coupling).
    Elastic(IsotropicConstants),
}

/// A built-in material with its source.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    /// Name used in scenarios (lower case).
    pub name: &'static str,
    /// Where the constants come from.
    pub source: &'static str,
    /// The constants.
    pub material: Material,
}

/// PZT-4, the seed paper's Table 1 (after Ke et al. 2008).
pub const PZT4: PiezoConstants = PiezoConstants {
    c11: 139e9,
    c13: 74.3e9,
    c33: 115e9,
    c44: 25.6e9,
    e31: -5.2,
    e33: 15.1,
    e15: 12.7,
    eps11: 64.61e-10,
    eps33: 56.2e-10,
};

/// Aluminium as used in the seed paper's Figure 4 check (μ = 27.3 GPa, ν = 0.3).
pub const ALUMINIUM: IsotropicConstants = IsotropicConstants {
    shear_modulus: 27.3e9,
    poisson_ratio: 0.3,
};

/// PZT-5H: Berlincourt, Curran & Jaffe (1964), in Mason (ed.) *Physical Acoustics* I-A, as
/// tabulated (c^E, e, ε^S) by Auld, *Acoustic Fields and Waves in Solids* I (1973), Appendix 2.
pub const PZT5H: PiezoConstants = PiezoConstants {
    c11: 126e9,
    c13: 84.1e9,
    c33: 117e9,
    c44: 23.0e9,
    e31: -6.5,
    e33: 23.3,
    e15: 17.0,
    eps11: 1.505e-8,
    eps33: 1.302e-8,
};

/// BaTiO3 ceramic: Berlincourt, Curran & Jaffe (1964), same tabulation as [`PZT5H`]
/// (c44 = 43.9 GPa from s44^E; ε^S = 1115 ε0, 1260 ε0).
pub const BATIO3: PiezoConstants = PiezoConstants {
    c11: 150e9,
    c13: 66e9,
    c33: 146e9,
    c44: 43.9e9,
    e31: -4.35,
    e33: 17.5,
    e15: 11.4,
    eps11: 9.87e-9,
    eps33: 1.116e-8,
};

/// The built-in presets.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "pzt4",
            source: "PZT-4, seed paper Table 1 (Ke et al. 2008; Berlincourt et al. 1964 c^E, e, ε^S)",
            material: Material::Piezoelectric(PZT4),
        },
        Preset {
            name: "pzt5h",
            source: "PZT-5H, Berlincourt, Curran & Jaffe 1964, as tabulated by Auld 1973 (Vol. I, App. 2)",
            material: Material::Piezoelectric(PZT5H),
        },
        Preset {
            name: "batio3",
            source: "BaTiO3 ceramic, Berlincourt, Curran & Jaffe 1964, as tabulated by Auld 1973 (Vol. I, App. 2)",
            material: Material::Piezoelectric(BATIO3),
        },
        Preset {
            name: "aluminium",
            source: "aluminium, seed paper Section 6 (Nowell, Hills & Sackfield 1988 check)",
            material: Material::Elastic(ALUMINIUM),
        },
    ]
}

/// Look a preset up by name (case-insensitive; `-` and `_` ignored).
pub fn preset(name: &str) -> Option<Preset> {
    let key = normalise_name(name);
    presets()
        .into_iter()
        .find(|p| normalise_name(p.name) == key)
}

fn normalise_name(name: &str) -> String {
    name.chars()
        .filter(|c| *c != '-' && *c != '_')
        .flat_map(char::to_lowercase)
        .collect()
}

/// Range of an elastic constant (Pa): a stiffness from a soft rubber to beyond diamond. Inside
/// it, and with the other ranges, the dimensionless constants of the Stroh eigenproblem stay
/// representable.
pub const STIFFNESS_RANGE: (f64, f64) = (1e3, 1e14);
/// Largest |e_ij| (C/m²) of a piezoelectric constant (ceramics and crystals have |e| < 100).
pub const MAX_PIEZOELECTRIC: f64 = 1e3;
/// Range of a permittivity (C/(V·m)); vacuum has 8.85e−12, ferroelectrics up to about 1e−6.
pub const PERMITTIVITY_RANGE: (f64, f64) = (1e-14, 1e-3);

/// An issue unless `value` lies in `[lo, hi]` (NaN does not).
fn check_range(
    issues: &mut Vec<Issue>,
    path: String,
    value: f64,
    unit: &str,
    (lo, hi): (f64, f64),
) {
    if !(lo..=hi).contains(&value) {
        issues.push(Issue::new(
            path,
            format!("{value:e} {unit} is invalid; it must lie in [{lo:e}, {hi:e}] {unit}"),
        ));
    }
}

/// The rules of Young's modulus `E` (Pa) and Poisson's ratio `ν` of an isotropic solid given
/// by them (`path` is prefixed): `E` in [`STIFFNESS_RANGE`], `−1 < ν ≤ 1/2`.
pub fn validate_youngs(path: &str, youngs_modulus: f64, poisson_ratio: f64) -> Vec<Issue> {
    let mut issues = Vec::new();
    check_range(
        &mut issues,
        format!("{path}.youngs_modulus"),
        youngs_modulus,
        "Pa",
        STIFFNESS_RANGE,
    );
    check_poisson(&mut issues, path, poisson_ratio);
    issues
}

fn check_poisson(issues: &mut Vec<Issue>, path: &str, nu: f64) {
    if !(nu.is_finite() && nu > -1.0 && nu <= 0.5) {
        issues.push(Issue::new(
            format!("{path}.poisson_ratio"),
            format!("{nu} is invalid; it must lie in (−1, 0.5]"),
        ));
    }
}

impl PiezoConstants {
    /// An isotropic elastic solid (shear modulus μ, Poisson's ratio ν) written as
    /// piezoelectric constants without coupling (e = 0), with permittivities ε11, ε33: the
    /// degenerate case of the Stroh formalism (the elastic half-plane's compliance, and the
    /// isotropic solid the tests check the kernels against).
    pub(crate) fn uncoupled_isotropic(mu: f64, nu: f64, eps11: f64, eps33: f64) -> Self {
        let lambda = 2.0 * mu * nu / (1.0 - 2.0 * nu);
        Self {
            c11: lambda + 2.0 * mu,
            c13: lambda,
            c33: lambda + 2.0 * mu,
            c44: mu,
            e31: 0.0,
            e33: 0.0,
            e15: 0.0,
            eps11,
            eps33,
        }
    }

    /// Every problem with the constants, each naming the constant (`path` is prefixed):
    /// finite, in range, and the elastic and dielectric matrices positive definite.
    pub fn validate(&self, path: &str) -> Vec<Issue> {
        let c = self;
        let mut issues = Vec::new();
        let named = [
            ("c11", c.c11, "Pa"),
            ("c13", c.c13, "Pa"),
            ("c33", c.c33, "Pa"),
            ("c44", c.c44, "Pa"),
            ("e31", c.e31, "C/m²"),
            ("e33", c.e33, "C/m²"),
            ("e15", c.e15, "C/m²"),
            ("eps11", c.eps11, "C/(V·m)"),
            ("eps33", c.eps33, "C/(V·m)"),
        ];
        for (name, value, unit) in named {
            if !value.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.{name}"),
                    format!("{value} {unit} is invalid; it must be finite"),
                ));
            }
        }
        if !issues.is_empty() {
            return issues;
        }
        for (name, value) in [("c11", c.c11), ("c33", c.c33), ("c44", c.c44)] {
            if value <= 0.0 {
                issues.push(Issue::new(
                    format!("{path}.{name}"),
                    format!("{value:e} Pa is invalid; it must be > 0 (elastic stiffness positive definite)"),
                ));
            } else {
                check_range(
                    &mut issues,
                    format!("{path}.{name}"),
                    value,
                    "Pa",
                    STIFFNESS_RANGE,
                );
            }
        }
        if c.c13.abs() > STIFFNESS_RANGE.1 {
            let max = STIFFNESS_RANGE.1;
            issues.push(Issue::new(
                format!("{path}.c13"),
                format!(
                    "{:e} Pa is invalid; it must satisfy |c13| ≤ {max:e} Pa",
                    c.c13
                ),
            ));
        } else if c.c11 > 0.0 && c.c33 > 0.0 && c.c11 * c.c33 - c.c13 * c.c13 <= 0.0 {
            issues.push(Issue::new(
                format!("{path}.c13"),
                format!(
                    "{:e} Pa is invalid; it must satisfy c13² < c11·c33 = {:e} Pa² (elastic stiffness positive definite)",
                    c.c13,
                    c.c11 * c.c33
                ),
            ));
        }
        for (name, value) in [("e31", c.e31), ("e33", c.e33), ("e15", c.e15)] {
            if value.abs() > MAX_PIEZOELECTRIC {
                issues.push(Issue::new(
                    format!("{path}.{name}"),
                    format!("{value:e} C/m² is invalid; it must satisfy |{name}| ≤ {MAX_PIEZOELECTRIC:e} C/m²"),
                ));
            }
        }
        for (name, value) in [("eps11", c.eps11), ("eps33", c.eps33)] {
            if value <= 0.0 {
                issues.push(Issue::new(
                    format!("{path}.{name}"),
                    format!("{value:e} C/(V·m) is invalid; it must be > 0 (permittivity positive definite)"),
                ));
            } else {
                check_range(
                    &mut issues,
                    format!("{path}.{name}"),
                    value,
                    "C/(V·m)",
                    PERMITTIVITY_RANGE,
                );
            }
        }
        issues
    }
}

impl Material {
    /// Every problem with the constants, each naming the constant (`path` is prefixed). An
    /// isotropic solid needs `μ` in [`STIFFNESS_RANGE`] and `−1 < ν ≤ 1/2`.
    pub fn validate(&self, path: &str) -> Vec<Issue> {
        match self {
            Material::Piezoelectric(c) => c.validate(path),
            Material::Elastic(c) => {
                let mut issues = Vec::new();
                check_range(
                    &mut issues,
                    format!("{path}.shear_modulus"),
                    c.shear_modulus,
                    "Pa",
                    STIFFNESS_RANGE,
                );
                check_poisson(&mut issues, path, c.poisson_ratio);
                issues
            }
        }
    }

    /// Scale the piezoelectric coupling constants by `factor` (used to study the uncoupled limit).
    pub fn with_scaled_coupling(&self, factor: f64) -> Material {
        match *self {
            Material::Piezoelectric(c) => Material::Piezoelectric(PiezoConstants {
                e31: c.e31 * factor,
                e33: c.e33 * factor,
                e15: c.e15 * factor,
                ..c
            }),
            m @ Material::Elastic(_) => m,
        }
    }

    /// Whether the material carries electric fields.
    pub fn is_piezoelectric(&self) -> bool {
        matches!(self, Material::Piezoelectric(_))
    }

    /// The plane-strain compliance of a uniform bulk stress along the surface, `εxx = s̃ σxx`
    /// (1/Pa): the state `σxx = σB` with `σzz = σxz = 0`, `εyy = 0` and, for a piezoelectric
    /// solid, open circuit `Dz = 0` (the surface outside the contact carries no charge) and
    /// `Ex = Dx = 0`. From `σzz = 0` and `Dz = 0`,
    ///
    /// ```text
    /// 1/s̃ = c11 − (c13² ε33 + 2 c13 e31 e33 − c33 e31²)/(c33 ε33 + e33²)
    /// ```
    ///
    /// which for an isotropic solid is `E/(1 − ν²)` (then `s̃ = (1 − ν²)/E`). The state's
    /// surface potential `φ = Ez·z` is zero at z = 0, so a conducting punch's condition is
    /// unchanged.
    pub fn bulk_compliance(&self) -> f64 {
        match self {
            Material::Piezoelectric(c) => {
                let det = c.c33 * c.eps33 + c.e33 * c.e33;
                let reduction = (c.c13 * c.c13 * c.eps33 + 2.0 * c.c13 * c.e31 * c.e33
                    - c.c33 * c.e31 * c.e31)
                    / det;
                1.0 / (c.c11 - reduction)
            }
            Material::Elastic(c) => 1.0 / c.plane_strain_modulus(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_found_by_name() {
        for p in presets() {
            assert!(p.material.validate("material").is_empty(), "{}", p.name);
        }
        assert!(preset("PZT-4").is_some());
        assert!(preset("Aluminium").is_some());
        assert!(preset("unobtainium").is_none());
    }

    #[test]
    fn validation_names_each_bad_constant() {
        let bad = Material::Piezoelectric(PiezoConstants {
            c44: -1.0,
            eps33: 0.0,
            ..PZT4
        });
        let issues = bad.validate("material.constants");
        let paths: Vec<_> = issues.iter().map(|i| i.path.as_str()).collect();
        assert_eq!(
            paths,
            ["material.constants.c44", "material.constants.eps33"]
        );
        assert!(issues[0].message.contains("must be > 0"));

        let not_pd = Material::Piezoelectric(PiezoConstants { c13: 200e9, ..PZT4 });
        let issues = not_pd.validate("m");
        assert_eq!(issues.len(), 1);
        assert_eq!(issues[0].path, "m.c13");
        assert!(issues[0].message.contains("c13² < c11·c33"));

        let nan = Material::Piezoelectric(PiezoConstants {
            e33: f64::NAN,
            ..PZT4
        });
        assert_eq!(nan.validate("m")[0].path, "m.e33");

        let iso = Material::Elastic(IsotropicConstants {
            shear_modulus: 0.0,
            poisson_ratio: 0.7,
        });
        let paths: Vec<_> = iso.validate("m").into_iter().map(|i| i.path).collect();
        assert_eq!(paths, ["m.shear_modulus", "m.poisson_ratio"]);
    }

    #[test]
    fn stiffness_outside_its_range_is_rejected() {
        let tiny = Material::Piezoelectric(PiezoConstants {
            c44: 2.56e-90,
            ..PZT4
        });
        let issues = tiny.validate("material");
        assert_eq!(issues.len(), 1);
        assert_eq!(
            issues[0].to_string(),
            "`material.c44` = 2.56e-90 Pa is invalid; it must lie in [1e3, 1e14] Pa"
        );
        let c13 = Material::Piezoelectric(PiezoConstants { c13: -2e14, ..PZT4 });
        assert_eq!(
            c13.validate("m")[0].to_string(),
            "`m.c13` = -2e14 Pa is invalid; it must satisfy |c13| ≤ 1e14 Pa"
        );
    }

    #[test]
    fn piezoelectric_constant_outside_its_range_is_rejected() {
        let huge = Material::Piezoelectric(PiezoConstants {
            e15: 1.27e301,
            ..PZT4
        });
        assert_eq!(
            huge.validate("material")[0].to_string(),
            "`material.e15` = 1.27e301 C/m² is invalid; it must satisfy |e15| ≤ 1e3 C/m²"
        );
    }

    #[test]
    fn permittivity_outside_its_range_is_rejected() {
        let huge = Material::Piezoelectric(PiezoConstants {
            eps11: 1e308,
            ..PZT4
        });
        assert_eq!(
            huge.validate("material")[0].to_string(),
            "`material.eps11` = 1e308 C/(V·m) is invalid; it must lie in [1e-14, 1e-3] C/(V·m)"
        );
    }

    #[test]
    fn isotropic_moduli_outside_their_range_are_rejected() {
        let issues = validate_youngs("material", 1.0, 0.3);
        assert_eq!(issues.len(), 1);
        assert_eq!(
            issues[0].to_string(),
            "`material.youngs_modulus` = 1e0 Pa is invalid; it must lie in [1e3, 1e14] Pa"
        );
        assert!(validate_youngs("material", 70e9, 0.3).is_empty());
        let stiff = Material::Elastic(IsotropicConstants {
            shear_modulus: 1e20,
            poisson_ratio: 0.3,
        });
        assert_eq!(
            stiff.validate("material")[0].to_string(),
            "`material.shear_modulus` = 1e20 Pa is invalid; it must lie in [1e3, 1e14] Pa"
        );
    }

    #[test]
    fn isotropic_relations() {
        let al = ALUMINIUM;
        approx::assert_relative_eq!(al.youngs_modulus(), 70.98e9, max_relative = 1e-12);
        approx::assert_relative_eq!(al.dundurs_beta(), 0.4 / 1.4, max_relative = 1e-12);
        let back = IsotropicConstants::from_youngs(al.youngs_modulus(), 0.3);
        approx::assert_relative_eq!(back.shear_modulus, al.shear_modulus, max_relative = 1e-12);
    }

    /// The open-circuit bulk state solves the constitutive law: with εxx = s̃σB and the εzz, Ez
    /// it implies, σzz = 0 and Dz = 0 to round-off; the isotropic limit is (1 − ν²)/E; and the
    /// open-circuit compliance of PZT-4 lies between the short-circuit (Ez = 0) one and the
    /// purely elastic one of its stiffness (the coupling stiffens it).
    #[test]
    fn bulk_compliance_open_circuit_state_and_isotropic_limit() {
        let al = Material::Elastic(ALUMINIUM);
        approx::assert_relative_eq!(
            al.bulk_compliance(),
            (1.0 - 0.09) / ALUMINIUM.youngs_modulus(),
            max_relative = 1e-14
        );
        let c = PZT4;
        let s = Material::Piezoelectric(c).bulk_compliance();
        let exx = s * 1e6;
        let det = c.c33 * c.eps33 + c.e33 * c.e33;
        let ezz = -(c.c13 * c.eps33 + c.e33 * c.e31) * exx / det;
        let field = (c.c13 * c.e33 - c.c33 * c.e31) * exx / det;
        let sxx = c.c11 * exx + c.c13 * ezz - c.e31 * field;
        let szz = c.c13 * exx + c.c33 * ezz - c.e33 * field;
        let dz = c.e31 * exx + c.e33 * ezz + c.eps33 * field;
        approx::assert_relative_eq!(sxx, 1e6, max_relative = 1e-12);
        assert!(szz.abs() < 1e-12 * 1e6, "{szz}");
        assert!(dz.abs() < 1e-12 * (c.e33 * exx).abs(), "{dz}");
        let short = 1.0 / (c.c11 - c.c13 * c.c13 / c.c33);
        assert!(s < short, "{s} {short}");
    }
}
