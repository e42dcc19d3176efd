//! Units of the compliant drive's parameters and outputs on a rotary or a linear axis. The
//! equations are the same on both (docs/fit-drive.md): on a linear axis (a ball screw, a belt)
//! everything past the gear is in the load's translation units (position [m], force [N], mass
//! [kg]) and the ratio N is in [rad/m]; the motor's own parameters keep theirs.

use super::fit::Signal;
use crate::drive::model::Axis;

/// The motor's own parameters, whose units do not depend on the axis.
const MOTOR_SIDE: [&str; 5] = ["R", "Km", "Ke", "Jj", "Cj"];

/// The unit of parameter `name` (hd-model's registry name; `N` the gear ratio) on `axis`.
pub fn parameter_unit(name: &str, axis: Axis) -> String {
    if name == "N" {
        return if axis == Axis::Linear { "rad/m" } else { "–" }.to_string();
    }
    let rotary = hd_model::registry::lookup(name).map_or("", |i| i.unit);
    if axis == Axis::Rotary || MOTOR_SIDE.contains(&name) {
        return rotary.to_string();
    }
    rotary.replace("kg·m²", "kg").replace("N·m", "N").replace("rad", "m")
}

/// The unit of output `o` on `axis` (the command's is `V or A`; the caller knows which).
pub fn signal_unit(o: Signal, axis: Axis) -> &'static str {
    match (o, axis) {
        (Signal::Load, Axis::Linear) => "m",
        _ => o.unit(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each kind of unit the registry gives the load's side maps to its translation unit;
    /// the motor's parameters and the rotary axis keep the registry's.
    #[test]
    fn load_side_units_translate() {
        let l = Axis::Linear;
        for (name, unit) in [
            ("Jz", "kg"),
            ("Cz", "N·s/m"),
            ("c", "N/m"),
            ("a", "N/m³"),
            ("mem_A", "N/m"),
            ("mem_B", "1/s"),
            ("sigma0", "N/m"),
            ("sigma1", "N·s/m"),
            ("Tc", "N"),
            ("ws", "m/s"),
            ("bw_beta", "m^-n"),
            ("ms_delta", "m"),
            ("TL", "N"),
            ("N", "rad/m"),
            ("Jj", "kg·m²"),
            ("Ke", "V·s/rad"),
        ] {
            assert_eq!(parameter_unit(name, l), unit, "{name}");
        }
        assert_eq!(parameter_unit("Jz", Axis::Rotary), "kg·m²");
        assert_eq!(signal_unit(Signal::Load, l), "m");
        assert_eq!(signal_unit(Signal::Motor, l), "rad");
    }
}
