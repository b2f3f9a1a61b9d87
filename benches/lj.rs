//! Time to the Lennard-Jones hysteresis Ŵ_LJ(μ): assembly and continuation on the
//! production mesh (the error estimate's coarse mesh adds about a third).

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use tapsim::contact::lj::{curve, mesh::MeshSpec, result::ELEMENTS_PER_ANNULUS, solver::Problem};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("w_hat_lj");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    for mu in [2.0, 5.0] {
        group.bench_function(format!("mu={mu}"), |b| {
            b.iter(|| {
                let problem =
                    Problem::new(mu, MeshSpec::for_tabor(mu, ELEMENTS_PER_ANNULUS).nodes());
                curve::trace(&problem, &curve::TraceOptions::default())
                    .expect("traced")
                    .w_hat
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
