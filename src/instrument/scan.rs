//! A scanned line: the tip carried along x over a sample of several materials and a
//! height profile while the z feedback holds the lock-in amplitude at the setpoint, as
//! an AFM records one line of an image.
//!
//! The sample is piecewise constant along x ([`Region`]): each region one material (its
//! own prepared simulation: law, contact parameters) and a surface height h. With the z
//! piezo at z_p the rest separation is z_c = z_p − h(x); the piezo position z_p is the
//! topography signal. Each drive period is marched at the material and height under the
//! tip at its start, the tip moving on by the scan speed times the period; the state of
//! the oscillator (and of a hysteretic contact) is carried across boundaries.

use super::feedback::PiController;
use super::lockin::LockIn;
use crate::dynamics::setup::Prepared;
use crate::dynamics::march::Phase;
use crate::error::{Error, Result};

/// A stretch of the sample along x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    /// Where the stretch ends, in m (the last region runs to the end of the line).
    pub until_m: f64,
    /// Its material: an index into the sample's materials.
    pub material: usize,
    /// Its surface height, in m.
    pub height_m: f64,
}

/// What is recorded over one pixel: means over its drive periods.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Pixel {
    /// The pixel's centre, in m.
    pub x_m: f64,
    /// The z piezo position (topography), in m.
    pub topography_m: f64,
    /// The lock-in amplitude ratio A/A₀.
    pub amplitude_ratio: f64,
    /// The amplitude error A/A₀ − setpoint (0 where below 1e-12: round-off).
    pub error: f64,
    /// The lock-in phase, degrees.
    pub phase_deg: f64,
}

/// Scan a line of length `length_m` in `pixels` pixels of `periods_per_pixel` drive
/// periods each, over `materials` laid out by `regions` (sorted by `until_m`), with the
/// loop already holding the setpoint from the piezo position `start_z_m` and the
/// oscillator state `phase` (as [`super::feedback::hold`] leaves them over the first
/// region, say). All
/// materials must share the cantilever (its drive period sets the time). `progress` is
/// told each pixel done. Returns the pixels and the piezo position at the end.
pub fn line(
    materials: &[Prepared],
    regions: &[Region],
    (length_m, pixels, periods_per_pixel): (f64, usize, usize),
    (lockin, controller): (&mut LockIn, &mut PiController),
    start_z_m: f64,
    phase: &mut Phase,
    mut progress: impl FnMut(usize),
) -> Result<(Vec<Pixel>, f64)> {
    if regions.is_empty() || regions.iter().any(|r| r.material >= materials.len()) {
        return Err(Error::NotApplicable(
            "a scanned sample needs regions, each naming one of its materials".into(),
        ));
    }
    crate::error::positive("scan length", length_m)?;
    if pixels == 0 || periods_per_pixel == 0 {
        return Err(Error::NotApplicable(
            "a scan line needs at least one pixel of at least one drive period".into(),
        ));
    }
    let a0 = materials[0].setup.cantilever.free_amplitude_m;
    let step = length_m / (pixels * periods_per_pixel) as f64;
    // The region under the tip: x only grows, so the index only moves on.
    let mut under = 0;
    let mut z = start_z_m;
    let mut out = Vec::with_capacity(pixels);
    for i in 0..pixels {
        let mut sum = [0.0; 4];
        for j in 0..periods_per_pixel {
            let x = step * (i * periods_per_pixel + j) as f64;
            while under + 1 < regions.len() && x >= regions[under].until_m {
                under += 1;
            }
            let region = &regions[under];
            let p = &materials[region.material];
            p.simulation_at(z - region.height_m)?
                .march(phase, 1, lockin)?;
            let amplitude = lockin.amplitude();
            let (dz, error) = controller.update(amplitude);
            for (s, v) in sum
                .iter_mut()
                .zip([z, amplitude, error, lockin.phase_deg()])
            {
                *s += v;
            }
            z += dz * a0;
        }
        let n = periods_per_pixel as f64;
        out.push(Pixel {
            x_m: step * periods_per_pixel as f64 * (i as f64 + 0.5),
            topography_m: sum[0] / n,
            amplitude_ratio: sum[1] / n,
            // (A mean error below 1e-12 is the round-off of a loop that holds.)
            error: if (sum[2] / n).abs() < 1e-12 {
                0.0
            } else {
                sum[2] / n
            },
            phase_deg: sum[3] / n,
        });
        progress(i + 1);
    }
    Ok((out, z))
}

/// `regions` of a line of length `length_m` as the retrace meets them: x mirrored.
pub fn mirrored(regions: &[Region], length_m: f64) -> Vec<Region> {
    let mut out = Vec::with_capacity(regions.len());
    for (i, r) in regions.iter().enumerate().rev() {
        let start = if i == 0 { 0.0 } else { regions[i - 1].until_m };
        out.push(Region {
            until_m: length_m - start,
            ..*r
        });
    }
    out
}
