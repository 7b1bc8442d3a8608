//! Seed 000 Table 2 conditions: nominal closed-loop poles (frequency domain and FDM).
use chatter_dynamics::examples;
use chatter_stability::StabilitySolver;
use chatter_stability::frequency_domain::dominant_pole;
use chatter_stability::monodromy::Discretization;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::ahmadi_2022_turning();
    for (rpm, mm, f, z) in [
        (7150.0, 2.286, 2473.0, 0.0012),
        (7150.0, 2.54, 2477.0, 0.0006),
        (6950.0, 2.54, 2508.0, 0.0019),
        (7500.0, 2.032, 2476.0, 0.0009),
        (7500.0, 2.54, 2476.0, 0.0002),
    ] {
        let p = dominant_pole(&model, rpm, mm * 1e-3)?;
        let (mu, ff) = Discretization::full().chatter_frequency_hz(&model, rpm, mm * 1e-3)?;
        let zf = -(mu.modulus().ln() / mu.period_s) / (2.0 * std::f64::consts::PI * ff);
        println!(
            "{rpm} rpm {mm} mm: table {f} Hz {z:.4} | freq-domain {:.1} Hz {:.5} | FDM {:.1} Hz {:.5}",
            p.frequency_hz, p.damping_ratio, ff, zf
        );
    }
    Ok(())
}
