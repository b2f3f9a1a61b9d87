//! Simulated steady-state tapping cycles per second with the hybrid law (default setup),
//! at integrator tolerances whose energy-balance error is below 1e-6 (checked before
//! measuring).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tapsim::dynamics::numeric::Ignore;
use tapsim::dynamics::observables::TapObservables;
use tapsim::dynamics::setup::{Numerics, Prepared, default_setup};

const CYCLES: u64 = 200;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("tap_hybrid_cycles");
    group.throughput(Throughput::Elements(CYCLES));
    // (rtol, atol): the defaults, then looser settings that still keep the energy
    // balance below 1e-6 (checked below; the balance is not monotonic in the tolerances,
    // so each pair is checked rather than assumed).
    for (rtol, atol) in [(1e-9, 1e-11), (1e-8, 1e-10), (2e-7, 2e-9), (3e-7, 1e-8)] {
        let numerics = Numerics {
            rtol,
            atol,
            ..Numerics::default()
        };
        let p = Prepared::new(&default_setup(), &numerics).expect("defaults are valid");
        let sim = p.simulation();
        let mut phase = sim.free_steady_start();
        let state = sim
            .steady_state(&mut phase, &p.steady)
            .expect("steady state");
        let o = TapObservables::new(&p, &state);
        assert!(
            o.converged && o.energy_balance_rel < 1e-6,
            "rtol {rtol}: {o:?}"
        );
        eprintln!(
            "rtol {rtol:e}, atol {atol:e}: energy balance {:.1e}, E_ts/loop - 1 = {:.1e}",
            o.energy_balance_rel,
            o.e_ts_j / o.loop_area_j - 1.0
        );
        group.bench_function(format!("rtol={rtol:e},atol={atol:e}"), |b| {
            b.iter(|| {
                for _ in 0..CYCLES {
                    sim.cycle(&mut phase, &mut Ignore).expect("cycle");
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
