//! Part files of a job split over machines (`tapsim map --shard I/N`, `tapsim batch
//! --shard I/N`, `tapsim scan --lines N --shard I/N`) and their merge (`tapsim merge`). A
//! part file is one JSON object: a header (format, tapsim version, a hash of the whole
//! configuration, N, I, what the job is, the numbers of the part's items: a map's cells,
//! a batch's cases, an image's lines) and each item's
//! records, floats written so they read back bit for bit. Merging checks that the parts
//! belong together and cover every item exactly once, and gives the records in the
//! order one whole run gives them.
//!
//! A part file is input like any other: before anything is sized or drawn from it,
//! [`merge`] checks its job as `map` and `batch` check theirs (axes a real log grid of
//! at most [`crate::analysis::sweep::MAX_MAP_STEPS`] points, from 1 to [`MAX_CASES`] cases), recomputes the
//! configuration hash from the configuration the part carries, counts each item's
//! records, checks that a map record is the cell it stands for, and recomputes the
//! checksum of the records; any mismatch is refused, naming the file and the field.

use crate::analysis::sweep::{MAX_SWEEP_POINTS, Shard, log_grid};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use serde_json::value::RawValue;

/// The most cases a batch can have.
pub const MAX_CASES: usize = 100_000;

/// What a part file says it is.
pub const FORMAT: &str = "tapsim-part";

/// The amplitude setpoint of a map: every cell solved where A/A₀ is `amplitude_ratio`
/// on `branch`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSetpoint {
    /// A/A₀.
    pub amplitude_ratio: f64,
    /// The branch.
    pub branch: crate::analysis::setpoint::PhaseBranch,
}

impl MapSetpoint {
    /// How titles name it: "A/A₀ = 0.8, repulsive branch".
    pub fn caption(&self) -> String {
        format!("A/A₀ = {}, {} branch", self.amplitude_ratio, self.branch)
    }
}

/// The job a part belongs to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Job {
    /// `tapsim map`: one record per cell.
    Map {
        /// The law, as the map's outputs name it.
        law: String,
        /// The work-of-adhesion axis in J/m².
        work_of_adhesion_j_m2: Vec<f64>,
        /// The modulus axis in Pa.
        modulus_pa: Vec<f64>,
        /// The amplitude setpoint every cell is solved at, if any (else one rest
        /// separation).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        setpoint: Option<MapSetpoint>,
    },
    /// `tapsim batch`: one record per tap case, one per setpoint of an approach case.
    Batch {
        /// The number of cases.
        cases: usize,
    },
    /// `tapsim map --mode peakforce`: one record per cell, each at the peak-force
    /// setpoint.
    QnmMap {
        /// The law, as the map's outputs name it.
        law: String,
        /// The work-of-adhesion axis in J/m².
        work_of_adhesion_j_m2: Vec<f64>,
        /// The modulus axis in Pa.
        modulus_pa: Vec<f64>,
        /// The peak-force setpoint in N.
        peak_force_n: f64,
    },
    /// `tapsim scan --mode peakforce --lines N`: one record per pixel, each line an item.
    QnmScan {
        /// Lines of the image.
        lines: usize,
        /// Pixels a line.
        pixels: usize,
        /// Whether each line is scanned back too.
        retrace: bool,
        /// The peak-force setpoint in N.
        peak_force_n: f64,
        /// What an image file needs beyond the records.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        image: Option<ImageInfo>,
    },
    /// `tapsim scan --mode fm --lines N`: one record per pixel, each line an item.
    FmScan {
        /// Lines of the image.
        lines: usize,
        /// Pixels a line.
        pixels: usize,
        /// Whether each line is scanned back too.
        retrace: bool,
        /// The frequency-shift setpoint in Hz.
        frequency_shift_hz: f64,
        /// What an image file needs beyond the records.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        image: Option<ImageInfo>,
    },
    /// `tapsim scan --lines N`: one record per pixel, each line an item.
    Scan {
        /// Lines of the image.
        lines: usize,
        /// Pixels a line.
        pixels: usize,
        /// Whether each line is scanned back too.
        retrace: bool,
        /// The amplitude setpoint A/A₀.
        setpoint: f64,
        /// What an image file needs beyond the records.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        image: Option<ImageInfo>,
    },
}

