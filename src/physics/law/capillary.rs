//! A capillary neck on top of a contact law, as VEDA defines it (after Kober et al.,
//! 2008): a meniscus forms when the tip touches the sample (gap d < a₀, the contact
//! law's own contact separation: α = 0) and pulls with a force that falls linearly from
//! its adhesion F_ad at contact to zero at the rupture distance D₀, where the neck
//! breaks:
//!
//!   F_cap = F_ad for d < a₀,  F_ad (D₀ − d)/(D₀ − a₀) for a₀ ≤ d < D₀,  0 without a neck.
//!
//! VEDA parametrises the neck by the energy it loses per cycle, ΔE, with
//! F_ad = 2ΔE(D₀ − a₀)/D₀²; tapsim by what sets that adhesion, the Laplace pressure of a
//! water meniscus between a sphere and a flat: F_ad = 4πRγ cos θ (surface tension γ,
//! contact angle θ). Not in the paper.
//!
//! In the contact's scales the neck pulls with T̂_cap = T̂_ad (1 − α̂/α̂_r) on
//! 0 ≤ α̂ < α̂_r, T̂_ad below, with T̂_ad = 4πγ cos θ/Δγ and α̂_r = (D₀ − a₀)/(με). The
//! neck is the law's contact branch: it forms at α̂ = 0 on the way down and breaks at
//! α̂_r on the way up, so each cycle in which it forms and breaks loses the area
//! ∫₀^{α̂_r} T̂_cap dα̂ = T̂_ad α̂_r / 2 in closed form.
//!
//! On a hysteretic contact law (JKR, hybrid, LJ) the neck outlives the contact: it forms
//! when the tip jumps in (at the law's α̂_A), and when the contact lets go (at its α̂_C)
//! the tip is out of contact with the neck still attached — a third state,
//! [`Branch::Necked`], on the law's approach branch plus the neck's pull — until the
//! neck breaks at α̂_r (beyond α̂_C) or the tip touches again at α̂_A. The pull is the
//! same function of α̂ in contact and out of it, so each cycle that forms and breaks the
//! neck loses ∫_{α̂_A}^{α̂_r} T̂_cap dα̂ on top of the law's own loop.

use super::{Branch, ContactState, Exits, ForceLaw};
use crate::error::{Error, Result, positive};
use crate::physics::params::Contact;

/// A contact law with a capillary neck.
#[derive(Debug, Clone)]
pub struct Capillary<L> {
    elastic: L,
    /// The neck's pull at contact, T̂_ad = 4πγ cos θ/Δγ.
    adhesion_t_hat: f64,
    /// Where the neck breaks, α̂_r = (D₀ − a₀)/(με).
    rupture_alpha_hat: f64,
    /// Whether the contact law is hysteretic, so that the neck outlives the contact
    /// ([`Branch::Necked`]).
    outlives_contact: bool,
}

/// A capillary neck's parameters, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neck {
    /// Surface tension γ of the liquid, J/m².
    pub surface_tension_j_m2: f64,
    /// Contact angle θ of the liquid on tip and sample, degrees.
    pub contact_angle_deg: f64,
    /// Gap at which the neck breaks, D₀, in m (measured as the gap d; the contact law's
    /// contact gap a₀ is subtracted).
    pub rupture_distance_m: f64,
}

impl<L: ForceLaw> Capillary<L> {
    /// `elastic` with the capillary `neck`, on `contact`, whose contact separation (gap)
    /// is `contact_gap_m` (a₀: ε for DMT, 0 for Hertz).
    pub fn new(elastic: L, neck: &Neck, contact: &Contact, contact_gap_m: f64) -> Result<Self> {
        let outlives_contact = elastic.loop_area_hat() != 0.0
            || elastic.jump_in_alpha_hat() != 0.0
            || elastic.jump_out_alpha_hat() != 0.0;
        positive("surface tension", neck.surface_tension_j_m2)?;
        positive("rupture distance", neck.rupture_distance_m)?;
        let theta = neck.contact_angle_deg;
        if !(0.0..90.0).contains(&theta) {
            return Err(Error::InvalidParameter {
                name: "contact angle",
                value: theta,
                reason: "a meniscus pulls for 0 <= theta < 90 degrees (a wetting liquid)",
            });
        }
        let open = neck.rupture_distance_m - contact_gap_m;
        if open.is_nan() || open <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "rupture distance",
                value: neck.rupture_distance_m,
                reason: "the neck breaks beyond contact: the rupture distance exceeds the \
                         contact gap a0 (the range for dmt, 0 for hertz)",
            });
        }
        let rupture_alpha_hat = open / contact.separation_scale_m();
        let let_go = elastic.jump_out_alpha_hat();
        if outlives_contact && rupture_alpha_hat <= let_go {
            return Err(Error::NotApplicable(format!(
                "the capillary neck must break beyond the separation where the contact \
                 lets go, {:.4} nm (the law's jump-out): give a rupture distance above it",
                let_go * contact.separation_scale_m() * 1e9
            )));
        }
        Ok(Self {
            elastic,
            adhesion_t_hat: 4.0
                * std::f64::consts::PI
                * neck.surface_tension_j_m2
                * theta.to_radians().cos()
                / contact.work_of_adhesion_j_m2,
            rupture_alpha_hat,
            outlives_contact,
        })
    }

    /// The same neck as a state of its own even on a law without hysteresis: the contact
    /// ends where the law's does (α̂ = 0) and the neck holds on in [`Branch::Necked`], so
    /// that a force acting only in contact (a relaxing sample's) stops there.
    pub fn outliving_contact(self) -> Self {
        Self {
            outlives_contact: true,
            ..self
        }
    }

    /// The contact law's branch under `branch`: out of contact with the neck attached
    /// is the law's approach branch.
    #[inline]
    fn elastic_branch(branch: Branch) -> Branch {
        match branch {
            Branch::Necked => Branch::Free,
            b => b,
        }
    }

    /// ∫ T̂_cap dα̂ while the neck holds: T̂_ad α̂ below contact, T̂_ad (α̂ − α̂²/(2α̂_r))
    /// above.
    fn neck_work_hat(&self, alpha_hat: f64) -> f64 {
        if alpha_hat < 0.0 {
            self.adhesion_t_hat * alpha_hat
        } else {
            self.adhesion_t_hat * (alpha_hat - 0.5 * alpha_hat * alpha_hat / self.rupture_alpha_hat)
        }
    }

    /// T̂_ad, the neck's pull at contact.
    pub fn adhesion_t_hat(&self) -> f64 {
        self.adhesion_t_hat
    }

    /// α̂_r, where the neck breaks.
    pub fn rupture_alpha_hat(&self) -> f64 {
        self.rupture_alpha_hat
    }

    /// The neck's pull T̂_cap at α̂ while it holds.
    #[inline]
    fn neck_t_hat(&self, alpha_hat: f64) -> f64 {
        self.adhesion_t_hat * (1.0 - alpha_hat.max(0.0) / self.rupture_alpha_hat)
    }
}

