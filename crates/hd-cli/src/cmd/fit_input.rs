//! Reading a rig's recording for `hdw fit`: the named columns, converted to SI by the
//! unit options, and the speed derived from an encoder position when asked. Every step is
//! recorded so fit.json says what was done to the data.

use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::DataSource;
use hd_ident::derivative::{DEFAULT_ORDER, choose_half_window, savitzky_golay_derivative};
use std::path::Path;

/// Split `a,b,c` into exactly `n` non-empty column names (one of `counts`).
pub fn column_names(text: &str, counts: &[usize], flag: &str) -> Result<Vec<String>> {
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).collect();
    if !counts.contains(&names.len()) || names.iter().any(String::is_empty) {
        let n: Vec<String> = counts.iter().map(|c| c.to_string()).collect();
        bail!("{flag} {text}: expected {} comma-separated column names", n.join(" or "));
    }
    // One column in two roles (time read as deflection) fits nonsense without a word.
    for (k, name) in names.iter().enumerate() {
        if let Some(j) = names[..k].iter().position(|m| m == name) {
            bail!(
                "{flag} {text}: column '{name}' is named twice (positions {} and {}): each role needs its own column",
                j + 1,
                k + 1
            );
        }
    }
    Ok(names)
}

/// Read the named columns of `path`.
pub fn load(path: &Path, names: &[String]) -> Result<Vec<Vec<f64>>> {
    super::common::check_data_file(path, "data file")?;
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(hd_io::read_columns(path, &refs)?)
}

/// Where a data set came from, with what was done to it.
pub fn source(role: &str, path: &Path, names: &[String], preprocessing: Vec<String>) -> DataSource {
    DataSource {
        role: role.into(),
        file: path.display().to_string(),
        columns: names.to_vec(),
        preprocessing,
    }
}

/// Context for a data-set error: the file and which columns played which role.
pub fn data_context(path: &Path, roles: &[&str], names: &[String]) -> String {
    let map: Vec<String> = roles.iter().zip(names).map(|(r, n)| format!("{r} = '{n}'")).collect();
    format!("{} (columns {})", path.display(), map.join(", "))
}

/// Whether `factor` can be a unit factor: finite, non-zero and within ×1e12 of 1 either way
/// (hd-ident's `SCALE_RANGE`, the drive fits' limit; beyond it a signal overflows or
/// vanishes in the fit's arithmetic).
pub fn usable_factor(factor: f64) -> bool {
    use hd_ident::drive::config::validate::SCALE_RANGE;
    factor.is_finite() && factor != 0.0 && (1.0 / SCALE_RANGE..=SCALE_RANGE).contains(&factor.abs())
}

/// Multiply `col` by `factor` (a conversion to SI), recording it.
pub fn scale(
    col: &mut [f64],
    factor: f64,
    what: &str,
    flag: &str,
    log: &mut Vec<String>,
) -> Result<()> {
    if !usable_factor(factor) {
        bail!(
            "{flag} {}: expected a finite, non-zero factor between 1e-12 and 1e12 in magnitude (the file's unit to SI; negative flips the sign)",
            hd_model::error::num(factor)
        );
    }
    if factor != 1.0 {
        col.iter_mut().for_each(|v| *v *= factor);
        log.push(format!("{what} multiplied by {factor:e} ({flag})"));
    }
    Ok(())
}

/// An angle unit of a deflection column: its factor to radians.
pub fn angle_factor(unit: &str) -> Result<f64> {
    Ok(match unit {
        "rad" => 1.0,
        "mrad" => 1e-3,
        "urad" | "µrad" => 1e-6,
        "deg" => std::f64::consts::PI / 180.0,
        "arcmin" => std::f64::consts::PI / (180.0 * 60.0),
        "arcsec" => std::f64::consts::PI / (180.0 * 3600.0),
        other => bail!("--theta-unit {other}: expected rad, mrad, urad, deg, arcmin or arcsec"),
    })
}

