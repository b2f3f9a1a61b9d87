//! `tapsim batch`: independent tap and approach runs from a table, in parallel and
//! shardable like a map.

use crate::analysis::sweep::{self, Shard};
use crate::app::config::TapInputs;
use crate::app::report::part::{self, Job, MAX_CASES};
use crate::app::report::records;
use crate::error::{Error, Result};
use clap::Args;
use serde_json::value::RawValue;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// Run one independent simulation per row of a table: a `tapsim tap` (the default) or a
/// `tapsim approach` (column command = approach), in parallel, each on its own core.
///
/// The table is CSV (a header row of column names) or TOML (an array of tables
/// [[case]]). Columns: any `tapsim tap` option by its flag's name (law, radius,
/// sample-modulus, work-of-adhesion, separation, quality, viscosity, …, with units as on
/// the command line; an empty cell keeps the default), and
///   name      the case's name (default: its row number, from 1)
///   command   tap or approach
///   setpoint, branch   a tap case at an amplitude setpoint A/A₀ instead of a rest
///             separation (as `tapsim tap --setpoint`): a row per state there, each with
///             its branch and separation_m; branch attractive, repulsive or all
///   points, from, to, no-retract   an approach's setpoints (as `tapsim approach`)
/// Options given on the command line apply to every row that does not set them.
///
/// A row with a value tapsim refuses (unreadable, or outside what `tapsim tap` accepts,
/// such as a 1 mm tip) refuses the whole batch before any case runs, naming the row; a
/// case where the law does not apply (a law outside its μ range) gets a note instead of
/// observables, as a map cell does.
///
/// Output: CSV on stdout (or --csv FILE), or --json (one object of equal-length
/// columns): one row per tap case (case, command, and every observable of `tapsim tap
/// --json`; a note where the law does not apply), one row per setpoint of an approach
/// case (an approach is one sequential job: its setpoints are never split).
///
/// --shard I/N runs every N-th case (number ≡ I mod N) into a part file for `tapsim
/// merge`, as `tapsim map` does (inside a Slurm array task, I and N come from it).
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct BatchArgs {
    /// The table (.csv or .toml).
    table: PathBuf,
    #[command(flatten)]
    inputs: TapInputs,
    #[command(flatten)]
    pub(super) out: super::SweepOutput,
    /// Worker threads (0: all cores).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    threads: usize,
    #[command(flatten)]
    split: super::shard::ShardArgs,
}

/// The largest table read, in bytes.
const MAX_TABLE_BYTES: u64 = 16 * 1024 * 1024;

/// What a case runs.
#[derive(Debug, Clone, serde::Serialize)]
enum Run {
    Tap,
    /// A tap at an amplitude setpoint: every state there, on one branch or both.
    Setpoint {
        ratio: f64,
        branch: Option<crate::analysis::setpoint::PhaseBranch>,
    },
    Approach {
        points: usize,
        from: Option<f64>,
        to: Option<f64>,
        retract: bool,
    },
}

/// One row of the table, resolved.
#[derive(Debug, Clone, serde::Serialize)]
struct Case {
    name: String,
    run: Run,
    setup: crate::dynamics::setup::TapSetup,
    numerics: crate::dynamics::setup::Numerics,
}

/// The cells of one row: (column, text), empty cells left out.
type Row = Vec<(String, String)>;

fn read_rows(path: &Path) -> Result<Vec<Row>> {
    let fail = |reason: String| Error::Parse {
        name: "table",
        text: path.display().to_string(),
        reason,
    };
    let text = crate::app::config::read_text(path, MAX_TABLE_BYTES, fail)?;
    let is_toml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let rows: Vec<Row> = if is_toml {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            fail(format!("not valid TOML: {}", e.to_string().trim_end()))
        })?;
        let cases = match table.get("case") {
            Some(toml::Value::Array(cases)) => cases,
            _ => return Err(fail("expected an array of tables [[case]]".into())),
        };
        cases
            .iter()
            .map(|case| {
                let toml::Value::Table(t) = case else {
                    return Err(fail("every [[case]] must be a table".into()));
                };
                t.iter()
                    .map(|(k, v)| {
                        let text = match v {
                            toml::Value::String(s) => s.clone(),
                            toml::Value::Integer(i) => i.to_string(),
                            toml::Value::Float(f) => f.to_string(),
                            toml::Value::Boolean(b) => b.to_string(),
                            other => {
                                return Err(fail(format!(
                                    "{k} = {other}: a number, a string or true/false"
                                )));
                            }
                        };
                        Ok((k.clone(), text))
                    })
                    .collect()
            })
            .collect::<Result<_>>()?
    } else {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| fail(e.to_string()))?
            .iter()
            .map(str::to_string)
            .collect();
        if let Some(twice) = header
            .iter()
            .enumerate()
            .find_map(|(i, h)| header[..i].contains(h).then_some(h))
        {
            return Err(fail(format!(
                "column {twice:?} is given twice: give each column once"
            )));
        }
        reader
            .records()
            .map(|r| {
                let r = r.map_err(|e| fail(e.to_string()))?;
                Ok(header
                    .iter()
                    .zip(r.iter())
                    .filter(|(_, v)| !v.is_empty())
                    .map(|(k, v)| (k.clone(), v.to_string()))
                    .collect())
            })
            .collect::<Result<_>>()?
    };
    if rows.is_empty() || rows.len() > MAX_CASES {
        return Err(fail(format!("must hold from 1 to {MAX_CASES} cases")));
    }
    Ok(rows)
}

