//! The key parameters of a model as a report table, in the units of the model file.

use super::{Table, number};
use chatter_dynamics::{ModalModel, ModeShape, Operation};

/// The model's operation, cutting coefficients, process damping and modes, one row per
/// parameter with its unit (N/mm^2 and mm as in the model file; SI inside).
pub fn model_table(label: &str, m: &ModalModel) -> Table {
    let mut t = Table::new(label, &["parameter", "value", "unit"]);
    let mut row = |name: &str, value: String, unit: &str| {
        t.row(vec![name.into(), value, unit.into()]);
    };
    if let Some(name) = m.name() {
        row("name", name.into(), "");
    }
    match m.operation() {
        Operation::Milling(g) => {
            row("operation", "milling".into(), "");
            row("teeth", g.teeth().to_string(), "");
            row("radial immersion a/D", number(g.radial_immersion()), "1");
            row(
                "direction",
                match g.direction() {
                    chatter_dynamics::MillingDirection::Up => "up milling",
                    chatter_dynamics::MillingDirection::Down => "down milling",
                }
                .into(),
                "",
            );
            if let Some(d) = g.tool_diameter_m() {
                row("tool diameter", number(d * 1e3), "mm");
            }
            if let Some(h) = g.helix_rad() {
                row("helix angle", number(h.to_degrees()), "deg");
            }
        }
        Operation::Turning(g) => {
            row("operation", "turning".into(), "");
            if let Some(d) = g.workpiece_diameter_m() {
                row("workpiece diameter", number(d * 1e3), "mm");
            }
        }
    }
    let cutting = m.cutting();
    row(
        "tangential cutting coefficient kt",
        number(cutting.kt_n_per_m2() * 1e-6),
        "N/mm^2",
    );
    row(
        "normal cutting coefficient kn",
        number(cutting.kn_n_per_m2() * 1e-6),
        "N/mm^2",
    );
    if let Some(c) = m.process_damping_n_per_m() {
        row("process damping coefficient C", number(c), "N/m");
    }
    let coordinates = m.operation().coordinates();
    if m.modes().is_empty() {
        row("modes", "none (measured FRF)".into(), "");
    }
    for (k, mode) in m.modes().iter().enumerate() {
        let n = k + 1;
        row(
            &format!("mode {n} natural frequency"),
            number(mode.frequency_hz()),
            "Hz",
        );
        row(
            &format!("mode {n} damping ratio"),
            number(100.0 * mode.damping_ratio()),
            "%",
        );
        match mode.shape() {
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m,
            } => row(
                &format!(
                    "mode {n} stiffness ({})",
                    coordinates.get(coordinate).map_or("?", |c| c.name())
                ),
                number(stiffness_n_per_m),
                "N/m",
            ),
            ModeShape::MassNormalized(shape) => row(
                &format!(
                    "mode {n} mass-normalized shape ({}, {})",
                    coordinates[0].name(),
                    coordinates[1].name()
                ),
                format!("{}, {}", number(shape[0]), number(shape[1])),
                "1/sqrt(kg)",
            ),
        }
        if !mode.is_proportional() {
            row(
                &format!("mode {n} residue phase (non-proportional)"),
                number(mode.residue_phase_rad().to_degrees()),
                "deg",
            );
        }
    }
    t
}

/// The unit of an updated or sampled parameter, from its name (`kt_n_per_mm2`, `c_n_per_m`,
/// `sigma_w2_hz2`, the relative `theta_*` perturbations of 000 Eq. 26).
pub fn parameter_unit(name: &str) -> &'static str {
    if name.ends_with("_n_per_mm2") {
        "N/mm^2"
    } else if name.ends_with("_n_per_m") {
        "N/m"
    } else if name.ends_with("_hz2") {
        "Hz^2"
    } else if name.ends_with("_hz") {
        "Hz"
    } else if name.ends_with("_mm") {
        "mm"
    } else if name.ends_with("_rpm") {
        "rpm"
    } else if name.ends_with("_per_rpm2") {
        "1/rpm^2"
    } else if name.ends_with("_deg") {
        "deg"
    } else if name.starts_with("theta_") {
        "1 (relative change)"
    } else {
        "1"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_milling_example_shows_its_file_values_with_units() {
        let t = model_table("m", &chatter_dynamics::examples::schmitz_2023_milling());
        let mut html = String::new();
        t.html(&mut html);
        for needed in ["teeth", "N/mm^2", "Hz", "%", "N/m", "radial immersion"] {
            assert!(html.contains(needed), "{needed}: {html}");
        }
    }

    #[test]
    fn units_follow_the_names() {
        assert_eq!(parameter_unit("kt_n_per_mm2"), "N/mm^2");
        assert_eq!(parameter_unit("c_n_per_m"), "N/m");
        assert_eq!(parameter_unit("sigma_w2_hz2"), "Hz^2");
        assert_eq!(parameter_unit("theta_omega_2"), "1 (relative change)");
        assert_eq!(parameter_unit("sigma_r2"), "1");
        assert_eq!(parameter_unit("softening_per_rpm2"), "1/rpm^2");
        assert_eq!(parameter_unit("direction_deg"), "deg");
    }
}
