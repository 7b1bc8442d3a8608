//! Criterion benchmarks live in `benches/benches/*.rs` of this package.
