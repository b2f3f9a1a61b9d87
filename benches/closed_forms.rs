//! Speed of the closed forms that sit in inner loops: Ŵ_hybrid(μ) (17), (18), (6) and the
//! JKR inverse â(α̂) (5). Target: well under 1 µs each.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tapsim::contact::{hybrid, jkr};

fn bench(c: &mut Criterion) {
    c.bench_function("w_hat_hybrid_fit(mu=5)", |b| {
        b.iter(|| hybrid::w_hat_fit(black_box(5.0)))
    });
    c.bench_function("jkr_a_hat_from_separation(0.85)", |b| {
        b.iter(|| jkr::a_hat_from_separation(black_box(0.85)))
    });
    c.bench_function("hybrid_hysteresis_full(mu=5)", |b| {
        b.iter(|| hybrid::hysteresis(black_box(5.0), hybrid::JumpIn::Fit))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
