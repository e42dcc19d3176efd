//! `hdw datasheet`: model parameters from a harmonic drive's catalogue entry — the
//! catalogue stiffness law (three spring rates, rounded corners, optional hysteresis loss)
//! and the seed law's spring a, b, c matched over the rated range, with a plot of both.

use super::common::{ensure_dir, stage_json};
use anyhow::{Result, anyhow, bail};
use clap::Args;
use hd_ident::datasheet::{lost_motion, match_spring};
use hd_io::atomic::Staged;
use hd_model::laws::catalogue::{CatalogueCurve, loop_width, with_loss};
use hd_model::laws::stiffness::ElasticCurve;
use hd_plot::{Series, overlay_plot};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Radians per arc minute.
const ARCMIN: f64 = std::f64::consts::PI / (180.0 * 60.0);

/// Parameters from a catalogue's stiffness data.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "The catalogue curve: K1 up to T1, K2 from T1 to T2, K3 beyond, the same in both directions, each\n\
corner rounded over 10 % of the shorter segment so the slope is continuous (outside the corners the\n\
curve is exactly the three segments). A hysteresis loss (the loop width at zero torque after loading\n\
to ±rated torque) is realised by 4 Maxwell-slip elements whose yield deflections spread up to half\n\
the rated deflection; their stiffness is taken off the curve so that a first loading still follows\n\
the catalogue. Lost motion (catalogues: the width at zero torque between ±4 % of rated torque) is\n\
compared with the model's own; the model has no backlash, so it does not fit it.\n\n\
Outputs (in --out DIR):\n  catalogue.toml    the catalogue law: cat_K1..cat_K3 [N·m/rad], cat_T1, cat_T2, cat_rated [N·m],\n                    cat_loss [rad] and the slip elements ms_k<i> [N·m/rad], ms_f<i> [N·m]\n  seed-params.toml  a, b, c of the seed law matched over ±rated deflection (a params file for\n                    hdw simulate / hdw synth --params), with the match error in a comment\n  datasheet.json    all of the above, the deflection at the rated torque, the match's RMS and\n                    largest torque error [N·m], the model's hysteresis loss and lost motion [arcmin]\n  curves.svg        torque against deflection: catalogue curve, matched cubic, and the loop\n\n\
Example (the worked example of data/catalogue/README.md):\n  hdw datasheet --k1 6.7e4 --k2 1.1e5 --k3 1.2e5 --t1 29 --t2 108 --hysteresis-loss 1 --out out/datasheet"
)]
pub struct DatasheetArgs {
    /// Spring rate up to T1 [N·m/rad].
    #[arg(long, allow_hyphen_values = true)]
    pub k1: f64,
    /// Spring rate from T1 to T2 [N·m/rad].
    #[arg(long, allow_hyphen_values = true)]
    pub k2: f64,
    /// Spring rate above T2 [N·m/rad].
    #[arg(long, allow_hyphen_values = true)]
    pub k3: f64,
    /// First corner torque [N·m].
    #[arg(long, allow_hyphen_values = true)]
    pub t1: f64,
    /// Second corner torque [N·m].
    #[arg(long, allow_hyphen_values = true)]
    pub t2: f64,
    /// Rated torque [N·m]: the range of the match and of the hysteresis loop (default T2).
    #[arg(long, allow_hyphen_values = true)]
    pub rated_torque: Option<f64>,
    /// Hysteresis loss [arcmin]: loop width at zero torque after ±rated torque.
    #[arg(long, value_name = "ARCMIN", allow_hyphen_values = true)]
    pub hysteresis_loss: Option<f64>,
    /// Catalogue lost motion [arcmin], compared with the model's (not fitted: no backlash).
    #[arg(long, value_name = "ARCMIN", allow_hyphen_values = true)]
    pub lost_motion: Option<f64>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/datasheet")]
    pub out: PathBuf,
}

/// `text` written to a temporary beside `path`, committed with the other outputs.
fn stage_text(path: &std::path::Path, text: &str) -> Result<Staged> {
    let mut staged = Staged::new(path)?;
    staged.write_with(|f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(path, e))
    })?;
    Ok(staged)
}

