//! True parameters of the rate-independent laws for synthetic data: defaults scaled to
//! the test's amplitude, changed by `NAME=VALUE` assignments in the laws' own names
//! (`ms_k3=…`, `ms_f3=…`, `bw_beta=…`); the spring a, b, c comes from the registry.

use crate::error::FitError;
use hd_model::Params;
use hd_model::laws::bouc_wen::{BoucWen, BoucWenStiffness};
use hd_model::laws::maxwell_slip::{MaxwellSlip, SlipElement};
use hd_model::laws::stiffness::CubicSpring;

/// Whether `name` belongs to one of the rate-independent laws (prefix `ms_` or `bw_`).
pub fn is_law_name(name: &str) -> bool {
    name.starts_with("ms_") || name.starts_with("bw_")
}

fn unknown(name: &str, law: &str, expected: &str) -> FitError {
    FitError::Setting {
        field: "set",
        value: name.to_string(),
        expected: format!("a parameter of the {law} law: {expected}"),
    }
}

fn positive(name: &str, v: f64) -> Result<f64, FitError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(FitError::Setting {
            field: "set",
            value: format!("{name}={v}"),
            expected: "a finite value >= 0".into(),
        })
    }
}

/// The default Maxwell-slip truth: `elements` elements of equal stiffness mem_A/elements
/// (the memory law's intensity shared out), yield deflections log-spaced from 2 % to 60 %
/// of `amplitude`, then the assignments applied (`ms_k<i>`, `ms_f<i>`, i from 1).
pub fn maxwell_slip_truth(
    p: &Params,
    amplitude: f64,
    elements: usize,
    set: &[(String, f64)],
) -> Result<MaxwellSlip, FitError> {
    if elements == 0 {
        return Err(FitError::Setting {
            field: "elements",
            value: "0".into(),
            expected: "at least 1".into(),
        });
    }
    let k = p.mem_a / elements as f64;
    let mut els: Vec<SlipElement> = (0..elements)
        .map(|i| {
            let share = if elements == 1 { 1.0 } else { i as f64 / (elements - 1) as f64 };
            SlipElement::from_yield(k, amplitude * 0.02 * 30f64.powf(share))
        })
        .collect();
    for (name, v) in set {
        let index = |rest: &str| rest.parse::<usize>().ok().filter(|i| (1..=elements).contains(i));
        let expected = format!("ms_k<i> or ms_f<i> with i in 1..={elements}");
        if let Some(i) = name.strip_prefix("ms_k").and_then(index) {
            els[i - 1].k = positive(name, *v)?;
        } else if let Some(i) = name.strip_prefix("ms_f").and_then(index) {
            els[i - 1].f = positive(name, *v)?;
        } else {
            return Err(unknown(name, "maxwell-slip", &expected));
        }
    }
    Ok(MaxwellSlip { spring: CubicSpring { a: p.a, b: p.b, c: p.c }, elements: els })
}

/// The default Bouc–Wen truth: α = mem_A, A = 1, n = 1, saturation deflection 20 % of
/// `amplitude` with γ/β = 3/7, then the assignments applied (`bw_alpha`, `bw_A`, `bw_beta`,
/// `bw_gamma`, `bw_n`).
pub fn bouc_wen_truth(
    p: &Params,
    amplitude: f64,
    set: &[(String, f64)],
) -> Result<BoucWenStiffness, FitError> {
    let wu = 0.2 * amplitude;
    let mut el = BoucWen { alpha: p.mem_a, a: 1.0, beta: 0.7 / wu, gamma: 0.3 / wu, n: 1.0 };
    for (name, v) in set {
        match name.as_str() {
            "bw_alpha" => el.alpha = *v,
            "bw_A" => el.a = positive(name, *v)?,
            "bw_beta" => el.beta = *v,
            "bw_gamma" => el.gamma = *v,
            "bw_n" => el.n = positive(name, *v)?,
            _ => {
                return Err(unknown(name, "bouc-wen", "bw_alpha, bw_A, bw_beta, bw_gamma or bw_n"));
            }
        }
        if !v.is_finite() {
            return Err(FitError::Setting {
                field: "set",
                value: format!("{name}={v}"),
                expected: "a finite value".into(),
            });
        }
    }
    if el.n <= 0.0 {
        return Err(FitError::Setting {
            field: "set",
            value: format!("bw_n={}", el.n),
            expected: "a value > 0".into(),
        });
    }
    Ok(BoucWenStiffness { spring: CubicSpring { a: p.a, b: p.b, c: p.c }, element: el })
}
