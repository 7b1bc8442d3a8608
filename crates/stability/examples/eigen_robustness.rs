//! Robustness of the eigen-solvers over many random cutting cases (issue 14): run the dominant
//! multiplier of full and semi-discretization on the first N cases (default 10 000) of the
//! seeded sequence of `tests/common/random_models.rs` and count the failures.
//!
//! `cargo run --profile test -p chatter-stability --example eigen_robustness -- 10000`

#[path = "../tests/common/random_models.rs"]
mod random_models;

use random_models::{case, check};
use rayon::prelude::*;

/// Seed of the sequence, shared with the test `tests/eigen_robustness.rs`.
const SEED: u64 = 14;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: u64 = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 10_000,
    };
    let start = std::time::Instant::now();
    let failures: Vec<String> = (0..n)
        .into_par_iter()
        .filter_map(|i| check(i, &case(SEED, i)).err())
        .collect();
    for f in &failures {
        println!("{f}");
    }
    println!(
        "{} cases, {} failures, {:.1} s",
        n,
        failures.len(),
        start.elapsed().as_secs_f64()
    );
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!("{} failures", failures.len()).into())
    }
}
