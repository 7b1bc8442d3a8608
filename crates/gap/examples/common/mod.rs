//! Command-line options of the proving-ground examples (`confusion`, `simulated`).

/// The value after `--name` on the command line.
pub fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// The comma-separated values after `--name` (the ones that parse), or `default`.
pub fn list<T: std::str::FromStr>(name: &str, default: Vec<T>) -> Vec<T> {
    arg(name).map_or(default, |s| {
        s.split(',').filter_map(|x| x.parse().ok()).collect()
    })
}