/// What a scanned image's Gwyddion file needs beyond its pixel records: the scanned
/// area's size and the run's parameters as metadata.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageInfo {
    /// The image's x and y extents, m.
    pub size_m: (f64, f64),
    /// The run's parameters, (name, value).
    pub meta: Vec<(String, String)>,
}

impl Job {
    /// How many items the whole job has.
    pub fn items(&self) -> usize {
        match self {
            Job::Map {
                work_of_adhesion_j_m2,
                modulus_pa,
                ..
            } => work_of_adhesion_j_m2.len().saturating_mul(modulus_pa.len()),
            Job::QnmMap {
                work_of_adhesion_j_m2,
                modulus_pa,
                ..
            } => work_of_adhesion_j_m2.len().saturating_mul(modulus_pa.len()),
            Job::Batch { cases } => *cases,
            Job::Scan { lines, .. } | Job::QnmScan { lines, .. } | Job::FmScan { lines, .. } => {
                *lines
            }
        }
    }

    /// Check the job as the command that runs it checks its input: a map's axes are
    /// each a log grid of 2 to [`crate::analysis::sweep::MAX_MAP_STEPS`] positive values, ascending (what
    /// [`log_grid`] gives for their ends and length, bit for bit); a batch holds from 1
    /// to [`MAX_CASES`] cases. `name` is the file the job was read from.
    pub fn validate(&self, name: &str) -> Result<()> {
        let peak_force = |f: f64| {
            crate::instrument::peakforce::check_setpoint(f).map_err(|e| {
                Error::NotApplicable(format!(
                    "{name}: job.peak_force_n {e}: not a part tapsim wrote"
                ))
            })
        };
        let refuse = |field: &str, why: String| {
            Error::NotApplicable(format!(
                "{name}: job.{field} {why}: not a part tapsim wrote"
            ))
        };
        match self {
            Job::QnmMap {
                law,
                work_of_adhesion_j_m2,
                modulus_pa,
                peak_force_n,
            } => {
                peak_force(*peak_force_n)?;
                Self::map_axes(name, law, work_of_adhesion_j_m2, modulus_pa)
            }
            Job::Map {
                law,
                work_of_adhesion_j_m2,
                modulus_pa,
                setpoint,
            } => {
                if setpoint.is_some_and(|s| !(s.amplitude_ratio > 0.0 && s.amplitude_ratio < 1.0)) {
                    return Err(refuse(
                        "setpoint",
                        "is not an amplitude setpoint between 0 and 1".into(),
                    ));
                }
                Self::map_axes(name, law, work_of_adhesion_j_m2, modulus_pa)
            }
            Job::Batch { cases } => {
                if !(1..=MAX_CASES).contains(cases) {
                    return Err(refuse(
                        "cases",
                        format!("is {cases}: a batch holds from 1 to {MAX_CASES} cases"),
                    ));
                }
                Ok(())
            }
            Job::QnmScan {
                lines,
                pixels,
                peak_force_n,
                ..
            } => {
                peak_force(*peak_force_n)?;
                Self::image(name, *lines, *pixels)
            }
            Job::FmScan {
                lines,
                pixels,
                frequency_shift_hz,
                ..
            } => {
                if !(frequency_shift_hz.is_finite() && *frequency_shift_hz != 0.0) {
                    return Err(refuse(
                        "frequency_shift_hz",
                        "is not a frequency-shift setpoint (finite, not zero)".into(),
                    ));
                }
                Self::image(name, *lines, *pixels)
            }
            Job::Scan {
                lines,
                pixels,
                setpoint,
                ..
            } => {
                if !(*setpoint > 0.0 && *setpoint < 1.0) {
                    return Err(refuse(
                        "setpoint",
                        "is not an amplitude setpoint between 0 and 1".into(),
                    ));
                }
                Self::image(name, *lines, *pixels)
            }
        }
    }

