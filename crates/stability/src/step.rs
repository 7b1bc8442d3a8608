//! The steps of the discretizations (see [`crate::monodromy`] for the equations; the grid is in
//! the crate's `grid` module):
//! the depth-independent part of a step program at one speed, prepared once ([`StepPlan`]) and
//! turned into the monodromy operator at any depth ([`StepPlan::monodromy`]).
//!
//! At one speed and grid only the depth changes along a boundary search, and the periodic
//! coefficients scale with it (A(t) = [[0, 0], [-b W(t), -b P(t)]], B(t) = [[0], [b W(t)]]). The
//! plan therefore holds everything else: the grid aligned with tooth entry and exit, the free-flight
//! exponentials e^{A_0 L}, the full discretization's e^{A_0 h}, F_1 and F_2 of each cutting
//! segment, and the modal W(t) and P(t) at the times the steps sample them (per unit depth). A
//! monodromy at depth b then costs the step solves alone; it is the same operator, to the last
//! bit, as one built from scratch.

use crate::error::{Result, StabilityError, check_condition};
use crate::grid::{envelope_segments, segments};
use crate::monodromy::{Discretization, Interp, Monodromy, Scheme, Step, Tap, principal_period};
use chatter_dynamics::simulate::TimeMap;
use chatter_dynamics::{CuttingEdge, ModalModel, Operation};
use nalgebra::{DMatrix, Matrix2};

/// Van Loan: exp of [[A, I, 0], [0, 0, I], [0, 0, 0]] h gives e^{A h}, F_1 and F_2.
fn exp_integrals(a: &DMatrix<f64>, h: f64) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let n = a.nrows();
    let mut big = DMatrix::zeros(3 * n, 3 * n);
    big.view_mut((0, 0), (n, n)).copy_from(&(a * h));
    for i in 0..n {
        big[(i, n + i)] = h;
        big[(n + i, 2 * n + i)] = h;
    }
    let e = big.exp();
    let phi0 = e.view((0, 0), (n, n)).into_owned();
    let f1 = e.view((0, n), (n, n)).into_owned();
    // top-right block = int_0^h e^{A(h-s)} s ds / h ... scaled: block (0,2n) of exp(M h) with the
    // unit blocks scaled by h equals int_0^h e^{A(h-s)} s ds.
    let f2 = e.view((0, 2 * n), (n, n)).into_owned();
    (phi0, f1, f2)
}

/// Row-major copy of a matrix.
pub(crate) fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

/// The cutting edge elements of a helical cutter at one depth that share one regenerative delay
/// (all slices of a tooth when the helix is uniform): one delayed input of the step program.
#[derive(Debug, Clone)]
struct EdgeGroup {
    delay_rad: f64,
    edges: Vec<CuttingEdge>,
}

/// The elements of `edges` grouped by their delay (equal delays to 1e-12 relative).
fn edge_groups(edges: Vec<CuttingEdge>) -> Vec<EdgeGroup> {
    let mut groups: Vec<EdgeGroup> = Vec::new();
    for edge in edges {
        match groups
            .iter_mut()
            .find(|g| (g.delay_rad - edge.delay_rad).abs() <= 1e-12 * edge.delay_rad)
        {
            Some(g) => g.edges.push(edge),
            None => groups.push(EdgeGroup {
                delay_rad: edge.delay_rad,
                edges: vec![edge],
            }),
        }
    }
    groups
}

/// The periodic coefficients per unit depth at one time in modal coordinates: [W | P]
/// (N x 2N, row-major), W = Phi^T H(t) Phi and P = Phi^T D(t) Phi.
struct Periodic<'a> {
    model: &'a ModalModel,
    speed_rpm: f64,
    /// Phi (2 x N), row-major.
    phi: Vec<f64>,
    modes: usize,
    /// A helical cutter's elements at the depth of the plan, by delay (`None`: the teeth).
    groups: Option<Vec<EdgeGroup>>,
}

