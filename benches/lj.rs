//! Time to the Lennard-Jones hysteresis Ŵ_LJ(μ) with its error estimate, as
//! `tapsim lj` computes it without the cache: assembly and continuation on the
//! production moving mesh (on one core) and on the 1.5× and 2.25× coarser ones (on the
//! other), side by side for μ = 3, 5 and 50 (the targets: 0.2 s with an estimated
//! relative error ≤ 1e-4, 0.5 s and 10 s).

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use tapsim::contact::lj;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("w_hat_lj");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    for mu in [3.0, 5.0, 50.0] {
        group.bench_function(format!("mu={mu}"), |b| {
            b.iter(|| {
                let s = lj::solve(mu, lj::Reach::Rigid).expect("solved");
                assert!(s.w_hat.error <= 1e-4 * s.w_hat.value, "{:?}", s.w_hat);
                s.w_hat.value
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
