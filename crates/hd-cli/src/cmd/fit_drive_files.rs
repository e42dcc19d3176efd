//! The checks `hdw fit drive` makes before any fit work on the files it reads and on the
//! records' columns: a compliant configuration's params file (size and type, as `simulate`
//! checks one), its start values against `[bounds]`, every record a regular file, no record
//! column that is constant (a dead sensor), and the rigid fit's inverse-model start inside
//! the `[bounds]` the configuration gives.

use super::DriveArgs;
use crate::cmd::common::{check_data_file, read_params_text};
use anyhow::{Result, bail};
use hd_ident::drive::compliant::CompliantConfig;
use hd_ident::drive::compliant::params::{NAMES, P};
use hd_ident::drive::config::validate::inside;
use hd_ident::drive::config::validate_compliant::{self, starts_in_bounds};
use hd_ident::drive::{DriveConfig, IdimFit};
use std::path::Path;

/// Whether `name` is a file `hdw fit drive` writes into its folder.
pub fn is_fit_output(name: &str) -> bool {
    matches!(name, "fit.json" | "params.toml" | "report.md" | "series.parquet")
        || name.ends_with(".svg")
}

/// Refuse a record column that holds one value on every row (`cols`: column name, values
/// as read and scaled): a dead sensor, an amplifier that was off, or the wrong column.
pub fn refuse_dead(path: &Path, cols: &[(&str, &[f64])]) -> Result<()> {
    for (name, v) in cols {
        if let Some(&first) = v.first()
            && v.len() > 1
            && v.iter().all(|x| *x == first)
        {
            bail!(
                "{}: column '{name}' is constant ({first} on all {} rows): a dead sensor, an amplifier that was off, or the wrong column; the fit cannot use it",
                path.display(),
                v.len()
            );
        }
    }
    Ok(())
}

/// Every check of a compliant configuration `text` (of `args.config`) that comes before
/// the fit: the configuration's numbers, the params file, the start values inside
/// `[bounds]`, every record (and `--validate`'s) a regular file whose signal columns move.
pub fn check_compliant(args: &DriveArgs, text: &str) -> Result<()> {
    let file = args.config.display().to_string();
    let cfg = CompliantConfig::parse(text, &file)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let mut p = hd_model::Params::default();
    if let Some(f) = &cfg.params_file {
        let path = base.join(f);
        let params = read_params_text(&path)?;
        hd_model::params_file::apply_params_toml(&mut p, &params, &path.display().to_string())?;
    }
    let mut start = [0.0; P];
    for (k, n) in NAMES.iter().enumerate() {
        start[k] = p.get(n)?;
    }
    starts_in_bounds(&cfg, &file, &start)?;
    let mut records: Vec<(String, std::path::PathBuf)> = cfg
        .experiment
        .iter()
        .map(|e| (format!("record of [[experiment]] '{}'", e.name), base.join(&e.file)))
        .collect();
    if let Some(v) = &args.validate {
        records.push(("--validate record".into(), v.clone()));
    }
    for (what, path) in &records {
        check_data_file(path, what)?;
    }
    // The signals a dead sensor or a switched-off amplifier leaves constant.
    let e = &cfg.experiment[0];
    let mut rows = usize::MAX;
    for ((_, path), ec) in records.iter().zip(cfg.experiment.iter().chain(std::iter::repeat(e))) {
        let mut names: Vec<&str> = vec![&ec.motor, &ec.load];
        names.extend(ec.voltage.as_deref().or(ec.command.as_deref()));
        names.extend(ec.current.as_deref());
        let cols = hd_io::read_columns(path, &names)?;
        let pairs: Vec<(&str, &[f64])> =
            names.iter().zip(&cols).map(|(n, c)| (*n, c.as_slice())).collect();
        refuse_dead(path, &pairs)?;
        rows = rows.min(cols.first().map_or(0, Vec::len));
    }
    validate_compliant::with_records(&cfg, &file, rows)?;
    Ok(())
}

/// The inverse-model start `idim` inside every `[bounds]` pair of `cfg` whose parameter
/// `[params]` does not start (the fit would otherwise start from the bound it was moved to).
pub fn idim_in_bounds(cfg: &DriveConfig, file: &str, idim: Option<&IdimFit>) -> Result<()> {
    let Some(fit) = idim else { return Ok(()) };
    for (name, &v) in fit.names.iter().zip(&fit.values) {
        if let Some(&[lo, hi]) = cfg.bounds.get(*name)
            && !cfg.params.contains_key(*name)
        {
            inside(file, name, v, lo, hi, "the inverse-model start; give [params] a start inside")?;
        }
    }
    Ok(())
}
