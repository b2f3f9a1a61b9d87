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
use super::probe::{OneMode, Probe, Readings};
use super::repeats::Repeats;
use super::thermal::ThermalForce;
use crate::dynamics::march::Phase;
use crate::dynamics::modes::MAX_MODES;
use crate::dynamics::setup::Prepared;
use crate::error::{Error, Result};

/// The most pixels along a line, and the most lines of an image.
pub const MAX_PIXELS: usize = 4096;
/// The most pixels of an image (lines × pixels): its records stay within memory.
pub const MAX_IMAGE_PIXELS: usize = 1 << 20;

/// A stretch of the sample along x.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Region {
    /// Where the stretch ends, in m (the last region runs to the end of the line).
    pub until_m: f64,
    /// Its material: an index into the sample's materials.
    pub material: usize,
    /// Its surface height, in m.
    pub height_m: f64,
}

/// What a lock-in of a higher mode read over a pixel: means over its drive periods.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModeReading {
    /// The mode (2 the second).
    pub mode: usize,
    /// Its amplitude over its free amplitude, Aᵢ/A₀ᵢ.
    pub amplitude_ratio: f64,
    /// Its phase lag, degrees.
    pub phase_deg: f64,
}

/// What is recorded over one pixel: means over its drive periods.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pixel {
    /// The pixel's centre, in m.
    pub x_m: f64,
    /// The z piezo position (topography), in m.
    pub topography_m: f64,
    /// The lock-in amplitude ratio A/A₀ (the first mode's).
    pub amplitude_ratio: f64,
    /// The amplitude error A/A₀ − setpoint (0 where below 1e-12: round-off).
    pub error: f64,
    /// The lock-in phase, degrees (the first mode's).
    pub phase_deg: f64,
    /// The higher modes' lock-ins (none for the point mass).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<ModeReading>,
}

/// Scan a line of length `length_m` in `pixels` pixels of `periods_per_pixel` drive
/// periods each, over `materials` laid out by `regions` (sorted by `until_m`), with the
/// loop already holding the setpoint from the piezo position `start_z_m` and the
/// oscillator state `phase` (as [`super::feedback::hold`] leaves them over the first
/// region, say): [`line_probe`] with the point mass. All materials must share the
/// cantilever (its drive period sets the time), and the thermal force `force` shakes it
/// ([`ThermalForce::none`] for none). `progress` is told each pixel done. Returns the
/// pixels and the piezo position at the end.
pub fn line(
    materials: &[Prepared],
    regions: &[Region],
    shape: (f64, usize, usize),
    (lockin, controller, force): (&mut LockIn, &mut PiController, &mut ThermalForce),
    (start_z_m, repeats): (f64, &mut Repeats),
    phase: &mut Phase,
    progress: impl FnMut(usize),
) -> Result<(Vec<Pixel>, f64)> {
    let mut probe = OneMode {
        materials,
        phase,
        lockin,
        force,
    };
    let loop_ = (controller, repeats);
    line_probe(&mut probe, regions, shape, loop_, start_z_m, progress)
}

/// The first of `total` periods of `step` (m) each whose start lies past region
/// `under` of `regions`: the next region's first, or `total` after the last region.
pub(super) fn stretch_end(regions: &[Region], under: usize, (step, total): (f64, usize)) -> usize {
    if under + 1 >= regions.len() {
        return total;
    }
    let until_m = regions[under].until_m;
    let mut g = ((until_m / step).ceil().max(0.0) as usize).min(total);
    while g > 0 && step * (g - 1) as f64 >= until_m {
        g -= 1;
    }
    while g < total && step * (g as f64) < until_m {
        g += 1;
    }
    g
}

/// Refuse a layout without regions or naming a material beyond `materials`.
pub(super) fn check_regions(regions: &[Region], materials: usize) -> Result<()> {
    if regions.is_empty() || regions.iter().any(|r| r.material >= materials) {
        return Err(Error::NotApplicable(
            "a scanned sample needs regions, each naming one of its materials".into(),
        ));
    }
    Ok(())
}