impl Periodic<'_> {
    /// The delayed inputs: the teeth, or the edge groups of a helical cutter.
    fn inputs(&self) -> usize {
        match &self.groups {
            Some(g) => g.len(),
            None => self.model.operation().delays_per_revolution(),
        }
    }

    /// Input `j`'s delay as the angle (rad) the spindle turns in it: tooth j's pitch, or the
    /// edge group's delay.
    fn delay_rad(&self, j: usize) -> f64 {
        match (&self.groups, self.model.operation()) {
            (Some(g), _) => g[j].delay_rad,
            (None, Operation::Milling(m)) => m.tooth_pitch_rad(j),
            (None, Operation::Turning(_)) => 2.0 * std::f64::consts::PI,
        }
    }

    /// Input `j`'s part of H(t) (N/m^2).
    fn input_matrix(&self, j: usize, t: f64) -> Matrix2<f64> {
        match &self.groups {
            Some(g) => g[j]
                .edges
                .iter()
                .map(|e| self.model.edge_directional_matrix(e, t, self.speed_rpm))
                .sum(),
            None => self.model.tooth_directional_matrix(j, t, self.speed_rpm),
        }
    }

    /// Append [W | P] at time `t` to `out`.
    fn push(&self, t: f64, out: &mut Vec<f64>) {
        let n = self.modes;
        let (h, d) = match &self.groups {
            Some(g) => (
                (0..g.len()).map(|j| self.input_matrix(j, t)).sum(),
                Matrix2::zeros(),
            ),
            None => (
                self.model.directional_matrix(t, self.speed_rpm),
                self.model.process_damping_matrix(t, self.speed_rpm),
            ),
        };
        let at = out.len();
        out.resize(at + 2 * n * n, 0.0);
        let m = &mut out[at..];
        for p in 0..n {
            for q in 0..n {
                let (mut w, mut pd) = (0.0, 0.0);
                for a in 0..2 {
                    for c in 0..2 {
                        let f = self.phi[a * n + p] * self.phi[c * n + q];
                        w += f * h[(a, c)];
                        pd += f * d[(a, c)];
                    }
                }
                m[p * 2 * n + q] = w;
                m[p * 2 * n + n + q] = pd;
            }
        }
    }

    /// Append input `j`'s W_j = Phi^T H_j(t) Phi (N x N, row-major) at time `t` to `out`.
    fn push_tooth(&self, j: usize, t: f64, out: &mut Vec<f64>) {
        let n = self.modes;
        let h = self.input_matrix(j, t);
        for p in 0..n {
            for q in 0..n {
                let mut w = 0.0;
                for a in 0..2 {
                    for c in 0..2 {
                        w += self.phi[a * n + p] * self.phi[c * n + q] * h[(a, c)];
                    }
                }
                out.push(w);
            }
        }
    }
}

/// `out` = b `unit`: the periodic coefficients M = [b W | b P] at depth b, so that
/// A(t) = [[0, 0], [-M]] and B(t) = [[0], [b W]].
fn scaled(depth_m: f64, unit: &[f64], out: &mut [f64]) {
    for (o, u) in out.iter_mut().zip(unit) {
        *o = depth_m * u;
    }
}

/// Gaussian elimination with partial pivoting of the small system `a` x = `b` in place
/// (`a` d x d, `b` d x k, row-major); `false` when `a` is singular.
fn solve_small(a: &mut [f64], b: &mut [f64], d: usize, k: usize) -> bool {
    for col in 0..d {
        let pivot = (col..d)
            .max_by(|&i, &j| a[i * d + col].abs().total_cmp(&a[j * d + col].abs()))
            .unwrap_or(col);
        if a[pivot * d + col] == 0.0 || !a[pivot * d + col].is_finite() {
            return false;
        }
        if pivot != col {
            for j in 0..d {
                a.swap(col * d + j, pivot * d + j);
            }
            for j in 0..k {
                b.swap(col * k + j, pivot * k + j);
            }
        }
        let inv = 1.0 / a[col * d + col];
        for i in col + 1..d {
            let f = a[i * d + col] * inv;
            if f == 0.0 {
                continue;
            }
            for j in col..d {
                a[i * d + j] -= f * a[col * d + j];
            }
            for j in 0..k {
                b[i * k + j] -= f * b[col * k + j];
            }
        }
    }
    for col in (0..d).rev() {
        let inv = 1.0 / a[col * d + col];
        for j in 0..k {
            let mut v = b[col * k + j];
            for i in col + 1..d {
                v -= a[col * d + i] * b[i * k + j];
            }
            b[col * k + j] = v * inv;
        }
    }
    true
}

/// The constant matrices of the full discretization on one cutting segment of step h:
/// e^{A_0 h}, C_1 = F_1 - F_2/h and F_2/h, row-major.
#[derive(Debug, Clone)]
struct FullSegment {
    phi0: Vec<f64>,
    c1: Vec<f64>,
    f2h: Vec<f64>,
}

impl FullSegment {
    fn new(a0: &DMatrix<f64>, h: f64) -> Self {
        let (phi0, f1, f2) = exp_integrals(a0, h);
        let f2h = &f2 / h;
        Self {
            phi0: row_major(&phi0),
            c1: row_major(&(f1 - &f2h)),
            f2h: row_major(&f2h),
        }
    }

