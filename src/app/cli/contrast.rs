//! `tapsim contrast`: phase contrast between materials under several laws.

use crate::analysis::contrast;
use crate::app::config::MaterialSpec;
use crate::app::config::TapInputs;
use crate::app::report::{contrast as report, output, plot};
use crate::error::Result;
use crate::physics::law::LawKind;
use clap::Args;

/// Phase contrast between two or more materials at the same cantilever and amplitude
/// setpoints, for several force laws side by side: how much phase contrast the classic
/// JKR law overstates relative to the hybrid and the exact Lennard-Jones law.
///
/// Each material is `name:key=value,...` with the flags' names as keys, e.g.
///   --material a:sample-modulus=0.5GPa,work-of-adhesion=0.1
///   --material b:sample-modulus=1GPa,work-of-adhesion=0.08
/// (without --material: these two). Every other `tapsim tap` option sets the common
/// cantilever and tip.
///
/// At each amplitude setpoint every steady state of each material is found, as
/// `tapsim tap --setpoint` finds them: the stable orbits of its period-1 families
/// (continued through z_c as `tapsim branches` does) at the rest separation z_c where
/// the amplitude is the setpoint, or, on a branch where there is none, the approach
/// curve's states there (orbits of higher period, irregular motion; interpolated).
/// Each lies on the attractive (φ above the free phase, 90° at resonance) or the
/// repulsive branch. Δφ = φ(last material) − φ(first) is taken only between materials
/// on the same branch; where a setpoint is bistable, both branches get a row. Beside it,
/// Δz_c = z_c(last) − z_c(first): the height step a topography image shows between the
/// materials over a flat sample, where the z feedback moves the sample to hold the
/// setpoint. The table names the motion behind every φ and compares JKR's contrast with
/// the other laws', branch by branch.
///
/// Bimodal contrast (--modes 2): with a second eigenmode driven at its resonance, the
/// states at each first-mode setpoint A₁/A₀₁ on each branch, per material and law; the
/// table gives φ₁ and φ₂ of each material and their contrasts Δφ₁ and Δφ₂ (a material
/// whose modes hold a setpoint in several states gets none, with a note listing them)
/// (JSON and CSV: law, materials, setpoint, branch, phase1_deg, phase2_deg, amplitude2_ratio,
/// e_ts_j, separation_m, stable, delta_phase1_deg, delta_phase2_deg, notes); --plot
/// draws Δφ₂ and Δφ₁ against the setpoint, a colour per law.
///
/// Can a contrast be seen? With --temperature (and --enbw, --lockin-order) each φ on a
/// stable period-1 orbit gets its thermal noise σ_φ, the standard deviation a lock-in
/// of that bandwidth reads (the linear theory about the orbit, as `tap --temperature`),
/// and each row the contrast over the noise of one reading on each material,
/// |Δφ|/√(σ_first² + σ_last²): above a few, one pixel on each tells them apart. A φ
/// from other motion (a long mode lock, irregular) has no σ: its noise is not that of a
/// small perturbation.
///
/// JSON (--json): columns (one array per key, an entry per law, setpoint and branch,
/// after format_version): law, materials,
/// amplitude_ratio, branch, phase_deg, regime, converged, grazing, separation_m, e_ts_j,
/// e_ts_adhesion_j, e_ts_viscous_j and e_ts_capillary_j (one entry per material, null
/// where it has no steady state on that branch), delta_phase_deg and
/// apparent_height_m; with --temperature also noise (temperature_k, lockin_order,
/// enbw_hz), sigma_phase_deg (per material) and contrast_to_noise. --csv has the same, a column per material. --plot: φ and E_ts (and
/// a viscous sample's share) against A/A₀ per law, and Δφ against the setpoint.
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ContrastArgs {
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    /// A material, name:key=value,... (repeat; at least two).
    #[arg(long = "material", value_parser = MaterialSpec::parse)]
    materials: Vec<MaterialSpec>,
    /// Laws to compare.
    #[arg(long, value_enum, ignore_case = true, value_delimiter = ',', default_values_t = [LawKind::Jkr, LawKind::Hybrid, LawKind::Lj])]
    laws: Vec<LawKind>,
    /// Amplitude setpoints A/A₀, each between 0 and 1.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true,
          value_parser = crate::app::config::number, default_values_t = [0.9, 0.8, 0.7, 0.6, 0.5])]
    setpoints: Vec<f64>,
    /// Setpoints on each approach curve.
    #[arg(long, allow_hyphen_values = true, default_value_t = 50)]
    points: usize,
    #[command(flatten)]
    pub(super) noise: super::NoiseArgs,
    #[command(flatten)]
    modes: crate::app::config::ModeInputs,
}

/// Run the subcommand.
pub fn run(args: ContrastArgs) -> Result<()> {
    let mut base = args.inputs.with_config()?;
    base.no_setpoint("contrast")?;
    base.takes_modes = true;
    let materials = if args.materials.is_empty() {
        MaterialSpec::defaults()?
    } else {
        args.materials.clone()
    };
    let quiet = args.out.quiet;
    let materials = materials
        .iter()
        .map(|m| m.resolve(&base))
        .collect::<Result<Vec<_>>>()?;
    if let Some(set) = args
        .modes
        .mode_set(&base.mode_file, &materials[0].setup.cantilever)?
    {
        super::modal::refuse(args.noise.temperature.is_some(), "--temperature")?;
        return super::modal::contrast(&materials, &set, &args.laws, &args.setpoints, &args.out);
    }
    let request = args.noise.request();
    if let Some(request) = &request {
        request.check(materials[0].setup.cantilever.drive_frequency_hz)?;
    }
    let (rows, curves) = contrast::contrast(
        &materials,
        &args.laws,
        (&args.setpoints, args.points),
        request.as_ref(),
        |what| {
            if !quiet {
                eprintln!("approach curves and orbit families: {what}");
            }
        },
    )?;
    if let Some(path) = &args.out.csv {
        let bytes =
            report::contrast_csv(&rows, &materials).map_err(|reason| crate::Error::Output {
                path: path.clone(),
                reason,
            })?;
        output::write_bytes(path, &bytes)?;
    }
    if let Some(path) = &args.out.plot {
        plot::render_stack(
            &report::contrast_charts(&args.laws, &materials, &rows, &curves),
            path,
        )?;
    }
    if args.out.json {
        outln!(
            "{}",
            crate::app::report::records::document(&crate::app::report::records::columns_json(
                &rows
            )?)?
        );
    } else {
        out!("{}", report::contrast_text(&args.laws, &rows));
    }
    Ok(())
}