/// Scan a line of length `length_m` in `pixels` pixels of `periods_per_pixel` drive
/// periods each with `probe` over its materials laid out by `regions`, the loop holding
/// the setpoint from the piezo position `start_z_m`. Each drive period is marched at the
/// material and height under the tip at its start, unless `repeats` finds the loop
/// repeating itself over the region: the periods up to the next region are then the
/// last one's repeats ([`Repeats`]; [`Repeats::exact`] marches every one). `progress` is
/// told each pixel done. Returns the pixels and the piezo position at the end.
pub fn line_probe<P: Probe>(
    probe: &mut P,
    regions: &[Region],
    (length_m, pixels, periods_per_pixel): (f64, usize, usize),
    (controller, repeats): (&mut PiController, &mut Repeats),
    start_z_m: f64,
    mut progress: impl FnMut(usize),
) -> Result<(Vec<Pixel>, f64)> {
    check_regions(regions, probe.materials())?;
    crate::error::positive("scan length", length_m)?;
    if pixels == 0 || periods_per_pixel == 0 {
        return Err(Error::NotApplicable(
            "a scan line needs at least one pixel of at least one drive period".into(),
        ));
    }
    let a0 = probe.free_amplitude_m();
    let modes = probe.modes();
    let cycle = probe.cycle();
    let step = length_m / (pixels * periods_per_pixel) as f64;
    let total = pixels * periods_per_pixel;
    // The region under the tip: x only grows, so the index only moves on.
    let mut under = 0;
    let mut z = start_z_m;
    let mut out = Vec::with_capacity(pixels);
    // The last cycle's readings, oldest first; while repeating, replayed in order.
    let mut recent: Vec<(Readings, f64)> = Vec::with_capacity(cycle);
    let (mut repeat_until, mut replayed) = (0, 0);
    repeats.restart();
    let mut sum = [0.0; 4];
    let mut higher = [(0.0, 0.0); MAX_MODES];
    for g in 0..total {
        let x = step * g as f64;
        while under + 1 < regions.len() && x >= regions[under].until_m {
            under += 1;
            repeats.restart();
            recent.clear();
            repeat_until = 0;
        }
        let region = &regions[under];
        // The piezo during the period (the controller moves it at its end).
        let during = z;
        let (read, error) = if g < repeat_until {
            repeats.skip();
            replayed += 1;
            recent[(replayed - 1) % cycle]
        } else {
            let read = probe.march(region.material, z - region.height_m, 1)?;
            let (dz, error) = controller.update(read[0].0);
            z += dz * a0;
            if recent.len() == cycle {
                recent.remove(0);
            }
            recent.push((read, error));
            if probe.repeats_itself(repeats, [z / a0, error]) && recent.len() == cycle {
                // Whole cycles up to the next region (or the line's end) repeat this one.
                let end = stretch_end(regions, under, (step, total));
                repeat_until = g + 1 + (end - g - 1) / cycle * cycle;
                replayed = 0;
            }
            (read, error)
        };
        let (amplitude, phase_deg) = read[0];
        for (s, v) in sum.iter_mut().zip([during, amplitude, error, phase_deg]) {
            *s += v;
        }
        for (s, r) in higher.iter_mut().zip(&read).take(modes).skip(1) {
            s.0 += r.0;
            s.1 += r.1;
        }
        if (g + 1) % periods_per_pixel != 0 {
            continue;
        }
        let i = g / periods_per_pixel;
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
            modes: (1..modes)
                .map(|k| ModeReading {
                    mode: k + 1,
                    amplitude_ratio: higher[k].0 / n,
                    phase_deg: higher[k].1 / n,
                })
                .collect(),
        });
        sum = [0.0; 4];
        higher = [(0.0, 0.0); MAX_MODES];
        progress(i + 1);
    }
    Ok((out, z))
}

/// The material under pixel `i` of `pixels` along a line of length `length_m` crossing
/// `regions`, if the pixel and the one before it lie wholly in one region (the loop has
/// had a pixel to settle there): what a pixel-to-pixel statistic of a material may use.
pub fn settled_material(
    regions: &[Region],
    length_m: f64,
    pixels: usize,
    i: usize,
) -> Option<usize> {
    if i == 0 || i >= pixels {
        return None;
    }
    let w = length_m / pixels as f64;
    let (from, to) = ((i - 1) as f64 * w, (i + 1) as f64 * w);
    let mut start = 0.0;
    for r in regions {
        if from >= start - 1e-12 * length_m && to <= r.until_m + 1e-12 * length_m {
            return Some(r.material);
        }
        if r.until_m > from {
            return None;
        }
        start = r.until_m;
    }
    None
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

/// A disc of one material laid over the stripes of a [`Layout`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Disc {
    /// Its centre (x, y), in m.
    pub centre_m: (f64, f64),
    /// Its radius, in m.
    pub radius_m: f64,
    /// Its material: an index into the sample's materials.
    pub material: usize,
    /// Its surface height, in m.
    pub height_m: f64,
}

/// A grid of cells over the whole sample, each a material and a surface height or
/// nothing (what lies beneath shows), as a mask image gives them: `rows` rows of `columns`
/// cells, the first row the top of the image (the largest y).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Mask {
    /// Cells per row.
    pub columns: usize,
    /// Rows, top first, each `columns` cells: (material, height in m) or nothing.
    pub cells: Vec<Vec<Option<(usize, f64)>>>,
    /// The extent it covers: the line's length and the image's width, in m.
    pub size_m: (f64, f64),
}

/// A sample's layout in the plane: stripes along x that run across the whole width
/// (as [`Region`]s), a mask laid over them where its cells say so, and discs over both
/// (a later disc over an earlier one).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Layout {
    /// The stripes, sorted by `until_m`, the last reaching the end of the line.
    pub stripes: Vec<Region>,
    /// The mask.
    pub mask: Option<Mask>,
    /// The discs.
    pub discs: Vec<Disc>,
}