/// Resolve row `index` (from 0) over `base`.
fn case(index: usize, row: &Row, base: &TapInputs) -> Result<Case> {
    let at = |e: Error| Error::NotApplicable(format!("row {}: {e}", index + 1));
    let mut inputs = TapInputs::default();
    let mut name = (index + 1).to_string();
    let mut command = "tap".to_string();
    let (mut points, mut from, mut to, mut retract) =
        (super::approach::DEFAULT_POINTS, None, None, true);
    for (key, text) in row {
        match key.as_str() {
            "name" => name = text.clone(),
            "command" => command = text.to_ascii_lowercase(),
            "points" => {
                points = text.parse().map_err(|_| {
                    at(Error::Parse {
                        name: "points",
                        text: text.clone(),
                        reason: "a whole number".into(),
                    })
                })?
            }
            "from" => {
                from = Some(
                    crate::app::config::length(text).map_err(|e| at(Error::NotApplicable(e)))?,
                )
            }
            "to" => {
                to = Some(
                    crate::app::config::length(text).map_err(|e| at(Error::NotApplicable(e)))?,
                )
            }
            "no-retract" => {
                retract = match text.to_ascii_lowercase().as_str() {
                    "true" | "yes" | "1" => false,
                    "false" | "no" | "0" => true,
                    _ => {
                        return Err(at(Error::Parse {
                            name: "no-retract",
                            text: text.clone(),
                            reason: "expected true or false".into(),
                        }));
                    }
                }
            }
            "law" => {
                inputs.law =
                    vec![
                        crate::physics::law::LawKind::from_name(text).ok_or_else(|| {
                            at(Error::Parse {
                                name: "law",
                                text: text.clone(),
                                reason: format!(
                                    "expected one of {}",
                                    crate::physics::law::LawKind::names().join(", ")
                                ),
                            })
                        })?,
                    ]
            }
            other => inputs.set(other, text).map_err(|e| match e {
                Error::Parse { name: "key", .. } => at(Error::Parse {
                    name: "column",
                    text: other.to_string(),
                    reason: format!(
                        "unknown column; the columns are name, command, points, from, to, \
                         no-retract, law and every tap option's name ({e})"
                    ),
                }),
                e => at(e),
            })?,
        }
    }
    let inputs = inputs.or(base.clone());
    let (setup, numerics) = inputs.resolve().map_err(at)?;
    // A value `tap` refuses refuses the batch here, before any case runs.
    setup.check_plausible().map_err(at)?;
    let setpoint = inputs.setpoint_ratio(setup.cantilever.free_amplitude_m);
    let branch = inputs
        .branch
        .unwrap_or(crate::app::config::BranchChoice::All)
        .only();
    let (run, numerics) = match command.as_str() {
        "tap" => match setpoint {
            None => (Run::Tap, numerics),
            Some(ratio) => {
                if inputs.separation.is_some() {
                    return Err(at(super::separation_and_setpoint()));
                }
                crate::analysis::setpoint::check_ratio(ratio).map_err(at)?;
                (Run::Setpoint { ratio, branch }, numerics)
            }
        },
        "approach" if setpoint.is_some() => {
            return Err(at(Error::NotApplicable(
                "an approach case runs over rest separations (from, to); a setpoint is for \
                 a tap case"
                    .into(),
            )));
        }
        "approach" => (
            Run::Approach {
                points,
                from,
                to,
                retract,
            },
            inputs.sweep_numerics(numerics),
        ),
        other => {
            return Err(at(Error::Parse {
                name: "command",
                text: other.to_string(),
                reason: "expected tap or approach".into(),
            }));
        }
    };
    Ok(Case {
        name,
        run,
        setup,
        numerics,
    })
}

