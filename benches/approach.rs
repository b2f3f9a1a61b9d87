//! An approach–retract curve with the hybrid law on the defaults: 100 setpoints down and
//! 100 up, each integrated to its steady state; and an FM approach of 100 points (issue
//! 48 asks for one under 10 s on one core), each point's settled loops from the last.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use tapsim::dynamics::setup::{Numerics, default_setup};
use tapsim::sweep;

fn bench(c: &mut Criterion) {
    let setup = default_setup();
    let a0 = setup.cantilever.free_amplitude_m;
    let ramp = sweep::ramp(1.2 * a0, 0.4 * a0, 100, true).expect("valid ramp");
    let numerics = sweep::sweep_numerics(Numerics::default(), (false, false));
    let mut group = c.benchmark_group("approach_hybrid");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(60));
    group.bench_function("200 setpoints", |b| {
        b.iter(|| sweep::approach_curve(&setup, &numerics, &ramp, |_, _| {}).expect("curve"))
    });
    group.finish();
}

/// `tapsim fm` on the defaults (hybrid law, A = 20 nm) from 1.2 A to 0.4 A in 100 points.
fn fm(c: &mut Criterion) {
    let setup = default_setup();
    let a0 = setup.cantilever.free_amplitude_m;
    let z: Vec<f64> = (0..100)
        .map(|i| a0 * (1.2 - 0.8 * f64::from(i) / 99.0))
        .collect();
    let numerics = Numerics::default();
    let mut group = c.benchmark_group("fm_approach_hybrid");
    group.sample_size(10);
    group.bench_function("100 points, loops settled", |b| {
        b.iter(|| {
            let points = tapsim::analysis::fm::approach(&setup, &numerics, &z, || {}).expect("fm");
            assert!(points.iter().all(|p| p.state.is_some()));
            points
        })
    });
    group.finish();
}

criterion_group!(benches, bench, fm);
criterion_main!(benches);