impl<L: ForceLaw> ForceLaw for Capillary<L> {
    #[inline]
    fn t_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        let elastic = self.elastic.t_hat(alpha_hat, Self::elastic_branch(branch));
        match branch {
            Branch::Free => elastic,
            Branch::Contact | Branch::Necked => elastic + self.neck_t_hat(alpha_hat),
        }
    }
    #[inline]
    fn slope_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        let elastic = self
            .elastic
            .slope_hat(alpha_hat, Self::elastic_branch(branch));
        match branch {
            Branch::Contact | Branch::Necked if alpha_hat >= 0.0 => {
                elastic - self.adhesion_t_hat / self.rupture_alpha_hat
            }
            _ => elastic,
        }
    }
    fn work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        self.elastic
            .work_hat(alpha_hat, Self::elastic_branch(branch))
            + self.capillary_work_hat(alpha_hat, branch)
    }
    /// The law's own jump-in (the neck forms there); 0 (contact) on a law without
    /// hysteresis.
    fn jump_in_alpha_hat(&self) -> f64 {
        if self.outlives_contact {
            self.elastic.jump_in_alpha_hat()
        } else {
            0.0
        }
    }
    /// Where the tip finally lets go: the neck's rupture.
    fn jump_out_alpha_hat(&self) -> f64 {
        self.rupture_alpha_hat
    }
    /// On a law without hysteresis the neck is its contact branch; on a hysteretic law
    /// the contact ends at the law's jump-out into [`Branch::Necked`], which ends at the
    /// rupture (into Free) or at the law's jump-in (into Contact again).
    fn exits(&self, branch: Branch) -> Exits {
        if !self.outlives_contact {
            return match branch {
                Branch::Contact => Exits {
                    below: None,
                    above: Some((self.rupture_alpha_hat, Branch::Free)),
                },
                _ => Exits {
                    below: Some((0.0, Branch::Contact)),
                    above: None,
                },
            };
        }
        let touch = Some((self.elastic.jump_in_alpha_hat(), Branch::Contact));
        match branch {
            Branch::Free => Exits {
                below: touch,
                above: None,
            },
            Branch::Contact => Exits {
                below: None,
                above: Some((self.elastic.jump_out_alpha_hat(), Branch::Necked)),
            },
            Branch::Necked => Exits {
                below: touch,
                above: Some((self.rupture_alpha_hat, Branch::Free)),
            },
        }
    }
    fn free_branch_is_force_free(&self) -> bool {
        self.elastic.free_branch_is_force_free()
    }
    /// The law's own loop and the neck's, ∫_{α̂_A}^{α̂_r} T̂_cap dα̂ (T̂_ad α̂_r / 2 on a law
    /// without hysteresis, which forms the neck at contact, α̂ = 0).
    fn loop_area_hat(&self) -> f64 {
        if self.outlives_contact {
            self.elastic.loop_area_hat() + self.neck_work_hat(self.rupture_alpha_hat)
                - self.neck_work_hat(self.elastic.jump_in_alpha_hat())
        } else {
            0.5 * self.adhesion_t_hat * self.rupture_alpha_hat
        }
    }
    /// ∫ T̂_cap dα̂ while the neck holds (in contact, and out of it while attached);
    /// nothing without a neck.
    fn capillary_work_hat(&self, alpha_hat: f64, branch: Branch) -> f64 {
        match branch {
            Branch::Free => 0.0,
            Branch::Contact | Branch::Necked => self.neck_work_hat(alpha_hat),
        }
    }
    fn is_rate_dependent(&self) -> bool {
        self.elastic.is_rate_dependent()
    }
    fn dissipative_t_hat(&self, state: &ContactState) -> f64 {
        self.elastic.dissipative_t_hat(state)
    }
    fn dissipative_slopes_hat(&self, state: &ContactState) -> (f64, f64) {
        self.elastic.dissipative_slopes_hat(state)
    }
}