/// The records of one case: one for a tap, one per setpoint for an approach; a note
/// where the law does not apply.
fn run_case(c: &Case) -> Result<Vec<Map<String, Value>>> {
    let head = |command: &str| {
        let mut m = Map::new();
        m.insert("case".into(), Value::String(c.name.clone()));
        m.insert("command".into(), Value::String(command.into()));
        m
    };
    let outcome = match &c.run {
        Run::Tap => crate::dynamics::observables::tap(
            &c.setup,
            &c.numerics,
            crate::dynamics::observables::Observe::default(),
        )
        .and_then(|run| Ok(vec![joined(head("tap"), &run.observables)?])),
        Run::Setpoint { ratio, branch } => {
            crate::analysis::setpoint::states_at_setpoint(&c.setup, &c.numerics, *ratio, *branch)
                .and_then(|states| {
                    states
                        .iter()
                        .map(|st| {
                            let mut m = head("tap");
                            m.insert("setpoint".into(), Value::from(*ratio));
                            joined(m, st)
                        })
                        .collect()
                })
        }
        Run::Approach {
            points,
            from,
            to,
            retract,
        } => {
            // The defaults of `tapsim approach`.
            let range = super::SeparationRange {
                from: *from,
                to: *to,
            };
            let (from, to) = range.resolve(c.setup.cantilever.free_amplitude_m);
            sweep::ramp(from, to, *points, *retract)
                .and_then(|ramp| sweep::approach_curve(&c.setup, &c.numerics, &ramp, |_, _| {}))
                .and_then(|curve| curve.iter().map(|p| joined(head("approach"), p)).collect())
        }
    };
    match outcome {
        Ok(records) => Ok(records),
        Err(Error::NotApplicable(why)) => {
            let mut m = head(match c.run {
                Run::Tap | Run::Setpoint { .. } => "tap",
                Run::Approach { .. } => "approach",
            });
            m.insert("note".into(), Value::String(why));
            Ok(vec![m])
        }
        Err(e) => Err(Error::NotApplicable(format!("case {}: {e}", c.name))),
    }
}

/// `head` followed by the fields of `record`.
fn joined(
    mut head: Map<String, Value>,
    record: &impl serde::Serialize,
) -> Result<Map<String, Value>> {
    head.extend(records::object(record)?);
    Ok(head)
}

/// Run the subcommand.
pub fn run(args: BatchArgs) -> Result<()> {
    use rayon::prelude::*;
    // Before any case runs.
    args.out.refuse_plots("batch", &[])?;
    let base = args.inputs.clone().with_config()?;
    base.no_setpoint("batch")?;
    let rows = read_rows(&args.table)?;
    let cases = rows
        .iter()
        .enumerate()
        .map(|(i, row)| case(i, row, &base))
        .collect::<Result<Vec<_>>>()?;
    let shard = args
        .split
        .resolve("batch", args.out.csv.is_some() || args.out.json)?;
    let items = shard.unwrap_or(Shard::WHOLE).items(cases.len());
    let pool = sweep::thread_pool(args.threads)?;
    let bar = args.out.progress("batch", items.len());
    // Each case's records kept as JSON text: a tenth of the memory of parsed objects.
    let records: Vec<Vec<Box<RawValue>>> = pool.install(|| {
        items
            .par_iter()
            .map(|&k| {
                let r = run_case(&cases[k]).and_then(|r| part::raw_records(&r));
                bar.inc(1);
                r
            })
            .collect::<Result<_>>()
    })?;
    bar.finish_and_clear();
    match shard {
        Some(shard) => args.split.write(
            ("batch", shard, args.out.quiet),
            Job::Batch { cases: cases.len() },
            &part::Config::PerItem(
                cases
                    .iter()
                    .map(|c| serde_json::to_value(c).expect("a case serialises"))
                    .collect(),
            ),
            items,
            records,
        ),
        None => emit(
            &args.out,
            &[],
            &records.into_iter().flatten().collect::<Vec<_>>(),
        ),
    }
}

/// Write a whole batch's outputs ([`super::SweepOutput::emit`]): the CSV and the JSON
/// columns; a batch has no plot. `tapsim merge` writes through this too.
pub(super) fn emit(
    out: &super::SweepOutput,
    extra: &[PathBuf],
    records: &[Box<RawValue>],
) -> Result<()> {
    out.emit(
        ("batch", extra),
        records,
        || records::columns_json(records),
        None,
    )
}
