//! What the registry of force laws says of each law ([`LawInfo`]: its name, help and
//! constructor), the handle that names one ([`LawKind`]), the parameters some laws take
//! ([`LawParam`]) and the specification a setup carries ([`LawSpec`]). Everything that
//! lists, names, parses or documents laws (the command line, parameter files, reports)
//! reads it from here; the list itself, [`LAWS`], sits beside the laws' modules.

use super::{AnyLaw, LAWS};
use crate::error::{Error, Result};
use crate::physics::params::Contact;
use serde::{Deserialize, Serialize};
use std::fmt;

/// What the registry says of one law: its name, its help, how to build it and the
/// few facts the wrappers around it ask.
#[derive(Debug)]
pub struct LawInfo {
    /// Its name as a user types it.
    pub name: &'static str,
    /// One paragraph of help.
    pub help: &'static str,
    /// The law on `contact` with the parameters of `spec` (the elastic law only: a
    /// neck or a rate-dependent sample is wrapped around it by [`AnyLaw::new`]).
    /// Refuses where the law does not apply.
    pub build: fn(&LawSpec, &Contact) -> Result<AnyLaw>,
    /// Whether its contact is Hertzian (a standard-linear-solid sample runs Lee and
    /// Radok's hereditary Hertz integral over it).
    pub hertzian: bool,
    /// Whether the bodies touch at the gap ε (d = α + ε, as DMT and the rigid law
    /// define it) rather than at α = 0: where a capillary neck starts.
    pub touches_at_range: bool,
}

/// The refusal of a law `name` that does not apply at the contact's Tabor parameter
/// `tabor_mu`, saying `why`.
#[doc(hidden)]
pub fn not_applicable(name: &str, tabor_mu: f64, why: impl fmt::Display) -> Error {
    Error::NotApplicable(format!(
        "the {name} law does not apply at Tabor parameter mu = {tabor_mu:.4}: {why}; \
         use the DMT law (small mu) or JKR"
    ))
}

/// One of the laws of the registry ([`LAWS`]), by its place there. The laws the code
/// itself names have a constant each (`LawKind::Hybrid`, …); any law, these included, is
/// found by its name ([`LawKind::from_name`]), and a law a file adds needs no constant.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct LawKind(u8);

#[allow(
    non_upper_case_globals,
    reason = "the laws read as the enum they were: LawKind::Hybrid, LawKind::Jkr, …"
)]
impl LawKind {
    /// The paper's hybrid law, eqs. (17), (5), (8), (18).
    pub const Hybrid: LawKind = LawKind::named("hybrid");
    /// The hybrid law with Greenwood's semi-rigid attraction, eqs. (12), (14), (15).
    pub const HybridAttractive: LawKind = LawKind::named("hybrid-attractive");
    /// Classic JKR.
    pub const Jkr: LawKind = LawKind::named("jkr");
    /// DMT as VEDA and dForce define it.
    pub const Dmt: LawKind = LawKind::named("dmt");
    /// Hertz.
    pub const Hertz: LawKind = LawKind::named("hertz");
    /// The Lennard-Jones law (10), tabulated from the full numerical solution.
    pub const Lj: LawKind = LawKind::named("lj");
    /// No tip–sample force.
    pub const None: LawKind = LawKind::named("none");

    /// Every law, in the order of the help (the registry's).
    pub const ALL: [LawKind; LAWS.len()] = {
        let mut all = [LawKind(0); LAWS.len()];
        let mut i = 0;
        while i < LAWS.len() {
            all[i] = LawKind(i as u8);
            i += 1;
        }
        all
    };

    /// The registered law called `name` (at compile time: a name the registry lacks
    /// does not compile).
    const fn named(name: &str) -> LawKind {
        /// Byte equality, as a const fn may write it.
        const fn same(a: &[u8], b: &[u8]) -> bool {
            if a.len() != b.len() {
                return false;
            }
            let mut k = 0;
            while k < a.len() {
                if a[k] != b[k] {
                    return false;
                }
                k += 1;
            }
            true
        }
        let mut i = 0;
        while i < LAWS.len() {
            if same(LAWS[i].name.as_bytes(), name.as_bytes()) {
                return LawKind(i as u8);
            }
            i += 1;
        }
        panic!("no law of that name in the registry")
    }

