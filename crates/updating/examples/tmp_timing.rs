#![allow(missing_docs, clippy::unwrap_used)]
use chatter_dynamics::{ModalModel, examples};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth_near};
use chatter_stability::monodromy::Discretization;
use chatter_stability::{DominantMultiplier, StabilitySolver};
use chatter_updating::parameters::{Parameterization, parse_model_parameters};
use std::sync::Mutex;
use std::time::Instant;
struct Count(Discretization, Mutex<Vec<(f64, f64, f64)>>);
impl StabilitySolver for Count {
    fn name(&self) -> &'static str {
        "c"
    }
    fn dominant_multiplier(
        &self,
        m: &ModalModel,
        s: f64,
        b: f64,
    ) -> chatter_stability::Result<DominantMultiplier> {
        let t = Instant::now();
        let op = self.0.monodromy(m, s, b)?;
        let r = op
            .dominant_eigenpair_from(None)
            .map(|(mu, _)| DominantMultiplier::new(mu, op.period_s));
        self.1.lock().unwrap().push((
            b * 1e3,
            r.as_ref().unwrap().modulus(),
            t.elapsed().as_secs_f64() * 1e3,
        ));
        r
    }
}
fn main() {
    let p = Parameterization::new(
        examples::process_damping_flexure(Some(2.5e5)),
        parse_model_parameters("kt_n_per_mm2,kn_n_per_mm2,c_n_per_m").unwrap(),
    )
    .unwrap();
    let model = p.model(&[2150.0, 1040.0, 2.8e5]).unwrap();
    for speed in [300.0, 700.0, 1100.0] {
        let c = Count(
            Discretization::full().resolved(p.nominal(), speed).unwrap(),
            Mutex::new(vec![]),
        );
        let guess =
            chatter_stability::zero_order::limiting_depth(&model, speed, &Default::default())
                .unwrap()
                .depth_m;
        let o = BoundaryOptions {
            relative_tolerance: 1e-3,
            max_depth_m: 7.5e-3,
            ..Default::default()
        };
        let t = Instant::now();
        let pt = limiting_depth_near(&c, &model, speed, Some(guess), &o).unwrap();
        println!(
            "{speed}: {:?} {:.1} ms",
            pt,
            t.elapsed().as_secs_f64() * 1e3
        );
        for e in c.1.lock().unwrap().iter() {
            println!("  b {:.4} mm |mu| {:.6} {:.2} ms", e.0, e.1, e.2);
        }
    }
}