    /// Refuse a law name or map axes `tapsim map` would not write.
    fn map_axes(name: &str, law: &str, works: &[f64], moduli: &[f64]) -> Result<()> {
        let refuse = |field: &str, why: String| {
            Error::NotApplicable(format!(
                "{name}: job.{field} {why}: not a part tapsim wrote"
            ))
        };
        if law.is_empty() || law.len() > 64 {
            return Err(refuse("law", "is not a law's name".into()));
        }
        for (field, axis) in [("work_of_adhesion_j_m2", works), ("modulus_pa", moduli)] {
            let (Some(&lo), Some(&hi)) = (axis.first(), axis.last()) else {
                return Err(refuse(field, "is empty".into()));
            };
            let grid = log_grid("axis", lo, hi, axis.len())
                .map_err(|e| refuse(field, format!("is not an axis tapsim map takes ({e})")))?;
            if grid
                .iter()
                .zip(axis)
                .any(|(a, b)| a.to_bits() != b.to_bits())
            {
                return Err(refuse(
                    field,
                    format!(
                        "is not the log grid of {} points from {lo:e} to {hi:e}",
                        axis.len()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Refuse an image's size `tapsim scan` would not scan.
    fn image(name: &str, lines: usize, pixels: usize) -> Result<()> {
        use crate::instrument::scan::{MAX_IMAGE_PIXELS, MAX_PIXELS};
        if !(1..=MAX_PIXELS).contains(&lines)
            || !(1..=MAX_PIXELS).contains(&pixels)
            || lines * pixels > MAX_IMAGE_PIXELS
        {
            return Err(Error::NotApplicable(format!(
                "{name}: job.lines and pixels are {lines} and {pixels}: from 1 to {MAX_PIXELS} \
                 each, at most {MAX_IMAGE_PIXELS} in all: not a part tapsim wrote"
            )));
        }
        Ok(())
    }

    /// What an item is called: a map's cell, a batch's case, an image's line.
    fn item_name(&self) -> &'static str {
        match self {
            Job::Map { .. } | Job::QnmMap { .. } => "cell",
            Job::Batch { .. } => "case",
            Job::Scan { .. } | Job::QnmScan { .. } | Job::FmScan { .. } => "line",
        }
    }

    /// The records one item has: a map cell's one, a scan line's pixels, trace (and
    /// retrace); `None` where it varies (a batch case).
    fn records_per_item(&self) -> Option<usize> {
        match self {
            Job::Map { .. } | Job::QnmMap { .. } => Some(1),
            Job::Batch { .. } => None,
            Job::Scan {
                pixels, retrace, ..
            }
            | Job::QnmScan {
                pixels, retrace, ..
            }
            | Job::FmScan {
                pixels, retrace, ..
            } => Some(pixels * if *retrace { 2 } else { 1 }),
        }
    }
}

/// What determines a job's results, carried in its parts so that [`merge`] can
/// recompute their hash: for a map one configuration for every cell, for a batch each
/// case's own (a part carries only its cases').
#[derive(Debug, Clone)]
pub enum Config {
    /// The same for every item.
    Whole(Value),
    /// Item k's configuration at index k.
    PerItem(Vec<Value>),
}

/// One part of a job. A key it does not know is refused (a part another program
/// edited, or a newer tapsim's, is not merged as if it were this one's).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Part {
    /// Always [`FORMAT`].
    pub format: String,
    /// The tapsim version that wrote it.
    pub tapsim_version: String,
    /// Hash of everything that determines the job ([`config_hash`]).
    pub config_hash: String,
    /// N, the number of parts.
    pub shards: usize,
    /// I, this part's number (from 0).
    pub shard: usize,
    /// The job.
    pub job: Job,
    /// The configuration every item shares (a map's; null for a batch).
    pub config: Value,
    /// Each of this part's items' own configuration, in the order of `items` (a batch's
    /// cases; empty for a map).
    pub item_configs: Vec<Value>,
    /// The items this part computed, by number.
    pub items: Vec<usize>,
    /// Each item's records (kept as their JSON text), in the same order.
    pub records: Vec<Vec<Box<RawValue>>>,
    /// FNV-1a of the items and their records as written ([`records_checksum`]).
    pub records_checksum: String,
}

impl Part {
    /// Part `shard` of `job` with these items and records, stamped with this build's
    /// version, the hash of `config` and `job` ([`job_hash`]) and the checksum of the
    /// records.
    pub fn new(
        shard: Shard,
        job: Job,
        config: &Config,
        items: Vec<usize>,
        records: Vec<Vec<Box<RawValue>>>,
    ) -> Self {
        let (common, item_configs) = match config {
            Config::Whole(c) => (c.clone(), Vec::new()),
            Config::PerItem(all) => (Value::Null, items.iter().map(|&k| all[k].clone()).collect()),
        };
        Self {
            format: FORMAT.into(),
            tapsim_version: env!("CARGO_PKG_VERSION").into(),
            config_hash: job_hash(&job, config),
            shards: shard.count,
            shard: shard.index,
            job,
            config: common,
            item_configs,
            records_checksum: records_checksum(&items, &records)
                .expect("records tapsim wrote are JSON"),
            items,
            records,
        }
    }
}

/// The hash of a job and what determines its results: this build's version, `job` and
/// `config` (for a batch, every case's configuration in order).
pub fn job_hash(job: &Job, config: &Config) -> String {
    let config = match config {
        Config::Whole(c) => serde_json::json!({ "whole": c }),
        Config::PerItem(all) => serde_json::json!({ "per_item": all }),
    };
    config_hash(&serde_json::json!({ "job": job, "config": config }))
}

/// FNV-1a of `items` and their `records`: what a part file's `records_checksum` holds.
/// Each record enters as its canonical JSON (parsed and written again), so re-indenting
/// a part file or re-writing its numbers in another notation keeps it valid, while any
/// change of a value, a key, the keys' order or the records' order does not; `None`
/// where a record is no JSON.
pub fn records_checksum(items: &[usize], records: &[Vec<Box<RawValue>>]) -> Option<String> {
    let mut h = crate::app::fnv::OFFSET;
    for (k, item) in items.iter().zip(records) {
        h = crate::app::fnv::continued(h, format!("item {k}: {} records\n", item.len()).as_bytes());
        for r in item {
            let canonical: Value = serde_json::from_str(r.get()).ok()?;
            h = crate::app::fnv::continued(h, canonical.to_string().as_bytes());
            h = crate::app::fnv::continued(h, b"\n");
        }
    }
    Some(format!("{h:016x}"))
}

/// A hash of the tapsim version and `config` (everything that determines a job's
/// results): parts with equal hashes were computed for the same job.
pub fn config_hash(config: &impl Serialize) -> String {
    let config = serde_json::json!({
        "tapsim_version": env!("CARGO_PKG_VERSION"),
        "config": config,
    });
    format!(
        "{:016x}",
        crate::app::fnv::hash(config.to_string().as_bytes())
    )
}

/// Numbers as `sbatch --array=` takes them: runs of consecutive ones as ranges ("2,5-7").
pub fn array_spec(numbers: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < numbers.len() {
        let mut j = i;
        while j + 1 < numbers.len() && numbers[j + 1] == numbers[j] + 1 {
            j += 1;
        }
        out.push(if j == i {
            numbers[i].to_string()
        } else {
            format!("{}-{}", numbers[i], numbers[j])
        });
        i = j + 1;
    }
    out.join(",")
}

/// A merged job: what it is and every record in the order of a whole run.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The job.
    pub job: Job,
    /// Every record, as its JSON text.
    pub records: Vec<Box<RawValue>>,
}

/// The records of `item` as JSON texts (what a part file keeps: a tenth of the memory
/// of parsed objects), each an object with every key once (a field a record flattens in
/// twice, such as a map cell's `tabor_mu`, is written once, where it first appears).
pub fn raw_records<T: Serialize>(item: &[T]) -> Result<Vec<Box<RawValue>>> {
    let fail = |e: serde_json::Error| Error::Output {
        path: "part file".into(),
        reason: e.to_string(),
    };
    item.iter()
        .map(|r| {
            let object = serde_json::to_value(r).map_err(fail)?;
            serde_json::value::to_raw_value(&object).map_err(fail)
        })
        .collect()
}

/// Check one part read from `name` on its own, before anything is sized by it: its
/// header, its job ([`Job::validate`]), its split, that it holds exactly its items with
/// the records each should have, the checksum of those records and, for a map, that
/// each record is the cell it stands for and the configuration hash.
fn check(name: &str, p: &Part) -> Result<Shard> {
    let refuse = |field: &str, why: String| Error::NotApplicable(format!("{name}: {field} {why}"));
    if p.format != FORMAT {
        return Err(refuse(
            "format",
            "is not \"tapsim-part\": not a tapsim part file".into(),
        ));
    }
    let version = env!("CARGO_PKG_VERSION");
    if p.tapsim_version != version {
        return Err(refuse(
            "tapsim_version",
            format!(
                "is {:?}, this is tapsim {version}: merge parts with the tapsim that wrote them",
                p.tapsim_version
            ),
        ));
    }
    let shard = Shard::new(p.shard, p.shards).map_err(|e| refuse("shard", e.to_string()))?;
    p.job.validate(name)?;
    let total = p.job.items();
    if p.items != shard.items(total) {
        return Err(refuse(
            "items",
            format!(
                "are not those of part {} of {} of a {total}-item job: it was changed or cut short",
                p.shard, p.shards
            ),
        ));
    }
    if p.records.len() != p.items.len() {
        return Err(refuse(
            "records",
            format!(
                "hold {} items' records for {} items",
                p.records.len(),
                p.items.len()
            ),
        ));
    }
    if !matches!(p.job, Job::Batch { .. }) {
        if !p.item_configs.is_empty() || !p.config.is_array() {
            return Err(refuse(
                "config",
                "is not a whole job's configuration".into(),
            ));
        }
        if job_hash(&p.job, &Config::Whole(p.config.clone())) != p.config_hash {
            return Err(refuse(
                "config_hash",
                "does not match the job and configuration the part holds: it was changed after tapsim wrote it"
                    .into(),
            ));
        }
    }
    if let Some(each) = p.job.records_per_item()
        && let Some((k, item)) = p
            .items
            .iter()
            .zip(&p.records)
            .find(|(_, r)| r.len() != each)
    {
        let name = p.job.item_name();
        return Err(refuse(
            "records",
            format!(
                "hold {} records for {name} {k}; a {name} has {each}",
                item.len()
            ),
        ));
    }
    match &p.job {
        Job::Map {
            work_of_adhesion_j_m2: works,
            modulus_pa: moduli,
            ..
        }
        | Job::QnmMap {
            work_of_adhesion_j_m2: works,
            modulus_pa: moduli,
            ..
        } => {
            for (&k, item) in p.items.iter().zip(&p.records) {
                let record = &item[0];
                #[derive(Deserialize)]
                struct At {
                    work_of_adhesion_j_m2: f64,
                    modulus_pa: f64,
                }
                let at: At = serde_json::from_str(record.get()).map_err(|e| {
                    refuse("records", format!("hold cell {k} as no map record: {e}"))
                })?;
                let (w, m) = (works[k % works.len()], moduli[k / works.len()]);
                if at.work_of_adhesion_j_m2.to_bits() != w.to_bits()
                    || at.modulus_pa.to_bits() != m.to_bits()
                {
                    return Err(refuse(
                        "records",
                        format!(
                            "hold for cell {k} the record of ({:e} J/m², {:e} Pa), not of \
                             ({w:e} J/m², {m:e} Pa)",
                            at.work_of_adhesion_j_m2, at.modulus_pa
                        ),
                    ));
                }
            }
        }
        Job::Batch { .. } => {
            if !p.config.is_null() || p.item_configs.len() != p.items.len() {
                return Err(refuse(
                    "item_configs",
                    format!(
                        "hold {} cases' configurations for {} cases",
                        p.item_configs.len(),
                        p.items.len()
                    ),
                ));
            }
            // A tap case has one record, an approach one per setpoint (or one note).
            let most = 2 * MAX_SWEEP_POINTS;
            for (&k, item) in p.items.iter().zip(&p.records) {
                if item.is_empty() || item.len() > most {
                    return Err(refuse(
                        "records",
                        format!("hold {} records for case {k}: from 1 to {most}", item.len()),
                    ));
                }
            }
        }
        Job::Scan { .. } | Job::QnmScan { .. } | Job::FmScan { .. } => {
            for (&k, item) in p.items.iter().zip(&p.records) {
                #[derive(Deserialize)]
                struct On {
                    line: usize,
                }
                for record in item {
                    let on: On = serde_json::from_str(record.get()).map_err(|e| {
                        refuse("records", format!("hold line {k} as no scan record: {e}"))
                    })?;
                    if on.line != k {
                        return Err(refuse(
                            "records",
                            format!("hold for line {k} a pixel of line {}", on.line),
                        ));
                    }
                }
            }
        }
    }
    if records_checksum(&p.items, &p.records).as_ref() != Some(&p.records_checksum) {
        return Err(refuse(
            "records",
            "do not match records_checksum: the records were changed after tapsim wrote them"
                .into(),
        ));
    }
    Ok(shard)
}

/// Merge `parts` (each with the name it was read from): check each (`check`), refuse
/// parts of different jobs or of a different split, a part given twice, and any missing
/// part, naming the missing part numbers as `sbatch --array=` takes them; for a batch,
/// whose parts carry only their own cases' configurations, recompute the hash once all
/// are there.
pub fn merge(parts: Vec<(String, Part)>) -> Result<Merged> {
    let refuse = |why: String| Error::NotApplicable(why);
    let Some((first_name, first)) = parts.first() else {
        return Err(refuse("no part files to merge".into()));
    };
    for (name, p) in &parts {
        check(name, p)?;
    }
    for (name, p) in &parts {
        if p.config_hash != first.config_hash || p.job != first.job {
            return Err(refuse(format!(
                "{name} belongs to another job than {first_name} (configuration {} against \
                 {}): merge the parts of one run",
                p.config_hash, first.config_hash
            )));
        }
        if p.shards != first.shards {
            return Err(refuse(format!(
                "{name} is part {} of {}, {first_name} part {} of {}: merge the parts of one \
                 split",
                p.shard, p.shards, first.shard, first.shards
            )));
        }
    }
    let n = first.shards;
    let total = first.job.items();
    let mut seen: Vec<Option<&str>> = vec![None; n];
    for (name, p) in &parts {
        if let Some(earlier) = seen[p.shard] {
            return Err(refuse(format!(
                "part {} of {n} is given twice ({earlier} and {name})",
                p.shard
            )));
        }
        seen[p.shard] = Some(name);
    }
    let missing: Vec<usize> = (0..n).filter(|&i| seen[i].is_none()).collect();
    if !missing.is_empty() {
        return Err(refuse(format!(
            "{} of {n} parts missing: {} (rerun them with sbatch --array={})",
            missing.len(),
            array_spec(&missing),
            array_spec(&missing)
        )));
    }
    type Item<'a> = (&'a Vec<Box<RawValue>>, &'a Value);
    let mut by_item: Vec<Option<Item>> = vec![None; total];
    for (_, p) in &parts {
        let configs = p.item_configs.iter().chain(std::iter::repeat(&Value::Null));
        for ((&k, r), c) in p.items.iter().zip(&p.records).zip(configs) {
            by_item[k] = Some((r, c));
        }
    }
    let by_item: Vec<Item> = by_item
        .into_iter()
        .map(|r| r.expect("every item was checked to be in exactly one part"))
        .collect();
    if let Job::Batch { .. } = first.job {
        let all = Config::PerItem(by_item.iter().map(|(_, c)| (*c).clone()).collect());
        if job_hash(&first.job, &all) != first.config_hash {
            return Err(refuse(format!(
                "the parts' config_hash does not match the cases they hold ({first_name} and \
                 the rest): a part was changed after tapsim wrote it"
            )));
        }
    }
    let records = by_item
        .into_iter()
        .flat_map(|(r, _)| r.iter().cloned())
        .collect();
    Ok(Merged {
        job: first.job.clone(),
        records,
    })
}