    /// What the registry says of this law.
    pub fn info(self) -> &'static LawInfo {
        LAWS[usize::from(self.0)]
    }

    /// The law a user names (as `--law` takes it), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        let name = name.trim();
        (0..LAWS.len())
            .find(|&i| LAWS[i].name.eq_ignore_ascii_case(name))
            .map(|i| LawKind(i as u8))
    }

    /// The names of every law as a user types them.
    pub fn names() -> Vec<String> {
        LAWS.iter().map(|l| l.name.to_string()).collect()
    }
}

impl Default for LawKind {
    /// The paper's hybrid law.
    fn default() -> Self {
        LawKind::Hybrid
    }
}

impl fmt::Display for LawKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.info().name)
    }
}

impl fmt::Debug for LawKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "LawKind({})", self.info().name)
    }
}

impl From<LawKind> for String {
    fn from(kind: LawKind) -> String {
        kind.info().name.to_string()
    }
}

impl TryFrom<String> for LawKind {
    type Error = String;
    fn try_from(name: String) -> std::result::Result<Self, String> {
        LawKind::from_name(&name).ok_or_else(|| {
            format!(
                "no law called {name:?}; the laws: {}",
                LawKind::names().join(", ")
            )
        })
    }
}

/// A parameter some laws take beyond the contact's own.
#[derive(Debug)]
pub struct LawParam {
    /// Its key (the flag's and the parameter file's name).
    pub key: &'static str,
    /// What it is, as messages name it.
    pub name: &'static str,
    /// Its SI unit.
    pub unit: &'static str,
    /// Its help (the flag's).
    pub help: &'static str,
    /// Whether `law` takes it.
    pub taken_by: fn(LawKind) -> bool,
    /// Its plausible range (lo, hi) in the SI unit, and why.
    pub range: (f64, f64, &'static str),
}

/// DMT's Hamaker constant.
pub const HAMAKER: LawParam = LawParam {
    key: "hamaker",
    name: "Hamaker constant",
    unit: "J",
    help: "Hamaker constant for the dmt law [J or eV; default 12πε²Δγ, whose pull-off is \
 \
           2πRΔγ]",
    taken_by: |law| law == LawKind::Dmt,
    range: (1e-22, 1e-17, "the range of real materials, about 1e-20 J"),
};

/// A Kelvin–Voigt sample's viscosity.
pub const VISCOSITY: LawParam = LawParam {
    key: "viscosity",
    name: "sample viscosity",
    unit: "Pa·s",
    help: "Kelvin–Voigt viscosity η of the sample, a force η√(Rδ)·dδ/dt against the \
 \
           indentation rate added to the law (dForce's and pyDAMPF's form; e.g. 50Pa·s) \
 \
           [Pa·s; default: none, elastic]",
    taken_by: |law| law != LawKind::None,
    range: (
        1e-6,
        1e6,
        "from water (1e-3 Pa·s) to polymer melts; 0 is no viscosity (leave it out)",
    ),
};

/// Whether a law takes a capillary neck: any with a contact.
fn takes_a_neck(law: LawKind) -> bool {
    law != LawKind::None
}

/// A capillary neck's rupture distance: giving it puts the neck on.
pub const RUPTURE_DISTANCE: LawParam = LawParam {
    key: "rupture-distance",
    name: "capillary rupture distance",
    unit: "m",
    help: "Capillary neck (VEDA's model, after Kober et al. 2008) on any contact law: a \
           meniscus forms at contact (a hysteretic law's jump-in), pulls with 4πRγ cos θ, \
           falling linearly to zero at this gap D₀ where it breaks (beyond the contact's \
           own let-go), losing 2πRγ cos θ (D₀ − a₀) per cycle on hertz or dmt (e.g. 2nm) \
           [m; default: none, no neck]",
    taken_by: takes_a_neck,
    range: (
        1e-11,
        1e-6,
        "a water neck breaks within a few nm to tens of nm",
    ),
};

/// A capillary neck's surface tension.
pub const SURFACE_TENSION: LawParam = LawParam {
    key: "surface-tension",
    name: "surface tension",
    unit: "J/m²",
    help: "Surface tension γ of the capillary neck's liquid [J/m² or N/m; default 0.072, \
           water at 25 °C; only with a rupture distance]",
    taken_by: takes_a_neck,
    range: (
        1e-3,
        1.0,
        "liquids from about 0.02 (alkanes) to 0.072 J/m² (water)",
    ),
};

/// A capillary neck's contact angle.
pub const CONTACT_ANGLE: LawParam = LawParam {
    key: "contact-angle",
    name: "contact angle",
    unit: "deg",
    help: "Contact angle θ of the capillary neck's liquid on tip and sample [degrees, \
           0 <= θ < 90; default 0, complete wetting; only with a rupture distance]",
    taken_by: takes_a_neck,
    range: (
        0.0,
        90.0,
        "a meniscus pulls only for a wetting liquid, θ < 90°",
    ),
};

/// Whether a law takes a standard-linear-solid sample: one whose contact is Hertzian.
fn takes_a_relaxing_sample(law: LawKind) -> bool {
    law.info().hertzian
}

/// A standard-linear-solid sample's unrelaxed modulus.
pub const UNRELAXED_MODULUS: LawParam = LawParam {
    key: "unrelaxed-modulus",
    name: "unrelaxed modulus",
    unit: "Pa",
    help: "Standard-linear-solid sample on the hertz or dmt law, E(t) = E∞ + (E0 − \
           E∞)exp(−t/τ), with Ting's receding contact (the surface lags a retreating tip and \
           never pulls; it creeps back between taps): its unrelaxed composite modulus E0, \
           above the contact's modulus E*, which is the relaxed E∞ (e.g. 3GPa; give the \
           relaxation time too) [Pa; default: none, elastic]",
    taken_by: takes_a_relaxing_sample,
    range: (1e5, 1e12, "from soft gels to stiff solids"),
};

/// A standard-linear-solid sample's relaxation time.
pub const RELAXATION_TIME: LawParam = LawParam {
    key: "relaxation-time",
    name: "relaxation time",
    unit: "s",
    help: "Relaxation time τ of the standard-linear-solid sample (e.g. 100ns; give the \
           unrelaxed modulus too; from 1e-8/ω₀ to a retardation (E0/E∞)τ of 100 lever \
           periods) [s; default: none, elastic]",
    taken_by: takes_a_relaxing_sample,
    range: (
        1e-14,
        1.0,
        "a relaxation time far outside the drive period (~µs) leaves the sample elastic",
    ),
};

/// Surface tension of water at 25 °C, J/m², the neck's default liquid.
pub const WATER_SURFACE_TENSION_J_M2: f64 = 0.072;

/// Every law parameter.
pub const LAW_PARAMS: [&LawParam; 7] = [
    &HAMAKER,
    &VISCOSITY,
    &RUPTURE_DISTANCE,
    &SURFACE_TENSION,
    &CONTACT_ANGLE,
    &UNRELAXED_MODULUS,
    &RELAXATION_TIME,
];

/// A force law with its own parameters: what a setup asks for.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LawSpec {
    /// The law.
    pub kind: LawKind,
    /// DMT's Hamaker constant H in J (default 12πε²Δγ).
    pub hamaker_j: Option<f64>,
    /// Kelvin–Voigt viscosity η of the sample in Pa·s (none: elastic).
    pub viscosity_pa_s: Option<f64>,
    /// A capillary neck's rupture distance D₀ in m (none: no neck).
    #[serde(default)]
    pub rupture_distance_m: Option<f64>,
    /// The neck's surface tension γ in J/m² (default water's).
    #[serde(default)]
    pub surface_tension_j_m2: Option<f64>,
    /// The neck's contact angle θ in degrees (default 0).
    #[serde(default)]
    pub contact_angle_deg: Option<f64>,
    /// A standard-linear-solid sample's unrelaxed composite modulus E₀ in Pa (none:
    /// elastic).
    #[serde(default)]
    pub unrelaxed_modulus_pa: Option<f64>,
    /// Its relaxation time τ_r in s.
    #[serde(default)]
    pub relaxation_time_s: Option<f64>,
}