impl Layout {
    /// The regions a line at `y_m` crosses: the stripes, cut where the mask's cells in
    /// that row and a disc's chord at that y begin and end, neighbours of the same
    /// material and height merged.
    pub fn line_at(&self, y_m: f64, length_m: f64) -> Vec<Region> {
        let row = self.mask.as_ref().map(|m| {
            let rows = m.cells.len();
            let from_top = ((m.size_m.1 - y_m) / m.size_m.1 * rows as f64).floor();
            let cell_m = m.size_m.0 / m.columns as f64;
            (&m.cells[(from_top.max(0.0) as usize).min(rows - 1)], cell_m)
        });
        let chords: Vec<(f64, f64, &Disc)> = self
            .discs
            .iter()
            .filter_map(|d| {
                let dy = y_m - d.centre_m.1;
                let half = (d.radius_m * d.radius_m - dy * dy).sqrt();
                (half > 0.0).then_some((d.centre_m.0 - half, d.centre_m.0 + half, d))
            })
            .collect();
        let mut cuts: Vec<f64> = self.stripes.iter().map(|r| r.until_m).collect();
        cuts.extend(chords.iter().flat_map(|&(a, b, _)| [a, b]));
        if let Some((cells, cell_m)) = row {
            cuts.extend((1..cells.len()).map(|i| i as f64 * cell_m));
        }
        cuts.retain(|&c| c > 0.0 && c < length_m);
        cuts.push(length_m);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let mut out: Vec<Region> = Vec::with_capacity(cuts.len());
        let mut start = 0.0;
        for until_m in cuts {
            let mid = 0.5 * (start + until_m);
            let stripe = self
                .stripes
                .iter()
                .find(|r| mid < r.until_m)
                .or(self.stripes.last())
                .expect("a layout has stripes");
            let masked = row
                .and_then(|(cells, cell_m)| cells[((mid / cell_m) as usize).min(cells.len() - 1)]);
            let beneath = masked.unwrap_or((stripe.material, stripe.height_m));
            let (material, height_m) = chords
                .iter()
                .rev()
                .find(|&&(a, b, _)| a <= mid && mid < b)
                .map_or(beneath, |&(_, _, d)| (d.material, d.height_m));
            match out.last_mut() {
                Some(last) if last.material == material && last.height_m == height_m => {
                    last.until_m = until_m;
                }
                _ => out.push(Region {
                    until_m,
                    material,
                    height_m,
                }),
            }
            start = until_m;
        }
        out
    }
}

/// One line of an image as [`row_probe`] scans it with the point mass over `materials`,
/// read by `lockin`, under the thermal force `force`.
pub fn row(
    materials: &[Prepared],
    regions: &[Region],
    shape: (f64, usize, usize),
    (lockin, controller, force): (LockIn, PiController, ThermalForce),
    engage: (usize, &mut Repeats),
    retrace: bool,
    progress: impl FnMut(usize),
) -> Result<(Vec<Pixel>, Option<Vec<Pixel>>)> {
    let (mut lockin, mut force) = (lockin, force);
    check_regions(regions, materials.len())?;
    let mut phase = materials[regions[0].material]
        .simulation()
        .free_steady_start();
    let mut probe = OneMode {
        materials,
        phase: &mut phase,
        lockin: &mut lockin,
        force: &mut force,
    };
    row_probe(
        &mut probe, regions, shape, controller, engage, retrace, progress,
    )
}

/// One line of an image: the loop engaged over the first region from 1.2 A₀
/// (`engage_periods` drive periods, [`super::feedback::hold_probe`]), then the line
/// scanned ([`line_probe`], periods where the loop repeats itself skipped as `repeats`
/// says) and, with `retrace`, scanned back (its pixels in the trace's x).
pub fn row_probe<P: Probe>(
    probe: &mut P,
    regions: &[Region],
    (length_m, pixels, periods_per_pixel): (f64, usize, usize),
    controller: PiController,
    (engage_periods, repeats): (usize, &mut Repeats),
    retrace: bool,
    mut progress: impl FnMut(usize),
) -> Result<(Vec<Pixel>, Option<Vec<Pixel>>)> {
    let mut controller = controller;
    check_regions(regions, probe.materials())?;
    let a0 = probe.free_amplitude_m();
    let (_, rest) = super::feedback::hold_probe(
        probe,
        regions[0].material,
        1.2 * a0,
        (&mut controller, &mut *repeats),
        engage_periods,
    )?;
    // The loop holds the rest separation; the piezo stands that much above the surface.
    let z = rest + regions[0].height_m;
    let shape = (length_m, pixels, periods_per_pixel);
    let loop_ = (&mut controller, &mut *repeats);
    let (trace, end) = line_probe(probe, regions, shape, loop_, z, &mut progress)?;
    if !retrace {
        return Ok((trace, None));
    }
    let back = mirrored(regions, length_m);
    let loop_ = (&mut controller, repeats);
    let (mut retrace, _) = line_probe(probe, &back, shape, loop_, end, progress)?;
    for p in &mut retrace {
        p.x_m = length_m - p.x_m;
    }
    Ok((trace, Some(retrace)))
}