    /// First-order full-discretization step (Ding et al. 2010) from the periodic coefficients at
    /// the step's start (`mi`) and end (`mj`): solves (I - F_2/h A_j) [P | R | S] =
    /// [e^{A_0 h} + C_1 A_i | C_1 B_i | F_2/h B_j], appending P, R, S to `out`. `scratch` holds
    /// the (2N)^2 system and the 2N x 4N right-hand side.
    fn step(
        &self,
        n: usize,
        mi: &[f64],
        mj: &[f64],
        scratch: &mut (Vec<f64>, Vec<f64>),
        out: &mut Vec<f64>,
    ) -> bool {
        let (phi0, c1, f2h) = (&self.phi0, &self.c1, &self.f2h);
        let d = 2 * n;
        let k = 4 * n;
        let (lhs, rhs) = scratch;
        lhs.clear();
        lhs.resize(d * d, 0.0);
        rhs.clear();
        rhs.resize(d * k, 0.0);
        for r in 0..d {
            lhs[r * d + r] = 1.0;
            for c in 0..d {
                // only the lower block rows of A and B are non-zero: A = [[0], [-M]], B = [[0], [W]]
                let (mut f2a, mut c1a) = (0.0, 0.0);
                for q in 0..n {
                    f2a += f2h[r * d + n + q] * mj[q * d + c];
                    c1a += c1[r * d + n + q] * mi[q * d + c];
                }
                lhs[r * d + c] += f2a;
                rhs[r * k + c] = phi0[r * d + c] - c1a;
            }
            for c in 0..n {
                let (mut c1b, mut f2b) = (0.0, 0.0);
                for q in 0..n {
                    c1b += c1[r * d + n + q] * mi[q * d + c];
                    f2b += f2h[r * d + n + q] * mj[q * d + c];
                }
                rhs[r * k + d + c] = c1b;
                rhs[r * k + d + n + c] = f2b;
            }
        }
        if !solve_small(lhs, rhs, d, k) {
            return false;
        }
        // [P | R | S] row-major blocks
        for r in 0..d {
            out.extend_from_slice(&rhs[r * k..r * k + d]);
        }
        for block in [d, d + n] {
            for r in 0..d {
                out.extend_from_slice(&rhs[r * k + block..r * k + block + n]);
            }
        }
        true
    }
}

impl FullSegment {
    /// [`Self::step`] with one delayed input per tooth in the cut (variable pitch): the delayed
    /// term C_1 B_i q_{i-m} + F_2/h B_j q_{i-m+1} becomes the sum over teeth of
    /// C_1 B_i^(t) q(t_i - tau_t) + F_2/h B_j^(t) q(t_j - tau_t), B^(t) = [[0], [b W_t]];
    /// appends P, then R_t and S_t of each tooth in `wi`/`wj` order (b W_t at the step's start
    /// and end, N x N row-major).
    fn step_teeth(
        &self,
        n: usize,
        (mi, mj): (&[f64], &[f64]),
        (wi, wj): (&[Vec<f64>], &[Vec<f64>]),
        out: &mut Vec<f64>,
    ) -> bool {
        let (phi0, c1, f2h) = (&self.phi0, &self.c1, &self.f2h);
        let d = 2 * n;
        let teeth = wi.len();
        let k = d + 2 * n * teeth;
        let mut lhs = vec![0.0; d * d];
        let mut rhs = vec![0.0; d * k];
        for r in 0..d {
            lhs[r * d + r] = 1.0;
            for c in 0..d {
                let (mut f2a, mut c1a) = (0.0, 0.0);
                for q in 0..n {
                    f2a += f2h[r * d + n + q] * mj[q * d + c];
                    c1a += c1[r * d + n + q] * mi[q * d + c];
                }
                lhs[r * d + c] += f2a;
                rhs[r * k + c] = phi0[r * d + c] - c1a;
            }
            for t in 0..teeth {
                for c in 0..n {
                    let (mut c1b, mut f2b) = (0.0, 0.0);
                    for q in 0..n {
                        c1b += c1[r * d + n + q] * wi[t][q * n + c];
                        f2b += f2h[r * d + n + q] * wj[t][q * n + c];
                    }
                    rhs[r * k + d + 2 * n * t + c] = c1b;
                    rhs[r * k + d + 2 * n * t + n + c] = f2b;
                }
            }
        }
        if !solve_small(&mut lhs, &mut rhs, d, k) {
            return false;
        }
        for r in 0..d {
            out.extend_from_slice(&rhs[r * k..r * k + d]);
        }
        for t in 0..teeth {
            for block in [d + 2 * n * t, d + 2 * n * t + n] {
                for r in 0..d {
                    out.extend_from_slice(&rhs[r * k + block..r * k + block + n]);
                }
            }
        }
        true
    }
}

