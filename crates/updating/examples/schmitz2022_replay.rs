//! 004 Sec. 6 replayed: the P_test = 25 / 50 / 75 % test sequences planned by `plan --strategy
//! mrr` from the RCSA prior, the cuts answered by the prior-mean machine through FDM
//! (`chatter_updating::schmitz2022::TruthMachine`), stopped by the paper's 10 % rule or the cap;
//! each sequence, then the paper's numbers beside ours.
//!
//! `cargo run --release -p chatter-updating --example schmitz2022_replay [PATHS] [SEED]`
//! (default 200 paths, seed 4).

use chatter_progress::Silent;
use chatter_updating::schmitz2022::{replay_reproduction, replay_table, table};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let paths: usize = args.next().map_or(Ok(200), |s| s.parse())?;
    let seed: u64 = args.next().map_or(Ok(4), |s| s.parse())?;
    let t = std::time::Instant::now();
    let (replays, rows) = replay_reproduction(paths, seed, &Silent)?;
    for r in &replays {
        print!("{}", replay_table(r));
    }
    println!("({:.1} s)", t.elapsed().as_secs_f64());
    print!("{}", table(&rows));
    Ok(())
}
