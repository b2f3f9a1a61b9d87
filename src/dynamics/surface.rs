//! The surface a relaxing sample remembers from one contact to the next, as the march
//! carries it beside the integrator's state ([`ForceLaw::surface`]: Ting's receding
//! contact on a standard linear solid, [`RelaxingHalfSpace`]).
//!
//! The integrator drives it one accepted step at a time: a step is opened where it
//! starts, every stage inside it reads the force the surface exerts at its own point
//! and time, and the accepted step's end closes it (the elements become what the
//! stages saw there) and opens the next. A step whose stages are rejected leaves the
//! surface as it was. In free flight, where no element touches, the surface creeps back
//! in closed form.
//!
//! The nodes' reach follows the tip: whenever a step opens deeper than 70 % of it, the
//! surface is moved onto nodes reaching half as far again (or far enough); when the taps
//! of the last two drive periods stayed shallower than 30 % of it (a transient's deep
//! first taps are over) and the elements past their depth have crept back to nothing
//! (1e-12 of it), onto nodes that put the deepest of them at 60 % of the reach. The
//! deepest contact so covers most of the nodes.

use crate::error::Result;
use crate::physics::contact::viscoelastic::RelaxingHalfSpace;
use crate::physics::law::ForceLaw;

/// What the surface sees of the tip: the indentation δ̂ = −α̂ and its rate dδ̂/dτ.
pub type View = [f64; 2];

/// The fraction of the nodes' reach past which a step's start grows it.
const GROW_AT: f64 = 0.7;
/// How much the reach grows at least.
const GROWTH: f64 = 1.5;
/// The fraction of the reach below which two periods' taps shrink it …
const SHRINK_BELOW: f64 = 0.3;
/// … to put the deepest of them at this fraction of it …
const SETTLE_AT: f64 = 0.6;
/// … once what the elements past it hold, relative to that depth, is below this.
const FORGOTTEN: f64 = 1e-12;
/// The first reach, as a fraction of the length unit L in the contact's units (a₁):
/// far shallower than any tap, which the growth then reaches.
const FIRST_REACH: f64 = 1e-3;

/// A relaxing sample's surface and the integrator step it is in.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    half_space: RelaxingHalfSpace,
    /// τ where the open step started.
    opened_at: f64,
    /// The deepest indentation a step opened at since the reach was last looked at
    /// for shrinking …
    deepest: f64,
    /// … and the time driven since (τ itself is rewound by whole periods).
    since: f64,
}

impl Surface {
    /// A fresh surface for `law` if its sample has one (none for every other law).
    /// `length_hat` is the length unit L in the contact's units (the coupling's a₁).
    pub(crate) fn of<L: ForceLaw>(law: &L, length_hat: f64) -> Option<Self> {
        let reach = (FIRST_REACH * length_hat).max(f64::MIN_POSITIVE.sqrt());
        Some(Self {
            half_space: law.surface(reach)?,
            opened_at: 0.0,
            deepest: 0.0,
            since: 0.0,
        })
    }

    /// Open a step at τ where the tip is seen as `view` (growing the reach first if the
    /// tip is deep in it; `period`, the drive's, paces the look for shrinking it).
    pub(crate) fn open(&mut self, tau: f64, [depth, rate]: View, period: f64) -> Result<()> {
        let reach = self.half_space.reach_hat();
        self.deepest = self.deepest.max(depth);
        if depth > GROW_AT * reach {
            self.half_space
                .regrid((GROWTH * reach).max(depth / GROW_AT));
        } else if self.since >= 2.0 * period {
            let target = self.deepest / SETTLE_AT;
            if self.deepest > 0.0
                && self.deepest < SHRINK_BELOW * reach
                && self.half_space.extension_beyond(target) <= FORGOTTEN * self.deepest
            {
                self.half_space.regrid(target);
            }
            (self.deepest, self.since) = (depth, 0.0);
        }
        self.half_space.begin_step(depth, rate)?;
        self.opened_at = tau;
        Ok(())
    }

    /// F̂, the surface's push on the tip (compressive positive, the contact's units), at τ
    /// inside the open step where the tip is seen as `view`.
    #[inline]
    pub(crate) fn force_at(&self, tau: f64, [depth, rate]: View) -> f64 {
        self.half_space
            .force_in_step_hat(depth, rate, tau - self.opened_at)
    }

    /// Close the open step at τ where the tip is seen as `view`, and open the next there.
    pub(crate) fn close(&mut self, tau: f64, view: View, period: f64) -> Result<()> {
        let [depth, rate] = view;
        self.half_space.end_step(depth, rate, tau - self.opened_at);
        self.since += tau - self.opened_at;
        self.open(tau, view, period)
    }

    /// Creep for `span` of free flight (no element touches) and open the next step at
    /// its end, τ, where the tip is seen as `view`.
    pub(crate) fn creep(&mut self, span: f64, tau: f64, view: View, period: f64) -> Result<()> {
        self.half_space.creep(span);
        self.since += span;
        self.open(tau, view, period)
    }

    /// The retardation time (1 + r)τ̂_r the surface creeps back with: its slowest
    /// memory.
    pub(crate) fn creep_hat(&self) -> f64 {
        self.half_space.creep_hat()
    }

    /// How deep the free surface sits under the axis (the contact's units).
    pub fn depth_hat(&self) -> f64 {
        self.half_space.surface_depth_hat()
    }
}
