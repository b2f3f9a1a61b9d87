//! Splitting a job over machines, for the commands that can (`map`, `batch`, `scan
//! --lines N`): which part
//! a run computes, and its part file.

use crate::analysis::sweep::Shard;
use crate::app::report::output;
use crate::app::report::part::{Config, Job, Part};
use crate::error::{Error, Result};
use serde_json::value::RawValue;
use std::path::PathBuf;

/// The flags that split a job.
#[derive(Debug, clap::Args)]
pub struct ShardArgs {
    /// Compute only part I (from 0) of N: the items (a map's cells, row by row as the
    /// CSV lists them; a batch's cases; an image's lines) whose number is I mod N, written
    /// to a part file (--part) for `tapsim merge`. Inside a Slurm array task, I and N default to the
    /// task's SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN and SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// The part file of a sharded run [default: <command>-part-I-of-N.json]; written
    /// whole or not at all, with a header (tapsim version, configuration hash, N, I, the
    /// items).
    #[arg(long)]
    part: Option<PathBuf>,
}

/// `--shard I/N`, else inside a Slurm array task SLURM_ARRAY_TASK_ID −
/// SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT, else the whole job (`None`).
fn from_flag_or_slurm(flag: Option<&str>) -> Result<Option<Shard>> {
    let number = |what: &str, text: &str| {
        text.trim().parse::<usize>().map_err(|_| Error::Parse {
            name: "shard",
            text: text.to_string(),
            reason: format!("{what} must be a whole number"),
        })
    };
    if let Some(text) = flag {
        let (i, n) = text.split_once('/').ok_or_else(|| Error::Parse {
            name: "shard",
            text: text.to_string(),
            reason: "expected I/N, part I (from 0) of N".into(),
        })?;
        return Ok(Some(Shard::new(number("I", i)?, number("N", n)?)?));
    }
    let var = |name: &str| std::env::var(name).ok();
    let (Some(id), Some(count)) = (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT"))
    else {
        return Ok(None);
    };
    let min = var("SLURM_ARRAY_TASK_MIN").unwrap_or_else(|| "0".into());
    let (id, min, count) = (
        number("SLURM_ARRAY_TASK_ID", &id)?,
        number("SLURM_ARRAY_TASK_MIN", &min)?,
        number("SLURM_ARRAY_TASK_COUNT", &count)?,
    );
    id.checked_sub(min)
        .and_then(|index| Shard::new(index, count).ok())
        .map(Some)
        .ok_or_else(|| {
            Error::NotApplicable(format!(
                "Slurm array task {id} of {count} starting at {min}: the array's task \
                 numbers must be consecutive (--array=0-{} or a range like it)",
                count.saturating_sub(1)
            ))
        })
}

impl ShardArgs {
    /// The part of `command`'s job this run computes (`None`: all of it). A part writes
    /// only its part file, so `whole_outputs` (the whole run's outputs were asked for)
    /// is refused with a shard, and --part without one.
    pub fn resolve(&self, command: &str, whole_outputs: bool) -> Result<Option<Shard>> {
        let shard = from_flag_or_slurm(self.shard.as_deref())?;
        if shard.is_some() && whole_outputs {
            return Err(Error::NotApplicable(format!(
                "a sharded {command} writes only its part file (--part): merge the parts \
                 with `tapsim merge` for the whole run's outputs"
            )));
        }
        if shard.is_none() && self.part.is_some() {
            return Err(Error::NotApplicable(format!(
                "--part writes one part of a sharded {command}: give --shard I/N (or run \
                 in a Slurm array)"
            )));
        }
        Ok(shard)
    }

    /// Write part `shard` of `command`'s `job` (determined by `config`): its items and
    /// their records, to --part or `<command>-part-I-of-N.json`.
    pub fn write(
        &self,
        (command, shard, quiet): (&str, Shard, bool),
        job: Job,
        config: &Config,
        items: Vec<usize>,
        records: Vec<Vec<Box<RawValue>>>,
    ) -> Result<()> {
        let path = self.part.clone().unwrap_or_else(|| {
            format!("{command}-part-{}-of-{}.json", shard.index, shard.count).into()
        });
        let total = job.items();
        let part = Part::new(shard, job, config, items, records);
        let text = serde_json::to_string(&part).expect("a part serialises");
        output::write_bytes(&path, text.as_bytes())?;
        if !quiet {
            eprintln!(
                "(part {} of {}: {} of {total} items)",
                shard.index,
                shard.count,
                part.items.len()
            );
        }
        Ok(())
    }
}