/// Gauss-Legendre points (fractions of the step) and weights of the semi-discretization's step
/// mean of the periodic coefficients.
fn gauss_points() -> [(f64, f64); 3] {
    [
        (0.5 - 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.5 + 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
    ]
}

/// One tooth in the cut on a variable-pitch segment: its W_t per unit depth where the steps
/// sample the coefficients (as [`Segment::Cutting`]'s `unit`) and, per step, where its delayed
/// displacements lie in the history.
#[derive(Debug, Clone)]
struct ToothInput {
    unit: Vec<f64>,
    taps: Vec<(Interp, Interp)>,
}

/// One segment of the grid, with what its steps need at any depth.
#[derive(Debug, Clone)]
enum Segment {
    /// Variable pitch: cutting steps as [`Segment::Cutting`] (`unit` the total [W | P]), with
    /// one delayed input per tooth in the cut, tooth t's delay pitch_t / Omega.
    Teeth {
        start_s: f64,
        steps: usize,
        h: f64,
        full: Option<FullSegment>,
        unit: Vec<f64>,
        teeth: Vec<ToothInput>,
    },
    /// No tooth cuts: one exact step e^{A_0 L} (row-major) of length L.
    Free { exp: Vec<f64>, length_s: f64 },
    /// `steps` cutting steps of length `h` from `start_s`; `unit` holds [W | P] per unit depth
    /// where the steps sample them: full discretization just inside the segment's start, then
    /// just inside each step's end; semi-discretization at the three Gauss points of each step.
    /// With constant coefficients (turning) only the first step is sampled.
    Cutting {
        start_s: f64,
        steps: usize,
        h: f64,
        full: Option<FullSegment>,
        unit: Vec<f64>,
    },
}

/// The depth-independent part of the step program of one discretization at one speed: the grid,
/// the constant exponentials and the periodic coefficients per unit depth (see the module docs).
#[derive(Debug, Clone)]
pub struct StepPlan {
    modes: usize,
    scheme: Scheme,
    a0: DMatrix<f64>,
    segments: Vec<Segment>,
    /// Whether the coefficients are constant (turning): every step of a segment is the same.
    constant: bool,
    period_s: f64,
    /// A helical cutter: the lag of its slices grows with the depth, so the program is built at
    /// each depth ([`StepPlan::helical_at_depth`]) from the model, speed and method kept here.
    helical: Option<Box<(ModalModel, f64, Discretization)>>,
}

impl StepPlan {
    /// The plan of `method` for `model` at `speed_rpm`. A helical cutter's plan keeps the model
    /// and builds the program at each depth ([`Self::monodromy`]); with helix zero the cutter is
    /// the straight one, to the bit.
    pub fn new(model: &ModalModel, speed_rpm: f64, method: Discretization) -> Result<Self> {
        check_condition(speed_rpm, 0.0)?;
        model.require_proportional(method.scheme.name())?;
        if model.operation().is_helical() {
            refuse_helical_process_damping(model, method)?;
            return Ok(Self {
                modes: model.mode_count(),
                scheme: method.scheme,
                a0: DMatrix::zeros(0, 0),
                segments: Vec::new(),
                constant: false,
                period_s: model.operation().principal_period_s(speed_rpm),
                helical: Some(Box::new((model.clone(), speed_rpm, method))),
            });
        }
        let (tau, _) = principal_period(model, speed_rpm);
        let periodic = Periodic {
            model,
            speed_rpm,
            phi: row_major(&model.shape_matrix()),
            modes: model.mode_count(),
            groups: None,
        };
        Self::build(&periodic, method, &segments(model, speed_rpm, tau))
    }

    /// The program of a helical cutter at `depth_m`: the cutting edge elements at that depth
    /// ([`chatter_dynamics::Milling::cutting_edges`]), grouped by delay into the delayed inputs,
    /// the grid cut where each tooth's engagement begins and ends (the crate's `grid` module).
    fn helical_at_depth(
        model: &ModalModel,
        speed_rpm: f64,
        method: Discretization,
        depth_m: f64,
    ) -> Result<Self> {
        let Operation::Milling(m) = model.operation() else {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: "operation.helix_deg: a helix is for milling only".into(),
            });
        };
        let edges = m.cutting_edges(depth_m);
        if let Some(e) = edges
            .iter()
            .find(|e| e.delay_rad.is_nan() || e.delay_rad <= 0.0)
        {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: format!(
                    "operation.helix_deg: at depth {} mm the teeth's helices cross (tooth {}'s \
                     delay angle is {} rad); the surface it cuts is not the tooth ahead's",
                    depth_m * 1e3,
                    e.tooth,
                    e.delay_rad
                ),
            });
        }
        let (tau, _) = principal_period(model, speed_rpm);
        let segs = envelope_segments(model, speed_rpm, tau, &edges);
        let periodic = Periodic {
            model,
            speed_rpm,
            phi: row_major(&model.shape_matrix()),
            modes: model.mode_count(),
            groups: Some(edge_groups(edges)),
        };
        Self::build(&periodic, method, &segs)
    }

    /// The plan over the grid `segs` of one principal period with the inputs of `periodic`.
    fn build(
        periodic: &Periodic,
        method: Discretization,
        segs: &[(f64, f64, bool)],
    ) -> Result<Self> {
        let (model, speed_rpm) = (periodic.model, periodic.speed_rpm);
        let n = model.mode_count();
        let d = 2 * n;
        let (tau, delays) = principal_period(model, speed_rpm);
        let cutting_time: f64 = segs.iter().filter(|s| s.2).map(|s| s.1 - s.0).sum();
        let m_cut = method
            .cutting_steps(model, cutting_time / delays as f64)
            .get()
            * delays;
        let omegas = model.omegas_rad_s();
        let zetas = model.damping_ratios();
        let mut a0 = DMatrix::zeros(d, d);
        for i in 0..n {
            a0[(i, n + i)] = 1.0;
            a0[(n + i, i)] = -omegas[i] * omegas[i];
            a0[(n + i, n + i)] = -2.0 * zetas[i] * omegas[i];
        }
        let constant = matches!(model.operation(), Operation::Turning(_));
        if model.operation().has_uneven_teeth() {
            let segments =
                variable_pitch_segments(periodic, segs, (m_cut, cutting_time), &a0, method, None)?;
            return Ok(Self {
                modes: n,
                scheme: method.scheme,
                a0,
                segments,
                constant,
                period_s: tau,
                helical: None,
            });
        }
        let segments = segs
            .iter()
            .map(|&(start, end, cutting)| {
                let len = end - start;
                if !cutting {
                    return Segment::Free {
                        exp: row_major(&(&a0 * len).exp()),
                        length_s: len,
                    };
                }
                let k = ((m_cut as f64 * len / cutting_time).round() as usize).max(1);
                let h = len / k as f64;
                let sampled = if constant { 1 } else { k };
                let mut unit = Vec::new();
                let full = match method.scheme {
                    Scheme::Full => {
                        // sampled just inside the segment (H is smooth there); the end of step i
                        // is the start of step i + 1 (same smooth segment)
                        let eps = 1e-9 * h;
                        periodic.push(start + eps, &mut unit);
                        for i in 0..sampled {
                            periodic.push(start + i as f64 * h + h - eps, &mut unit);
                        }
                        Some(FullSegment::new(&a0, h))
                    }
                    Scheme::Semi => {
                        for i in 0..sampled {
                            for (x, _) in gauss_points() {
                                periodic.push(start + i as f64 * h + x * h, &mut unit);
                            }
                        }
                        None
                    }
                };
                Segment::Cutting {
                    start_s: start,
                    steps: k,
                    h,
                    full,
                    unit,
                }
            })
            .collect();
        Ok(Self {
            modes: n,
            scheme: method.scheme,
            a0,
            segments,
            constant,
            period_s: tau,
            helical: None,
        })
    }

    /// The scheme of the plan.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The monodromy operator at depth `depth_m` (m).
    pub fn monodromy(&self, depth_m: f64) -> Result<Monodromy> {
        check_condition(1.0, depth_m)?;
        if let Some(helical) = &self.helical {
            let (model, speed_rpm, method) = helical.as_ref();
            return Self::helical_at_depth(model, *speed_rpm, *method, depth_m)?.monodromy(depth_m);
        }
        let n = self.modes;
        let d = 2 * n;
        let size = n * d;
        let mut steps = Vec::new();
        let mut step_s = Vec::new();
        let mut coefficients = Vec::new();
        let mut scratch = (Vec::new(), Vec::new());
        let (mut mi, mut mj) = (vec![0.0; size], vec![0.0; size]);
        let mut grid = 0usize;
        let mut taps = Vec::new();
        for segment in &self.segments {
            let (start_s, k, h, full, unit) = match segment {
                Segment::Teeth {
                    start_s,
                    steps: k,
                    h,
                    full,
                    unit,
                    teeth,
                } => {
                    for i in 0..*k {
                        let offset = coefficients.len();
                        let lengths = self.teeth_step(
                            depth_m,
                            (i, *h, full.as_ref()),
                            unit,
                            teeth,
                            &mut coefficients,
                        );
                        let Some(blocks) = lengths else {
                            return Err(StabilityError::NoConvergence {
                                solver: "full discretization",
                                detail: format!(
                                    "singular step matrix at t = {} s",
                                    start_s + i as f64 * h
                                ),
                            });
                        };
                        let first = taps.len();
                        let block = d * n;
                        for (t, tooth) in teeth.iter().enumerate() {
                            let (a, b) = tooth.taps[i];
                            taps.push(Tap {
                                r: blocks + 2 * t * block,
                                s: blocks + (2 * t + 1) * block,
                                a,
                                b,
                            });
                        }
                        steps.push(Step {
                            offset,
                            start: grid,
                            cutting: true,
                            taps: (first, taps.len()),
                        });
                        step_s.push(*h);
                        grid += 1;
                    }
                    continue;
                }
                Segment::Free { exp, length_s } => {
                    steps.push(Step {
                        offset: coefficients.len(),
                        start: grid,
                        cutting: false,
                        taps: (0, 0),
                    });
                    coefficients.extend_from_slice(exp);
                    step_s.push(*length_s);
                    grid += 1;
                    continue;
                }
                Segment::Cutting {
                    start_s,
                    steps,
                    h,
                    full,
                    unit,
                } => (*start_s, *steps, *h, full, unit),
            };
            for i in 0..k {
                if self.constant && i > 0 {
                    let mut step = steps[steps.len() - 1];
                    step.start = grid;
                    steps.push(step);
                    step_s.push(h);
                    grid += 1;
                    continue;
                }
                let offset = coefficients.len();
                match full {
                    Some(full) => {
                        if i == 0 {
                            scaled(depth_m, &unit[..size], &mut mi);
                        } else {
                            std::mem::swap(&mut mi, &mut mj);
                        }
                        scaled(depth_m, &unit[(i + 1) * size..(i + 2) * size], &mut mj);
                        if !full.step(n, &mi, &mj, &mut scratch, &mut coefficients) {
                            return Err(StabilityError::NoConvergence {
                                solver: "full discretization",
                                detail: format!(
                                    "singular step matrix at t = {} s",
                                    start_s + i as f64 * h
                                ),
                            });
                        }
                    }
                    None => self.semi_step(
                        depth_m,
                        &unit[3 * i * size..3 * (i + 1) * size],
                        h,
                        &mut mi,
                        &mut coefficients,
                    ),
                }
                steps.push(Step {
                    offset,
                    start: grid,
                    cutting: true,
                    taps: (0, 0),
                });
                step_s.push(h);
                grid += 1;
            }
        }
        Ok(Monodromy::from_steps(
            n,
            grid,
            steps,
            coefficients,
            step_s,
            taps,
            self.period_s,
        ))
    }

    /// Step `i` of a variable-pitch segment at `depth_m`: appends P and each tooth's R and S
    /// (FDM: [`FullSegment::step_teeth`]; SDM: A_0 + A frozen at its step mean, R_t = C_1 B_t,
    /// S_t = F_2/h B_t with B_t = [[0], [b mean W_t]]); returns where the R and S blocks start,
    /// or `None` for a singular FDM step matrix.
    fn teeth_step(
        &self,
        depth_m: f64,
        (i, h, full): (usize, f64, Option<&FullSegment>),
        unit: &[f64],
        teeth: &[ToothInput],
        out: &mut Vec<f64>,
    ) -> Option<usize> {
        let n = self.modes;
        let d = 2 * n;
        let size = n * d;
        let nn = n * n;
        let scale = |u: &[f64]| u.iter().map(|v| depth_m * v).collect::<Vec<f64>>();
        match full {
            Some(full) => {
                let mi = scale(&unit[i * size..(i + 1) * size]);
                let mj = scale(&unit[(i + 1) * size..(i + 2) * size]);
                let wi: Vec<Vec<f64>> = teeth
                    .iter()
                    .map(|t| scale(&t.unit[i * nn..(i + 1) * nn]))
                    .collect();
                let wj: Vec<Vec<f64>> = teeth
                    .iter()
                    .map(|t| scale(&t.unit[(i + 1) * nn..(i + 2) * nn]))
                    .collect();
                let at = out.len() + d * d;
                full.step_teeth(n, (&mi, &mj), (&wi, &wj), out)
                    .then_some(at)
            }
            None => {
                let gauss = gauss_points();
                let mean_of = |u: &[f64], len: usize| {
                    let mut mean = vec![0.0; len];
                    for (j, (_, wgt)) in gauss.iter().enumerate() {
                        for (a, b) in mean
                            .iter_mut()
                            .zip(&u[(3 * i + j) * len..(3 * i + j + 1) * len])
                        {
                            *a += wgt * depth_m * b;
                        }
                    }
                    mean
                };
                let mean = mean_of(unit, size);
                let mut a = self.a0.clone();
                for p in 0..n {
                    for c in 0..d {
                        a[(n + p, c)] -= mean[p * d + c];
                    }
                }
                let (e, f1, f2) = exp_integrals(&a, h);
                let c1 = &f1 - &f2 / h;
                let f2h = &f2 / h;
                out.extend(row_major(&e));
                let at = out.len();
                for tooth in teeth {
                    let w = mean_of(&tooth.unit, nn);
                    let mut bm = DMatrix::zeros(d, n);
                    for p in 0..n {
                        for c in 0..n {
                            bm[(n + p, c)] = w[p * n + c];
                        }
                    }
                    out.extend(row_major(&(&c1 * &bm)));
                    out.extend(row_major(&(&f2h * &bm)));
                }
                Some(at)
            }
        }
    }

    /// Semi-discretization step (Insperger and Stépán): A_0 + A frozen at the step's mean of
    /// the periodic part (3-point Gauss over `unit`, the three samples per unit depth) and
    /// integrated exactly; appends P = e^{A_i h}, R = C_1 B_i and S = F_2/h B_i with the F_1, F_2
    /// of A_i. `buffer` holds one scaled sample.
    fn semi_step(
        &self,
        depth_m: f64,
        unit: &[f64],
        h: f64,
        buffer: &mut [f64],
        out: &mut Vec<f64>,
    ) {
        let n = self.modes;
        let d = 2 * n;
        let size = n * d;
        let mut mean = vec![0.0; size];
        for (j, (_, wgt)) in gauss_points().into_iter().enumerate() {
            scaled(depth_m, &unit[j * size..(j + 1) * size], buffer);
            for (a, b) in mean.iter_mut().zip(buffer.iter()) {
                *a += wgt * b;
            }
        }
        let mut a = self.a0.clone();
        let mut bm = DMatrix::zeros(d, n);
        for p in 0..n {
            for c in 0..d {
                a[(n + p, c)] -= mean[p * d + c];
            }
            for c in 0..n {
                bm[(n + p, c)] = mean[p * d + c];
            }
        }
        let (e, f1, f2) = exp_integrals(&a, h);
        out.extend(row_major(&e));
        out.extend(row_major(&((&f1 - &f2 / h) * &bm)));
        out.extend(row_major(&(&f2 / h * &bm)));
    }
}

