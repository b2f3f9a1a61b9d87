//! Part files of a map split over machines (`tapsim map --shard I/N`) and their merge
//! (`tapsim merge`). A part file is one JSON object: a header (format, tapsim version,
//! a hash of the whole configuration, N, I, the part's cell numbers) and the part's
//! cells as records, floats written so they read back bit for bit. Merging checks that
//! the parts belong together and cover every cell exactly once, and gives the cells in
//! the order one whole run gives them.

use crate::dynamics::setup::{Numerics, TapSetup};
use crate::error::{Error, Result};
use crate::sweep::Shard;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// What a part file says it is.
pub const FORMAT: &str = "tapsim-map-part";

/// One part of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapPart {
    /// Always [`FORMAT`].
    pub format: String,
    /// The tapsim version that wrote it.
    pub tapsim_version: String,
    /// Hash of everything that determines the map ([`config_hash`]).
    pub config_hash: String,
    /// N, the number of parts.
    pub shards: usize,
    /// I, this part's number (from 0).
    pub shard: usize,
    /// The law, as the map's outputs name it.
    pub law: String,
    /// The work-of-adhesion axis in J/m².
    pub work_of_adhesion_j_m2: Vec<f64>,
    /// The modulus axis in Pa.
    pub modulus_pa: Vec<f64>,
    /// The cells this part computed, by number (row by row over the grid).
    pub cells: Vec<usize>,
    /// Those cells as records, in the same order.
    pub records: Vec<Map<String, Value>>,
}

/// FNV-1a, 64 bits: a stable hash (the same on every machine and build).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// A hash of the tapsim version, the setup, the numerics and both axes: parts with equal
/// hashes were computed for the same map.
pub fn config_hash(setup: &TapSetup, numerics: &Numerics, works: &[f64], moduli: &[f64]) -> String {
    let config = serde_json::json!({
        "tapsim_version": env!("CARGO_PKG_VERSION"),
        "setup": setup,
        "numerics": numerics,
        "work_of_adhesion_j_m2": works,
        "modulus_pa": moduli,
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

/// The merged map: law, axes and every cell's record in the order of a whole run.
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// The law.
    pub law: String,
    /// The work-of-adhesion axis.
    pub works: Vec<f64>,
    /// The modulus axis.
    pub moduli: Vec<f64>,
    /// Every cell's record.
    pub records: Vec<Map<String, Value>>,
}

/// Merge `parts` (each with the name it was read from): refuse parts of different maps
/// or of a different split, a part given twice, and any missing part, naming the missing
/// part numbers as `sbatch --array=` takes them.
pub fn merge(parts: Vec<(String, MapPart)>) -> Result<Merged> {
    let refuse = |why: String| Error::NotApplicable(why);
    let Some((first_name, first)) = parts.first() else {
        return Err(refuse("no part files to merge".into()));
    };
    for (name, p) in &parts {
        if p.format != FORMAT {
            return Err(refuse(format!("{name} is not a tapsim map part file")));
        }
        if p.config_hash != first.config_hash || p.tapsim_version != first.tapsim_version {
            return Err(refuse(format!(
                "{name} belongs to another map than {first_name} (configuration {} of tapsim \
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
    let n = first.shards;
    let total = first.work_of_adhesion_j_m2.len() * first.modulus_pa.len();
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
        if p.cells != shard.items(total) || p.records.len() != p.cells.len() {
            return Err(refuse(format!(
                "{name} does not hold the cells of part {} of {n}: it was changed or cut short",
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
    let mut records: Vec<Option<Map<String, Value>>> = vec![None; total];
    for (_, p) in parts.iter() {
        for (&k, r) in p.cells.iter().zip(&p.records) {
            records[k] = Some(r.clone());
        }
    }
    Ok(Merged {
        law: first.law.clone(),
        works: first.work_of_adhesion_j_m2.clone(),
        moduli: first.modulus_pa.clone(),
        records: records
            .into_iter()
            .map(|r| r.expect("every cell was checked to be in exactly one part"))
            .collect(),
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
