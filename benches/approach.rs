//! An approach–retract curve with the hybrid law on the defaults: 100 setpoints down and
//! 100 up, each integrated to its steady state.

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

criterion_group!(benches, bench);
criterion_main!(benches);
