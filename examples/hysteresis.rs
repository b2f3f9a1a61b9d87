//! The paper's headline in a few lines: the JKR loss (9) against the hybrid loss (18)
//! for a range of Tabor parameters, and what a compliant support (26) adds.
//!
//! Run with `cargo run --example hysteresis`.

use tapsim::contact::hybrid::{self, JumpIn};
use tapsim::contact::{jkr, spring};

fn main() -> tapsim::Result<()> {
    let w_jkr = jkr::w_hat_jkr();
    println!("JKR loss per cycle, eq. (9): {w_jkr:.4}");
    println!(
        "{:>6} {:>10} {:>10} {:>12}",
        "mu", "alpha_A", "W_hybrid", "% of JKR"
    );
    for mu in [1.5, 2.0, 5.0, 10.0, 20.0, 100.0] {
        let h = hybrid::hysteresis(mu, JumpIn::Fit)?;
        println!(
            "{mu:>6} {:>10.4} {:>10.4} {:>11.1}%",
            h.alpha_hat_a.unwrap_or(f64::NAN),
            h.w_hat,
            100.0 * h.w_hat / w_jkr
        );
    }
    println!("\nmu = 5 with a support of stiffness k_hat, eq. (26):");
    for k_hat in [0.1, 1.0, 10.0, 100.0] {
        let s = spring::hysteresis(5.0, k_hat, JumpIn::Fit)?;
        println!("  k_hat = {k_hat:>6}: W = {:.4}", s.w_hat);
    }
    Ok(())
}