impl From<LawKind> for LawSpec {
    fn from(kind: LawKind) -> Self {
        Self {
            kind,
            ..Self::default()
        }
    }
}

impl LawSpec {
    /// Each law parameter with its value in this spec (`None`: not set).
    pub fn params(&self) -> [(&'static LawParam, Option<f64>); LAW_PARAMS.len()] {
        [
            (&HAMAKER, self.hamaker_j),
            (&VISCOSITY, self.viscosity_pa_s),
            (&RUPTURE_DISTANCE, self.rupture_distance_m),
            (&SURFACE_TENSION, self.surface_tension_j_m2),
            (&CONTACT_ANGLE, self.contact_angle_deg),
            (&UNRELAXED_MODULUS, self.unrelaxed_modulus_pa),
            (&RELAXATION_TIME, self.relaxation_time_s),
        ]
    }

    /// The standard-linear-solid sample asked for: (unrelaxed modulus in Pa,
    /// relaxation time in s), none unless both are given.
    pub fn relaxing(&self) -> Option<(f64, f64)> {
        Some((self.unrelaxed_modulus_pa?, self.relaxation_time_s?))
    }

    /// The capillary neck asked for, with the defaults filled in (none without a
    /// rupture distance).
    pub fn neck(&self) -> Option<super::Neck> {
        Some(super::Neck {
            rupture_distance_m: self.rupture_distance_m?,
            surface_tension_j_m2: self
                .surface_tension_j_m2
                .unwrap_or(WATER_SURFACE_TENSION_J_M2),
            contact_angle_deg: self.contact_angle_deg.unwrap_or(0.0),
        })
    }

    /// The spec of law `kind` with the parameters `values`, in the order of
    /// [`LAW_PARAMS`] (the inverse of [`LawSpec::params`]).
    pub fn from_values(kind: LawKind, values: [Option<f64>; LAW_PARAMS.len()]) -> Self {
        let [
            hamaker_j,
            viscosity_pa_s,
            rupture_distance_m,
            surface_tension_j_m2,
            contact_angle_deg,
            unrelaxed_modulus_pa,
            relaxation_time_s,
        ] = values;
        Self {
            kind,
            hamaker_j,
            viscosity_pa_s,
            rupture_distance_m,
            surface_tension_j_m2,
            contact_angle_deg,
            unrelaxed_modulus_pa,
            relaxation_time_s,
        }
    }

    /// The same parameters for law `kind`, leaving out those it does not take (a sweep
    /// over laws on one material).
    pub fn with_kind(&self, kind: LawKind) -> Self {
        Self::from_values(
            kind,
            self.params()
                .map(|(param, value)| value.filter(|_| (param.taken_by)(kind))),
        )
    }

    /// Refuse a parameter the law does not take, naming the laws that do.
    pub fn check(&self) -> Result<()> {
        for (param, value) in self.params() {
            if value.is_some() && !(param.taken_by)(self.kind) {
                return Err(Error::NotApplicable(format!(
                    "the {} law takes no {} parameter (the laws that do: {})",
                    self.kind,
                    param.key,
                    LawKind::ALL
                        .iter()
                        .filter(|k| (param.taken_by)(**k))
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        }
        if self.rupture_distance_m.is_none()
            && (self.surface_tension_j_m2.is_some() || self.contact_angle_deg.is_some())
        {
            return Err(Error::NotApplicable(
                "a surface tension or contact angle describes a capillary neck: give its \
                 rupture-distance too (which puts the neck on)"
                    .into(),
            ));
        }
        if self.unrelaxed_modulus_pa.is_some() != self.relaxation_time_s.is_some() {
            return Err(Error::NotApplicable(
                "a standard-linear-solid sample needs both its unrelaxed-modulus and its \
                 relaxation-time"
                    .into(),
            ));
        }
        if self.relaxing().is_some() && self.viscosity_pa_s.is_some() {
            return Err(Error::NotApplicable(
                "a standard-linear-solid sample takes no viscosity: it is itself the \
                 sample's rheology (Kelvin–Voigt is its limit of a short relaxation time)"
                    .into(),
            ));
        }
        Ok(())
    }
}

impl fmt::Display for LawSpec {
    /// The law's name, with "+kelvin-voigt" for a viscous sample.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.kind)?;
        if self.rupture_distance_m.is_some() {
            f.write_str("+capillary")?;
        }
        if self.viscosity_pa_s.is_some() {
            f.write_str("+kelvin-voigt")?;
        }
        if self.relaxing().is_some() {
            f.write_str("+sls")?;
        }
        Ok(())
    }
}