/// Run `hdw datasheet`.
pub fn run(a: DatasheetArgs) -> Result<()> {
    // The law's message names the field (K1, T2, …); the flag is its lower case.
    let curve = CatalogueCurve::new(a.k1, a.k2, a.k3, a.t1, a.t2)
        .map_err(|e| anyhow!("--{}{}", e[..2].to_lowercase(), &e[2..]))?;
    let rated = a.rated_torque.unwrap_or(a.t2);
    if !(rated.is_finite() && rated > 0.0) {
        anyhow::bail!("--rated-torque {rated}: expected a finite value > 0 [N·m]");
    }
    let loss_arcmin = a.hysteresis_loss.unwrap_or(0.0);
    let law = with_loss(curve, loss_arcmin * ARCMIN, rated)
        .map_err(|e| anyhow!("--hysteresis-loss {loss_arcmin} arcmin: {e}"))?;
    if let Some(lm) = a.lost_motion
        && !(lm.is_finite() && lm >= 0.0)
    {
        anyhow::bail!("--lost-motion {lm}: expected a finite value >= 0 [arcmin]");
    }
    let m = match_spring(&curve, rated);
    let th_r = m.rated_deflection;
    let model_loss = loop_width(&law, th_r) / ARCMIN;
    let model_lm = lost_motion(&law, rated) / ARCMIN;
    // Values the files will hold must be ones `hdw simulate` accepts: extreme inputs
    // (1e308) overflow the match to zeros or infinities.
    let mut written = vec![
        ("cat_K1", a.k1),
        ("cat_K2", a.k2),
        ("cat_K3", a.k3),
        ("cat_T1", a.t1),
        ("cat_T2", a.t2),
        ("cat_rated", rated),
        ("cat_loss", loss_arcmin * ARCMIN),
        ("a", m.a),
        ("b", m.b),
        ("c", m.c),
    ];
    let names: Vec<(String, String)> =
        (1..=law.elements.len()).map(|i| (format!("ms_k{i}"), format!("ms_f{i}"))).collect();
    for ((k, f), e) in names.iter().zip(&law.elements) {
        written.push((k.as_str(), e.k));
        written.push((f.as_str(), e.f));
    }
    for (name, v) in written {
        let ok = hd_model::registry::lookup(name).and_then(|p| p.check(v)).is_ok();
        if !ok || !v.is_finite() {
            bail!(
                "these catalogue values give {name} = {v:e}, which a params file cannot hold (hdw simulate would refuse it): check the units (N·m/rad, N·m, arcmin) and magnitudes"
            );
        }
    }
    for (what, v) in [
        ("rated deflection", th_r),
        ("model hysteresis loss", model_loss),
        ("model lost motion", model_lm),
    ] {
        if !v.is_finite() {
            bail!(
                "these catalogue values give a {what} of {v}: check the units (N·m/rad, N·m, arcmin) and magnitudes"
            );
        }
    }
    let dir = ensure_dir(&a.out)?;

    let mut cat =
        String::from("# Catalogue stiffness law written by hdw datasheet; units in brackets.\n");
    let _ = writeln!(cat, "stiffness = \"catalogue\"");
    for (k, v, u) in [
        ("cat_K1", a.k1, "N·m/rad"),
        ("cat_K2", a.k2, "N·m/rad"),
        ("cat_K3", a.k3, "N·m/rad"),
        ("cat_T1", a.t1, "N·m"),
        ("cat_T2", a.t2, "N·m"),
        ("cat_rated", rated, "N·m"),
        ("cat_loss", loss_arcmin * ARCMIN, "rad"),
    ] {
        let _ = writeln!(cat, "{k} = {v:e}  # [{u}]");
    }
    if !law.elements.is_empty() {
        let _ = writeln!(
            cat,
            "# Maxwell-slip elements realising the hysteresis loss ({loss_arcmin} arcmin):"
        );
        for (i, e) in law.elements.iter().enumerate() {
            let _ = writeln!(
                cat,
                "ms_k{} = {:e}  # [N·m/rad]\nms_f{} = {:e}  # [N·m]",
                i + 1,
                e.k,
                i + 1,
                e.f
            );
        }
    }
    // The four outputs are staged and renamed into place together.
    let mut staged = vec![stage_text(&dir.join("catalogue.toml"), &cat)?];
    let seed = format!(
        "# Seed-law spring matched to the catalogue curve over ±{th_r:.4e} rad (±{rated} N·m) by hdw datasheet:\n\
         # RMS torque error {:.3e} N·m, largest {:.3e} N·m ({:.2} % of the rated torque).\n\
         a = {:e}  # [N·m/rad³]\nb = {:e}  # [N·m/rad²]\nc = {:e}  # [N·m/rad]\n",
        m.rms_error,
        m.max_error,
        100.0 * m.max_error / rated,
        m.a,
        m.b,
        m.c
    );
    staged.push(stage_text(&dir.join("seed-params.toml"), &seed)?);
    let summary = serde_json::json!({
        "catalogue": {"cat_K1": a.k1, "cat_K2": a.k2, "cat_K3": a.k3, "cat_T1": a.t1, "cat_T2": a.t2,
                      "rated_torque": rated, "cat_loss": loss_arcmin * ARCMIN},
        "slip_elements": law.elements.iter().map(|e| serde_json::json!({"k": e.k, "f": e.f})).collect::<Vec<_>>(),
        "rated_deflection": th_r,
        "seed_spring": m,
        "hysteresis_loss_arcmin": {"catalogue": a.hysteresis_loss, "model": model_loss},
        "lost_motion_arcmin": {"catalogue": a.lost_motion, "model": model_lm},
    });
    staged.push(stage_json(&dir.join("datasheet.json"), &summary)?);

    let n = 801;
    let th: Vec<f64> = (0..n).map(|k| th_r * (2.0 * k as f64 / (n - 1) as f64 - 1.0)).collect();
    let spring = m.spring();
    let mut series = vec![
        Series::new(
            "catalogue curve",
            th.clone(),
            th.iter().map(|&x| curve.spring_torque(x)).collect(),
        ),
        Series::new(
            "seed law a·θ³ + b·θ² + c·θ",
            th.clone(),
            th.iter().map(|&x| spring.torque(x)).collect(),
        ),
    ];
    if !law.elements.is_empty() {
        let path: Vec<f64> = th.iter().chain(th.iter().rev()).chain(th.iter()).copied().collect();
        let tb = law.torque_along(&path);
        let k0 = 2 * n - n / 2; // after the first rise and fall: the steady loop
        series.push(Series::new(
            "catalogue law with hysteresis (loop)",
            path[k0..].to_vec(),
            tb[k0..].to_vec(),
        ));
    }
    let plot = Staged::new(&dir.join("curves.svg"))?;
    overlay_plot(
        plot.path(),
        "Catalogue stiffness and the matched seed-law spring",
        "θ [rad]",
        "T [N·m]",
        &series,
    )?;
    staged.push(plot);
    hd_io::atomic::commit(staged, &[])?;
    println!(
        "deflection at the rated torque {rated} N·m: {th_r:.4e} rad\nseed spring: a = {:.4e} N·m/rad³, b = {:.3e} N·m/rad², c = {:.4e} N·m/rad; RMS error {:.3e} N·m, largest {:.3e} N·m\nhysteresis loss: model {model_loss:.4} arcmin{}\nlost motion (±4 % rated torque): model {model_lm:.4} arcmin{}",
        m.a,
        m.b,
        m.c,
        m.rms_error,
        m.max_error,
        a.hysteresis_loss.map_or(String::new(), |v| format!(" (catalogue {v} arcmin)")),
        a.lost_motion.map_or(String::new(), |v| format!(
            " (catalogue {v} arcmin; the difference is backlash, which the model lacks)"
        )),
    );
    eprintln!("wrote {}", dir.display());
    Ok(())
}