/// Unit options shared by the friction data sets.
#[derive(Args, Debug, Clone)]
pub struct FrictionUnits {
    /// Factor from the file's time unit to seconds (e.g. 1e-3 for ms).
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub time_scale: f64,
    /// Factor from the file's speed unit to rad/s (or m/s for a linear rig), e.g. 0.10472 for rpm.
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub speed_scale: f64,
    /// Factor from the file's position unit to rad (or m), with --position-column; e.g. 1e-3 for mm.
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub position_scale: f64,
    /// Factor from the file's torque unit to N·m (or N); negative flips the sign, e.g. -1e-6 for µN
    /// measured with the opposite sign convention.
    #[arg(long, value_name = "K", default_value_t = 1.0, allow_hyphen_values = true)]
    pub torque_scale: f64,
    /// Speed from this position column instead of a speed column (Savitzky–Golay derivative);
    /// --transient-columns then names only T,TORQUE.
    #[arg(long, value_name = "NAME")]
    pub position_column: Option<String>,
    /// Half-width of the differentiator's window [samples]; default: chosen from the data's
    /// noise and reversals (see fit.json).
    #[arg(long, value_name = "N")]
    pub derivative_window: Option<usize>,
    /// Degree of the differentiator's local polynomial.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_ORDER)]
    pub derivative_order: usize,
}

/// A friction time series read and converted: t [s], ω [rad/s], torque [N·m], the columns
/// as named and what was done.
pub struct Series {
    pub t: Vec<f64>,
    pub omega: Vec<f64>,
    pub torque: Vec<f64>,
    pub names: Vec<String>,
    pub log: Vec<String>,
}

/// Read a friction time series: `names` is T,OMEGA,TORQUE, or T,TORQUE with a position column.
pub fn friction_series(path: &Path, columns: &str, u: &FrictionUnits) -> Result<Series> {
    let mut log = Vec::new();
    let (names, mut cols) = match &u.position_column {
        None => {
            let names = column_names(columns, &[3], "--transient-columns")?;
            let cols = load(path, &names)?;
            (names, cols)
        }
        Some(pos) => {
            let given = column_names(columns, &[2, 3], "--transient-columns")?;
            if given.len() == 3 {
                bail!(
                    "--transient-columns {columns}: with --position-column '{pos}' name only the time and torque columns (T,TORQUE); the speed comes from the position"
                );
            }
            let names = vec![given[0].clone(), pos.clone(), given[1].clone()];
            let cols = load(path, &names)?;
            (names, cols)
        }
    };
    let mut torque = cols.pop().unwrap_or_default();
    let mut middle = cols.pop().unwrap_or_default();
    let mut t = cols.pop().unwrap_or_default();
    scale(&mut t, u.time_scale, "time", "--time-scale", &mut log)?;
    scale(&mut torque, u.torque_scale, "torque", "--torque-scale", &mut log)?;
    let omega = match &u.position_column {
        None => {
            scale(&mut middle, u.speed_scale, "speed", "--speed-scale", &mut log)?;
            middle
        }
        Some(pos) => {
            scale(&mut middle, u.position_scale, "position", "--position-scale", &mut log)?;
            if let Some(w) = t.windows(2).position(|w| w[1] <= w[0]) {
                bail!(
                    "{}: column '{}', row {}: time {} does not come after the previous row's {}; time must increase strictly",
                    path.display(),
                    names[0],
                    w + 2,
                    t[w + 1],
                    t[w]
                );
            }
            let order = u.derivative_order;
            let (h, why) = match u.derivative_window {
                Some(h) => (h, format!("half-window {h} samples as given (--derivative-window)")),
                None => {
                    let c = choose_half_window(&t, &middle, order);
                    (c.half_window, c.reason)
                }
            };
            let omega = savitzky_golay_derivative(&t, &middle, h, order).with_context(|| {
                format!("{}: speed from position column '{pos}'", path.display())
            })?;
            log.push(format!(
                "speed = d/dt of position column '{pos}' by a Savitzky–Golay differentiator (local polynomial of degree {order} over {} samples); {why}",
                2 * h + 1
            ));
            omega
        }
    };
    Ok(Series { t, omega, torque, names, log })
}
