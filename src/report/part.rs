//! Part files of a job split over machines (`tapsim map --shard I/N`, `tapsim batch
//! --shard I/N`) and their merge (`tapsim merge`). A part file is one JSON object: a
//! header (format, tapsim version, a hash of the whole configuration, N, I, what the job
//! is, the numbers of the part's items: a map's cells, a batch's cases) and each item's
//! records, floats written so they read back bit for bit. Merging checks that the parts
//! belong together and cover every item exactly once, and gives the records in the
//! order one whole run gives them.

use crate::error::{Error, Result};
use crate::sweep::Shard;
use serde::{Deserialize, Serialize};

use serde_json::value::RawValue;

/// The most items a job can have: a 200 × 200 map's cells, a batch's 100 000 cases.
pub const MAX_ITEMS: usize = 100_000;

/// What a part file says it is.
pub const FORMAT: &str = "tapsim-part";

/// The job a part belongs to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Job {
    /// `tapsim map`: one record per cell.
    Map {
        /// The law, as the map's outputs name it.
        law: String,
        /// The work-of-adhesion axis in J/m².
        work_of_adhesion_j_m2: Vec<f64>,
        /// The modulus axis in Pa.
        modulus_pa: Vec<f64>,
    },
    /// `tapsim batch`: one record per tap case, one per setpoint of an approach case.
    Batch {
        /// The number of cases.
        cases: usize,
    },
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
            Job::Batch { cases } => *cases,
        }
    }
}

/// One part of a job.
#[derive(Debug, Clone, Serialize, Deserialize)]
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
    /// The items this part computed, by number.
    pub items: Vec<usize>,
    /// Each item's records (kept as their JSON text), in the same order.
    pub records: Vec<Vec<Box<RawValue>>>,
}

impl Part {
    /// Part `shard` of `job` with these items and records, stamped with this build's
    /// version and the hash of `config`.
    pub fn new(
        shard: Shard,
        job: Job,
        config: &impl Serialize,
        items: Vec<usize>,
        records: Vec<Vec<Box<RawValue>>>,
    ) -> Self {
        Self {
            format: FORMAT.into(),
            tapsim_version: env!("CARGO_PKG_VERSION").into(),
            config_hash: config_hash(config),
            shards: shard.count,
            shard: shard.index,
            job,
            items,
            records,
        }
    }
}

/// FNV-1a, 64 bits: a stable hash (the same on every machine and build).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// A hash of the tapsim version and `config` (everything that determines a job's
/// results): parts with equal hashes were computed for the same job.
pub fn config_hash(config: &impl Serialize) -> String {
    let config = serde_json::json!({
        "tapsim_version": env!("CARGO_PKG_VERSION"),
        "config": config,
    });
    format!("{:016x}", fnv1a(config.to_string().as_bytes()))
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
/// of parsed objects).
pub fn raw_records<T: Serialize>(item: &[T]) -> Result<Vec<Box<RawValue>>> {
    item.iter()
        .map(|r| {
            serde_json::value::to_raw_value(r).map_err(|e| Error::Output {
                path: "part file".into(),
                reason: e.to_string(),
            })
        })
        .collect()
}

/// Merge `parts` (each with the name it was read from): refuse parts of different jobs
/// or of a different split, a part given twice, and any missing part, naming the missing
/// part numbers as `sbatch --array=` takes them.
pub fn merge(parts: Vec<(String, Part)>) -> Result<Merged> {
    let refuse = |why: String| Error::NotApplicable(why);
    let Some((first_name, first)) = parts.first() else {
        return Err(refuse("no part files to merge".into()));
    };
    for (name, p) in &parts {
        if p.format != FORMAT {
            return Err(refuse(format!("{name} is not a tapsim part file")));
        }
        if p.config_hash != first.config_hash
            || p.tapsim_version != first.tapsim_version
            || p.job != first.job
        {
            return Err(refuse(format!(
                "{name} belongs to another job than {first_name} (configuration {} of tapsim \
                 {} against {} of tapsim {}): merge the parts of one run",
                p.config_hash, p.tapsim_version, first.config_hash, first.tapsim_version
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
    // (Checked before anything is sized by them: a part file is input like any other.)
    Shard::new(first.shard, first.shards)?;
    let n = first.shards;
    let total = first.job.items();
    if total > MAX_ITEMS {
        return Err(refuse(format!(
            "{first_name} describes {total} items, more than any tapsim job has ({MAX_ITEMS})"
        )));
    }
    let mut seen: Vec<Option<&str>> = vec![None; n];
    for (name, p) in &parts {
        let shard = Shard::new(p.shard, p.shards)?;
        if let Some(earlier) = seen[p.shard] {
            return Err(refuse(format!(
                "part {} of {n} is given twice ({earlier} and {name})",
                p.shard
            )));
        }
        seen[p.shard] = Some(name);
        if p.items != shard.items(total) || p.records.len() != p.items.len() {
            return Err(refuse(format!(
                "{name} does not hold the items of part {} of {n}: it was changed or cut short",
                p.shard
            )));
        }
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
    let mut by_item: Vec<Option<&Vec<Box<RawValue>>>> = vec![None; total];
    for (_, p) in &parts {
        for (&k, r) in p.items.iter().zip(&p.records) {
            by_item[k] = Some(r);
        }
    }
    let records = by_item
        .into_iter()
        .flat_map(|r| {
            r.expect("every item was checked to be in exactly one part")
                .clone()
        })
        .collect();
    Ok(Merged {
        job: first.job.clone(),
        records,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_parts_read_as_an_sbatch_array() {
        assert_eq!(array_spec(&[2]), "2");
        assert_eq!(array_spec(&[0, 1, 2, 5, 7, 8]), "0-2,5,7-8");
        assert_eq!(array_spec(&[]), "");
    }

    #[test]
    fn the_hash_is_fnv_1a() {
        // The published test vectors of 64-bit FNV-1a.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
