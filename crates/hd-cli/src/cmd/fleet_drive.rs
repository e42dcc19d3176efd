//! The drive template of `hdw fleet`: every log fitted as `hdw fit drive` fits one record,
//! with the fleet's configuration whose one `[[experiment]]` `file` is replaced by the
//! log. Each log runs `hdw fit drive` (this binary) in a temporary folder, so the fit is
//! exactly the command's (controller check, start, the laws ranked by BIC); its fit.json
//! gives the rows: the best law's parameters with their standard errors.

use super::fleet_fit::LogFit;
use super::fleet_plan::LogSpec;
use hd_ident::Estimate;
use std::path::Path;

/// The configuration's lines with the one `file = …` replaced by `path`; an error when the
/// configuration has no or several `file` keys (one record per log).
pub fn with_record(config: &str, path: &Path) -> Result<String, String> {
    let is_file = |l: &str| {
        let t = l.trim_start();
        t.strip_prefix("file").is_some_and(|r| r.trim_start().starts_with('='))
    };
    let n = config.lines().filter(|l| is_file(l)).count();
    if n != 1 {
        return Err(format!(
            "the drive configuration has {n} `file =` keys: expected one [[experiment]] whose file each log replaces"
        ));
    }
    let quoted = path.display().to_string().replace('\\', "\\\\").replace('"', "\\\"");
    let lines: Vec<String> = config
        .lines()
        .map(|l| if is_file(l) { format!("file = \"{quoted}\"") } else { l.to_string() })
        .collect();
    Ok(lines.join("\n") + "\n")
}

/// The registry's unit of a drive parameter (a `&'static str` for the table).
fn unit_of(name: &str, unit: &str) -> &'static str {
    if let Some(p) = hd_model::registry::find(name) {
        return p.unit;
    }
    const UNITS: [&str; 14] = [
        "kg",
        "N",
        "N·s/m",
        "N/V",
        "m",
        "s",
        "kg·m²",
        "N·m",
        "N·m·s/rad",
        "N·m/V",
        "rad",
        "m/s",
        "rad/s",
        "-",
    ];
    UNITS.iter().copied().find(|u| *u == unit).unwrap_or("")
}

/// A temporary folder for one log's fit, removed when dropped.
struct Work(std::path::PathBuf);

impl Work {
    fn new(index: usize) -> Result<Self, String> {
        let p =
            std::env::temp_dir().join(format!("hdw-fleet-drive-{}-{index}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        Ok(Work(p))
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Work {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Fit one log with `config` (the template's text); fills `out`'s fit quality.
pub fn fit_drive_log(
    log: &LogSpec,
    config: &str,
    out: &mut LogFit,
) -> Result<Vec<(String, Estimate)>, String> {
    if let Some(p) = &log.problem {
        return Err(p.clone());
    }
    let path =
        std::path::absolute(&log.path).map_err(|e| format!("{}: {e}", log.path.display()))?;
    if !path.exists() {
        return Err(format!("{}: no such file", log.path.display()));
    }
    super::common::check_data_file(&path, "log").map_err(|e| format!("{e:#}"))?;
    let text = with_record(config, &path)?;
    let work = Work::new(log.index)?;
    let cfg = work.path().join("fit.toml");
    std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let dir = work.path().join("fit");
    let exe = std::env::current_exe().map_err(|e| format!("this program's path: {e}"))?;
    let run = std::process::Command::new(exe)
        .args(["fit", "drive", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&dir)
        .stdout(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("hdw fit drive: {e}"))?;
    if !run.status.success() {
        let err = String::from_utf8_lossy(&run.stderr);
        let line = err
            .lines()
            .rev()
            .find(|l| l.trim_start().starts_with("error"))
            .or_else(|| err.lines().rev().find(|l| !l.trim().is_empty()))
            .unwrap_or("failed")
            .trim()
            .to_string();
        let line = line.replace(&cfg.display().to_string(), "the drive configuration");
        return Err(format!("{}: hdw fit drive: {line}", log.path.display()));
    }
    let fit_json = dir.join("fit.json");
    let text = std::fs::read_to_string(&fit_json).map_err(|e| format!("fit.json: {e}"))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("fit.json: {e}"))?;
    let Some(params) = doc.get("parameters").and_then(|p| p.as_object()) else {
        return Err("fit.json: no parameters".into());
    };
    let best = doc.get("best").and_then(|b| b.as_str()).unwrap_or("");
    // The best law's position residual over the position noise (the record's scores).
    let pos = doc
        .get("experiments")
        .and_then(|r| r.as_object())
        .and_then(|r| r.values().next())
        .and_then(|e| e.get("position"));
    out.rms = pos.and_then(|p| p.get("rmse")).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
    out.samples = pos.and_then(|p| p.get("samples")).and_then(|v| v.as_u64()).unwrap_or(0);
    out.noise_std = doc
        .get("noise")
        .and_then(|n| n.get("position"))
        .and_then(|v| v.as_f64())
        .unwrap_or(f64::NAN);
    out.resid_over_noise = out.rms / out.noise_std;
    out.fit = format!("drive-{best}");
    let mut rows = Vec::new();
    for (name, p) in params {
        let num = |k: &str| p.get(k).and_then(|v| v.as_f64());
        let Some(value) = num("value") else { continue };
        let free = p.get("free").and_then(|v| v.as_bool()).unwrap_or(false);
        let se = num("std_error").filter(|s| s.is_finite());
        let unit = unit_of(name, p.get("unit").and_then(|u| u.as_str()).unwrap_or(""));
        rows.push((
            name.clone(),
            Estimate {
                value,
                unit,
                std_error: se,
                ci95: se.map(|s| [value - 1.96 * s, value + 1.96 * s]),
                determined: free && se.is_some(),
                fixed: !free,
                note: None,
            },
        ));
    }
    Ok(rows)
}
