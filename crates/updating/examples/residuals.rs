//! Normalized residuals of seed 000 at chosen theta, for both residual forms: Eq. 28 as printed
//! (determinant) and the pole error used by default.
use chatter_dynamics::examples;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};
use chatter_updating::turning::{ResidualForm, TurningPoleLikelihood, expand_repetitions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    let poles = expand_repetitions(&obs.poles);
    let params = Parameterization::new(
        model,
        parse_model_parameters("theta_omega_2,theta_zeta_2,theta_phi_2")?,
    )?;
    for form in [ResidualForm::Determinant, ResidualForm::PoleError] {
        let like = TurningPoleLikelihood::new(params.clone(), poles.clone(), 0.5, form)?;
        println!("{form:?}");
        let published = chatter_dynamics::examples::ahmadi_2022_posterior().mean;
        for theta in [vec![0.0, 0.0, 0.0], published, vec![0.0146, -0.774, -0.651]] {
            let r = like.normalized_residuals(&theta)?;
            let n = r.len() as f64;
            let re: f64 = r.iter().map(|x| x.0 * x.0).sum::<f64>() / n;
            let im: f64 = r.iter().map(|x| x.1 * x.1).sum::<f64>() / n;
            println!("  {theta:?}: mean square re {re:.4} im {im:.4}");
        }
    }
    Ok(())
}
