//! Normalized characteristic-equation residuals of seed 000 at chosen theta.
use chatter_dynamics::{Parameter, examples};
use chatter_updating::turning::{TurningPoleLikelihood, expand_repetitions};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    let poles = expand_repetitions(&obs.poles);
    let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let like = TurningPoleLikelihood::new(model.clone(), params.clone(), poles.clone(), 0.5)?;
    for theta in [
        [0.0, 0.0, 0.0],
        [0.0067, 0.1385, 0.0549],
        [0.0146, -0.774, -0.651],
        [0.0067, 0.0, 0.0],
    ] {
        let r = like.normalized_residuals(&theta)?;
        let re: f64 = r.iter().map(|x| x.0 * x.0).sum::<f64>() / r.len() as f64;
        let im: f64 = r.iter().map(|x| x.1 * x.1).sum::<f64>() / r.len() as f64;
        let means: Vec<String> = r
            .chunks(10)
            .map(|c| {
                format!(
                    "({:+.3},{:+.3})",
                    c.iter().map(|x| x.0).sum::<f64>() / 10.0,
                    c.iter().map(|x| x.1).sum::<f64>() / 10.0
                )
            })
            .collect();
        println!(
            "{theta:?}: mean sq re {re:.4} im {im:.4} per point {}",
            means.join(" ")
        );
    }
    Ok(())
}