/// Process damping on a helical cutter (D(t) would need the slices' surface normals) is refused,
/// naming `operation.helix_deg`.
fn refuse_helical_process_damping(model: &ModalModel, method: Discretization) -> Result<()> {
    if model.process_damping_n_per_m().is_some_and(|c| c > 0.0) {
        return Err(StabilityError::Unsupported {
            method: method.scheme.name(),
            reason: "operation.helix_deg with process_damping is not modelled (the slices' \
                     process damping)"
                .into(),
        });
    }
    Ok(())
}

impl StepPlan {
    /// The plan of `method` for `model` at the mean speed `speed_rpm` under the spindle-speed
    /// variation of relative amplitude `amplitude_ratio` in (0, 1) at `frequency_ratio` times the
    /// mean spindle frequency: the principal period is the modulation period T_m, which must hold
    /// a whole number q = N / frequency_ratio of mean tooth periods (of revolutions in turning),
    /// the grid is cut at every tooth entry and exit in true time, and each step's delayed points
    /// are where the tooth ahead passed the same angle (the time-varying delay, interpolated in
    /// the history). Models with process damping are refused (the cutting speed varies too).
    pub(crate) fn with_speed_variation(
        model: &ModalModel,
        speed_rpm: f64,
        method: Discretization,
        (amplitude_ratio, frequency_ratio): (f64, f64),
    ) -> Result<Self> {
        check_condition(speed_rpm, 0.0)?;
        model.require_proportional(method.scheme.name())?;
        if model.process_damping_n_per_m().is_some_and(|c| c > 0.0) {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: "process_damping with a spindle-speed variation (the cutting speed varies \
                         along the cut) is not modelled"
                    .into(),
            });
        }
        let op = model.operation();
        if op.is_helical() {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason:
                    "operation.helix_deg with a spindle-speed variation is not modelled in the \
                         discretizations (the time-domain simulator models both)"
                        .into(),
            });
        }
        let delays = op.delays_per_revolution();
        let q_real = delays as f64 / frequency_ratio;
        let q = q_real.round();
        if !(q >= 1.0 && (q_real - q).abs() <= 1e-9 * q_real) {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: format!(
                    "ssv_frequency_ratio = {frequency_ratio}: the modulation period must hold a \
                     whole number of tooth periods (revolutions in turning), i.e. a ratio \
                     {delays} / q for an integer q >= 1 (here {delays} / {frequency_ratio} = {q_real})"
                ),
            });
        }
        let q = q as usize;
        let tau = op.delay_s(speed_rpm);
        let period = q as f64 * tau;
        let revolution = 60.0 / speed_rpm;
        let omega = 2.0 * std::f64::consts::PI / revolution;
        let map = TimeMap::new(amplitude_ratio, 2.0 * std::f64::consts::PI / period);
        // breakpoints in equivalent time: every entry and exit over the q delays
        let mut cuts = vec![0.0, period];
        if let Operation::Milling(m) = op {
            let (entry, exit) = m.entry_exit_rad();
            let revolutions = (period / revolution).ceil() as usize + 1;
            for k in 0..revolutions {
                for j in 0..m.teeth() {
                    for angle in [entry, exit] {
                        let s = ((angle - m.tooth_offset_rad(j)) / omega).rem_euclid(revolution)
                            + k as f64 * revolution;
                        if s > 1e-12 * period && s < period * (1.0 - 1e-12) {
                            cuts.push(s);
                        }
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * period);
        let segs: Vec<(f64, f64, bool)> = cuts
            .windows(2)
            .map(|w| {
                let mid = 0.5 * (w[0] + w[1]);
                let cutting = model.directional_matrix(mid, speed_rpm).abs().max() > 0.0;
                (map.inverse(w[0]), map.inverse(w[1]), cutting)
            })
            .collect();
        let cutting_time: f64 = segs.iter().filter(|s| s.2).map(|s| s.1 - s.0).sum();
        let m_cut = method.cutting_steps(model, cutting_time / q as f64).get() * q;
        let n = model.mode_count();
        let d = 2 * n;
        let omegas = model.omegas_rad_s();
        let zetas = model.damping_ratios();
        let mut a0 = DMatrix::zeros(d, d);
        for i in 0..n {
            a0[(i, n + i)] = 1.0;
            a0[(n + i, i)] = -omegas[i] * omegas[i];
            a0[(n + i, n + i)] = -2.0 * zetas[i] * omegas[i];
        }
        let periodic = Periodic {
            model,
            speed_rpm,
            phi: row_major(&model.shape_matrix()),
            modes: n,
            groups: None,
        };
        let segments = variable_pitch_segments(
            &periodic,
            &segs,
            (m_cut, cutting_time),
            &a0,
            method,
            Some(map),
        )?;
        Ok(Self {
            modes: n,
            scheme: method.scheme,
            a0,
            segments,
            constant: false,
            period_s: period,
            helical: None,
        })
    }
}

/// The segments of a variable-pitch cutter over one revolution `period` (grid `segs` cut at every
/// tooth's entry and exit): free flight as for even pitch; cutting segments with
/// `m_cut` steps over the `cutting_time` in proportion to their length, the total [W | P] and
/// each cutting tooth's W_t sampled as [`StepPlan::new`] samples them, and each tooth's delayed
/// points t_k - tau_t, t_{k+1} - tau_t located in the history (linear interpolation between grid
/// points; on the grid itself when the teeth's cuts do not overlap, since every tooth's cut then
/// gets the same steps).
///
/// With a spindle-speed variation (`map`, [`TimeMap`]) the segments are in true time, the
/// coefficients are sampled at the equivalent constant-speed time of the tooth angles, and each
/// tooth's delay is the time the spindle takes to turn its pitch before the step's points.
fn variable_pitch_segments(
    periodic: &Periodic,
    segs: &[(f64, f64, bool)],
    (m_cut, cutting_time): (usize, f64),
    a0: &DMatrix<f64>,
    method: Discretization,
    map: Option<TimeMap>,
) -> Result<Vec<Segment>> {
    let equivalent = |t: f64| map.map_or(t, |m| m.equivalent(t));
    let omega = 2.0 * std::f64::consts::PI * periodic.speed_rpm / 60.0;
    let period = segs.last().map_or(0.0, |s| s.1);
    // steps per segment and the grid times
    let counts: Vec<usize> = segs
        .iter()
        .map(|&(start, end, cutting)| {
            if cutting {
                ((m_cut as f64 * (end - start) / cutting_time).round() as usize).max(1)
            } else {
                1
            }
        })
        .collect();
    let mut times = vec![0.0];
    for (&(start, end, _), &k) in segs.iter().zip(&counts) {
        let h = (end - start) / k as f64;
        for i in 1..k {
            times.push(start + i as f64 * h);
        }
        times.push(end);
    }
    let grid = times.len() - 1;
    let locate = |u: f64, step: usize| -> Result<Interp> {
        // u in [0, 2 T): the previous period's grid, then this one's
        if u < -1e-12 * period {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: format!(
                    "a delay longer than the principal period ({period} s): the history holds \
                     one period"
                ),
            });
        }
        let (base, v) = if u >= period {
            (grid, u - period)
        } else {
            (0, u.max(0.0))
        };
        let i = times
            .partition_point(|t| *t <= v)
            .saturating_sub(1)
            .min(grid - 1);
        let w = (v - times[i]) / (times[i + 1] - times[i]);
        let at = if w > 1.0 - 1e-9 {
            Interp {
                p: base + i + 1,
                w: 0.0,
            }
        } else if w < 1e-9 {
            Interp {
                p: base + i,
                w: 0.0,
            }
        } else {
            Interp { p: base + i, w }
        };
        if at.p + usize::from(at.w > 0.0) > grid + step {
            return Err(StabilityError::Unsupported {
                method: method.scheme.name(),
                reason: format!(
                    "operation.pitch_deg: a pitch shorter than one step of the grid ({} s); \
                     use more steps",
                    times[i + 1] - times[i]
                ),
            });
        }
        Ok(at)
    };
    let mut out = Vec::with_capacity(segs.len());
    let mut first_step = 0usize;
    for (&(start, end, cutting), &k) in segs.iter().zip(&counts) {
        let len = end - start;
        if !cutting {
            out.push(Segment::Free {
                exp: row_major(&(a0 * len).exp()),
                length_s: len,
            });
            first_step += 1;
            continue;
        }
        let h = len / k as f64;
        // the sample times of the scheme, as StepPlan::new takes them
        let samples: Vec<f64> = match method.scheme {
            Scheme::Full => {
                let eps = 1e-9 * h;
                std::iter::once(start + eps)
                    .chain((0..k).map(|i| start + i as f64 * h + h - eps))
                    .collect()
            }
            Scheme::Semi => (0..k)
                .flat_map(|i| gauss_points().map(|(x, _)| start + i as f64 * h + x * h))
                .collect(),
        };
        let mut unit = Vec::new();
        for &t in &samples {
            periodic.push(equivalent(t), &mut unit);
        }
        let mut teeth = Vec::new();
        for j in 0..periodic.inputs() {
            // an input that cuts nowhere the steps sample it has no delayed term here (on a
            // straight cutter's segment a tooth cuts at every sample or at none)
            let mut tooth_unit = Vec::new();
            for &t in &samples {
                periodic.push_tooth(j, equivalent(t), &mut tooth_unit);
            }
            if tooth_unit.iter().all(|w| *w == 0.0) {
                continue;
            }
            let tau = periodic.delay_rad(j) / omega;
            let taps = (0..k)
                .map(|i| {
                    let t0 = start + i as f64 * h;
                    let step = first_step + i;
                    Ok(match map {
                        None => (
                            locate(t0 - tau + period, step)?,
                            locate(t0 + h - tau + period, step)?,
                        ),
                        // the time the tooth ahead passed the same angle
                        Some(m) => (
                            locate(m.inverse(m.equivalent(t0) - tau) + period, step)?,
                            locate(m.inverse(m.equivalent(t0 + h) - tau) + period, step)?,
                        ),
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            teeth.push(ToothInput {
                unit: tooth_unit,
                taps,
            });
        }
        let full = match method.scheme {
            Scheme::Full => Some(FullSegment::new(a0, h)),
            Scheme::Semi => None,
        };
        out.push(Segment::Teeth {
            start_s: start,
            steps: k,
            h,
            full,
            unit,
            teeth,
        });
        first_step += k;
    }
    Ok(out)
}
