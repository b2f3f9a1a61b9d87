//! Tests of `tapsim::instrument::average` (src/instrument/average.rs).

use tapsim::instrument::average::*;

#[test]
fn each_place_draws_its_own_seed_and_the_same_place_the_same() {
    let r = AverageRequest {
        temperature_k: 300.0,
        periods: 1600,
        seed: 1,
    };
    let seeds: Vec<u64> = (0..1000).map(|i| r.at(&[i]).seed).collect();
    let mut distinct = seeds.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), seeds.len());
    assert!(!seeds.contains(&1));
    assert_eq!(r.at(&[7, 3]).seed, r.at(&[7, 3]).seed);
    assert_ne!(r.at(&[7, 3]).seed, r.at(&[3, 7]).seed);
    assert_ne!(
        r.at(&[7]).seed,
        AverageRequest { seed: 2, ..r }.at(&[7]).seed
    );
    // Only the seed moves.
    assert_eq!(
        AverageRequest {
            seed: 1,
            ..r.at(&[5])
        },
        r
    );
}
