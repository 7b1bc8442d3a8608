//! Random cutting cases for the robustness checks of the eigen-solvers: 1-4 mode milling and
//! turning models with frequencies 100-3000 Hz, damping ratios 0.005-0.1 and stiffnesses
//! 1e6-1e8 N/m (log-uniform; in one case in three the first mode has a twin within 5 % in the
//! other direction, as on a nearly symmetric tool), 1-4 teeth, radial immersion 0.05-1, up and down milling, and
//! cutting conditions over wide ranges: 0.05 to 20 vibration cycles of the highest mode per delay
//! (the speed, log-uniform) and 1e-3 to 1e3 times a Tlusty depth scale (log-uniform), with one
//! case in four at zero depth (the first point of every boundary search, where the monodromy has
//! rank 2N and the Krylov space breaks down). Seeded (splitmix64), so every run draws the same
//! cases.

use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation, Turning,
};

/// splitmix64 (Steele, Lea and Flood 2014): a tiny seeded generator, enough for drawing cases.
pub struct SplitMix(pub u64);

impl SplitMix {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    /// Log-uniform in [lo, hi).
    pub fn log_between(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.uniform()).exp()
    }
    /// Uniform integer in lo..=hi.
    pub fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + ((hi - lo + 1) as f64 * self.uniform()) as usize
    }
}

/// One random cutting case.
pub struct Case {
    /// The model.
    pub model: ModalModel,
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth (m).
    pub depth_m: f64,
}

/// The `index`-th case of the seeded sequence `seed` (independent of the others, so any subset
/// can be rerun alone).
pub fn case(seed: u64, index: u64) -> Case {
    let mut rng = SplitMix(seed ^ index.wrapping_mul(0xD134_2543_DE82_EF95));
    let mut modes: Vec<Mode> = (0..rng.int(1, 4))
        .map(|_| {
            let shape = ModeShape::Directional {
                coordinate: rng.int(0, 1),
                stiffness_n_per_m: rng.log_between(1e6, 1e8),
            };
            Mode::new(
                rng.log_between(100.0, 3000.0),
                rng.log_between(0.005, 0.1),
                shape,
            )
            .expect("valid mode")
        })
        .collect();
    if index % 3 == 2 {
        // a nearly symmetric tool: the first mode's twin in the other direction, frequency and
        // stiffness within 5 % (issue 14's machine, and every Monte Carlo sample around it)
        let first = modes[0];
        if let ModeShape::Directional {
            coordinate,
            stiffness_n_per_m,
        } = first.shape()
        {
            let shape = ModeShape::Directional {
                coordinate: 1 - coordinate,
                stiffness_n_per_m: stiffness_n_per_m * rng.between(0.95, 1.05),
            };
            let twin = Mode::new(
                first.frequency_hz() * rng.between(0.95, 1.05),
                first.damping_ratio() * rng.between(0.8, 1.25),
                shape,
            )
            .expect("valid mode");
            modes.truncate(3);
            modes.insert(1, twin);
        }
    }
    let kt = rng.log_between(3e8, 3e9);
    let kn = kt * rng.between(0.1, 0.6);
    let cutting = CuttingCoefficients::new(kt, kn).expect("valid coefficients");
    let operation = if rng.uniform() < 0.75 {
        let direction = if rng.uniform() < 0.5 {
            MillingDirection::Up
        } else {
            MillingDirection::Down
        };
        Operation::Milling(
            Milling::new(rng.int(1, 4), rng.between(0.05, 1.0), direction, None, None)
                .expect("valid milling"),
        )
    } else {
        Operation::Turning(Turning::new(None).expect("valid turning"))
    };
    let f_max = modes.iter().map(|m| m.frequency_hz()).fold(0.0, f64::max);
    // Tlusty's depth scale 2 k zeta / kt of the most flexible mode
    let depth_scale = modes
        .iter()
        .map(|m| {
            let phi = m.mass_normalized_shape();
            let k = m.omega_rad_s().powi(2) / (phi[0] * phi[0] + phi[1] * phi[1]);
            2.0 * k * m.damping_ratio() / kt
        })
        .fold(f64::INFINITY, f64::min);
    let model = ModalModel::new(None, operation, cutting, modes, None).expect("valid model");
    let cycles = rng.log_between(0.05, 20.0);
    let tau = cycles / f_max;
    let speed_rpm = 60.0 / (tau * model.operation().delays_per_revolution() as f64);
    let depth_m = if index % 4 == 1 {
        0.0
    } else {
        depth_scale * rng.log_between(1e-3, 1e3)
    };
    Case {
        model,
        speed_rpm,
        depth_m,
    }
}

/// The free-decay multiplier at zero depth: max over modes of exp(-zeta omega_n tau).
pub fn free_decay(case: &Case) -> f64 {
    let tau = case.model.operation().delay_s(case.speed_rpm);
    case.model
        .modes()
        .iter()
        .map(|m| (-m.damping_ratio() * m.omega_rad_s() * tau).exp())
        .fold(0.0, f64::max)
}

/// Run the eigen-solvers on one case: the dominant multiplier by full and semi-discretization at
/// the automatic resolution, (one case in four) the chatter frequency from the dominant
/// eigenvector and (one case in ten) the whole limiting-depth search by full discretization. A description of the failure when a solver returns an error or a non-finite
/// value, or, at zero depth, misses the free decay by more than 1e-7 relative (the multiplier
/// of e^{A_0 tau} is exact in both schemes; 1e-7 leaves room for the Arnoldi tolerance 1e-10
/// on far-from-normal operators).
pub fn check(index: u64, case: &Case) -> Result<(), String> {
    use chatter_stability::StabilitySolver;
    use chatter_stability::monodromy::Discretization;
    let describe = |what: &str| {
        format!(
            "case {index}: {what} ({} modes, {:?}, {:.1} rpm, depth {:.3e} m)",
            case.model.mode_count(),
            case.model.operation(),
            case.speed_rpm,
            case.depth_m
        )
    };
    for method in [Discretization::full(), Discretization::semi()] {
        let mu = method
            .dominant_multiplier(&case.model, case.speed_rpm, case.depth_m)
            .map_err(|e| describe(&format!("{}: {e}", method.name())))?;
        let modulus = mu.modulus();
        if !modulus.is_finite() {
            return Err(describe(&format!("{}: |mu| = {modulus}", method.name())));
        }
        if case.depth_m == 0.0 {
            let expected = free_decay(case);
            if (modulus - expected).abs() > 1e-7 * expected {
                return Err(describe(&format!(
                    "{}: |mu| = {modulus} at zero depth, free decay {expected}",
                    method.name()
                )));
            }
        }
    }
    if index.is_multiple_of(10) {
        // a whole boundary search: zero depth, the geometric scan and the Illinois refinement
        let point = chatter_stability::boundary::limiting_depth(
            &Discretization::full(),
            &case.model,
            case.speed_rpm,
            &chatter_stability::boundary::BoundaryOptions::default(),
        )
        .map_err(|e| describe(&format!("fdm limiting depth: {e}")))?;
        if point.depth_m.is_nan() || point.depth_m <= 0.0 {
            return Err(describe(&format!("fdm limiting depth {} m", point.depth_m)));
        }
    }
    if index.is_multiple_of(4) {
        let (_, hz) = Discretization::full()
            .chatter_frequency_hz(&case.model, case.speed_rpm, case.depth_m)
            .map_err(|e| describe(&format!("fdm chatter frequency: {e}")))?;
        if !hz.is_finite() {
            return Err(describe(&format!("fdm chatter frequency {hz}")));
        }
    }
    Ok(())
}
