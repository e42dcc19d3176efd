//! `hdw design`: the voltage test that determines what a fit could not (issue #54). From a
//! compliant fit's folder (or a params file with named unknowns) and the rig's limits, an
//! input that maximises the information on the weakest directions (or D- or A-optimal),
//! scaled to the limits in simulation, compared with the default chirp and multisine, and
//! optionally checked by refits of synthesised records.

use super::design_load::{Loaded, NoiseArgs, from_fit, from_params};
use anyhow::{Result, bail};
use clap::Args;
use hd_ident::design::{Criterion, Family, Limits, design, targeted};
use hd_ident::drive::compliant::{Amplifier, NAMES};
use hd_model::error::num;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;

/// Design the next voltage test of a compliant drive.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "The information of a candidate input is the compliant fit's own exact Jacobian on a noise-free\n\
record of it (each output divided by its noise level), in relative (log) coordinates; the fitted\n\
records' information is the prior; samples where an encoder moves less than 1.5 counts to the next\n\
(its rounding a staircase, not noise) are not counted. Criteria: targeted (default with --fit: the variance along the\n\
prior's weakest directions), d (log det over every free parameter), a (relative variances of\n\
--a-params). Families: chirp, multisine (16 log-spaced lines, amplitude ∝ f^tilt, Schroeder phases),\n\
ramp (triangles with dwell at zero), mix (a multisine then ramps), spectrum (sines, ramps and the\n\
other families' best weighed from each one's own information: played one after another or as a\n\
multisine of chosen lines; searched only when named or with --family all: a design of few lines\n\
can be predicted better than its refits reach); each candidate is scaled to the\n\
largest amplitude whose simulated peak voltage, current, motor and load speed, gear deflection,\n\
transmitted torque and load travel stay within the limits, and a few family parameters are searched by Nelder–Mead.\n\n\
In closed loop (--controller FILE.toml, or --fit of a closed-loop fit) the input is the position\n\
reference [rad, on the fed-back encoder] through that controller, scaled also to --reference.\n\n\
Writes input.csv and input.parquet (t [s], u [V]; in closed loop t, reference [rad]), design.json, report.md and plots. --check N\n\
synthesises N records of the design (and of the fitted records) with fresh noise as hdw synth drive\n\
does, refits each from perturbed starts, and compares the spread with the predicted standard errors.\n\n\
Example:\n  hdw design --params data/compliant/start.toml --free R,Ke,Jj,Cj --duration 0.1 --evaluations 6 --family chirp --out out/design-demo"
)]
pub struct DesignArgs {
    /// A compliant fit's output folder (fit.json, params.toml; its records are re-read).
    #[arg(long, value_name = "DIR", conflicts_with = "params")]
    pub fit: Option<PathBuf>,
    /// A params file (hdw simulate's) of the drive, with --free.
    #[arg(long, value_name = "FILE.toml")]
    pub params: Option<PathBuf>,
    /// The unknown parameters (registry names, comma-separated): required with --params;
    /// with --fit, a subset of the fit's free ones (the others held at their fitted values).
    #[arg(long, value_delimiter = ',')]
    pub free: Vec<String>,
    /// Criterion: targeted, d or a [default: targeted with --fit, d with --params].
    #[arg(long)]
    pub criterion: Option<String>,
    /// Parameters of the A-optimal criterion (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub a_params: Vec<String>,
    /// Families searched: chirp, multisine, ramp, mix, spectrum (comma-separated); default
    /// (the first four) or all (every one).
    #[arg(long, value_delimiter = ',', default_value = "default")]
    pub family: Vec<String>,
    /// Candidates evaluated per family.
    #[arg(long, default_value_t = 40)]
    pub evaluations: usize,
    /// Closed loop: the `[controller]` (kp and kv, or p and d; saturation, delay in samples,
    /// speed_filter, feedback, amplifier) the drive runs in, from this TOML file (a fit
    /// configuration, or a file holding only that table). The design is then of the
    /// position reference. With --fit, a fit of a closed loop brings its own.
    #[arg(long, value_name = "FILE.toml", conflicts_with = "fit")]
    pub controller: Option<PathBuf>,
    /// Closed loop: peak position reference [rad, on the fed-back encoder] [default: the
    /// fitted records' peak].
    #[arg(long)]
    pub reference: Option<f64>,
    /// Peak voltage [V] [default: the fitted records' peak, else 12].
    #[arg(long)]
    pub voltage: Option<f64>,
    /// Peak current [A].
    #[arg(long)]
    pub current: Option<f64>,
    /// Peak motor speed [rad/s].
    #[arg(long)]
    pub speed: Option<f64>,
    /// Peak load speed [rad/s].
    #[arg(long)]
    pub load_speed: Option<f64>,
    /// Peak gear deflection [rad].
    #[arg(long)]
    pub deflection: Option<f64>,
    /// Peak torque the gear transmits [N·m] (its spring and memory, at the load side).
    #[arg(long)]
    pub torque: Option<f64>,
    /// The load's range of travel: its largest excursion from the starting angle, either
    /// way [rad].
    #[arg(long)]
    pub load_angle: Option<f64>,
    /// Record length [s].
    #[arg(long, default_value_t = 2.0)]
    pub duration: f64,
    /// Sample rate [Hz] [default: the fitted records', else 1000].
    #[arg(long)]
    pub rate: Option<f64>,
    /// Motor encoder counts per revolution [default: the fit's noise level, else 4096].
    #[arg(long)]
    pub motor_counts: Option<u64>,
    /// Load encoder counts per revolution [default: the fit's noise level, else 2^20].
    #[arg(long)]
    pub load_counts: Option<u64>,
    /// Current noise, standard deviation [A] [default: the fit's level, else 0.01].
    #[arg(long)]
    pub current_noise: Option<f64>,
    /// Evaluate this input (CSV or Parquet, columns t [s] and u [V], or in closed loop
    /// reference [rad], at the design's rate)
    /// instead of searching: its predicted SEs and peaks, as given (not rescaled).
    #[arg(long, value_name = "FILE")]
    pub input: Option<PathBuf>,
    /// With --fit: predict at this params file's values instead of the fitted ones (e.g.
    /// the truth of a synthetic test).
    #[arg(long, value_name = "FILE.toml")]
    pub at: Option<PathBuf>,
    /// Refit check: synthesise and fit this many records.
    #[arg(long, default_value_t = 0)]
    pub check: usize,
    /// The drive the check synthesises from (params file) [default: the designed-for drive].
    #[arg(long, value_name = "FILE.toml")]
    pub truth: Option<PathBuf>,
    /// Seed of the check's noise and starts.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
}

/// The limits of `a`, with the defaults of the fitted records.
fn limits(a: &DesignArgs) -> Result<Limits> {
    // With --fit, the fitted records' rate and peak voltage replace these defaults later.
    let (v, rate) = (a.voltage.unwrap_or(12.0), a.rate.unwrap_or(1000.0));
    for (flag, x) in [
        ("--voltage", Some(v)),
        ("--rate", Some(rate)),
        ("--duration", Some(a.duration)),
        ("--current", a.current),
        ("--speed", a.speed),
        ("--deflection", a.deflection),
        ("--load-speed", a.load_speed),
        ("--torque", a.torque),
        ("--reference", a.reference),
        ("--load-angle", a.load_angle),
    ] {
        if let Some(x) = x.filter(|x| !(x.is_finite() && *x > 0.0)) {
            bail!("{flag} {}: expected a finite value > 0", num(x));
        }
    }
    // Each limit within what a rig can mean by it (a limit of 1e-300 V or 1e300 A is a
    // typing slip, and its design would be all zeros or overflow the simulation).
    for (flag, x, lo, hi, unit) in [
        ("--voltage", Some(v), 1e-3, 1e4, "V"),
        ("--rate", Some(rate), 1.0, 1e7, "Hz"),
        ("--current", a.current, 1e-6, 1e5, "A"),
        ("--speed", a.speed, 1e-6, 1e6, "rad/s"),
        ("--deflection", a.deflection, 1e-12, 1.0, "rad"),
        ("--load-speed", a.load_speed, 1e-9, 1e6, "rad/s"),
        ("--torque", a.torque, 1e-9, 1e7, "N·m"),
        ("--reference", a.reference, 1e-9, 1e6, "rad"),
        ("--load-angle", a.load_angle, 1e-9, 1e6, "rad"),
    ] {
        if let Some(x) = x.filter(|x| !(lo..=hi).contains(x)) {
            bail!("{flag} {}: expected a limit from {lo:e} to {hi:e} {unit}", num(x));
        }
    }
    for (flag, c) in [("--motor-counts", a.motor_counts), ("--load-counts", a.load_counts)] {
        if let Some(c) = c.filter(|c| !(2..=1u64 << 40).contains(c)) {
            bail!(
                "{flag} {c}: expected an encoder resolution from 2 to 2^40 counts per revolution"
            );
        }
    }
    if let Some(x) = a.current_noise.filter(|x| !(x.is_finite() && *x > 0.0 && *x <= 1e3)) {
        bail!(
            "--current-noise {}: expected the current sensor's noise, a standard deviation > 0 and at most 1e3 A",
            num(x)
        );
    }
    let n = a.duration * rate;
    if !(20.0..=2e6).contains(&n) {
        bail!(
            "--duration {} s at --rate {} Hz gives {n:.0} samples: expected 20 to 2e6",
            num(a.duration),
            num(rate)
        );
    }
    Ok(Limits {
        reference: a.reference,
        voltage: v,
        current: a.current,
        speed: a.speed,
        deflection: a.deflection,
        load_speed: a.load_speed,
        torque: a.torque,
        load_angle: a.load_angle,
        duration: a.duration,
        rate,
    })
}

/// Run `hdw design`.
pub fn run(a: DesignArgs) -> Result<()> {
    let families: Vec<Family> = if a.family.iter().any(|f| f == "all") {
        Family::ALL.to_vec()
    } else if a.family.iter().any(|f| f == "default") {
        Family::DEFAULT.to_vec()
    } else {
        a.family
            .iter()
            .map(|f| {
                Family::parse(f).ok_or_else(|| {
                    anyhow::anyhow!(
                        "--family {f}: expected chirp, multisine, ramp, mix, spectrum, default or all"
                    )
                })
            })
            .collect::<Result<_>>()?
    };
    if a.evaluations < 2 {
        bail!("--evaluations {}: expected at least 2", a.evaluations);
    }
    let lim = limits(&a)?;
    let noise = NoiseArgs {
        motor_counts: a.motor_counts,
        load_counts: a.load_counts,
        current_noise: a.current_noise,
    };
    let t0 = Instant::now();
    let mut loaded: Loaded = match (&a.fit, &a.params) {
        (Some(dir), _) => from_fit(dir, &a.free, a.at.as_deref(), lim, &noise)?,
        (None, Some(p)) => from_params(p, &a.free, lim, &noise, a.controller.as_deref())?,
        (None, None) => {
            bail!("give --fit DIR (a compliant fit's output folder) or --params FILE with --free")
        }
    };
    // Defaults from the fitted records: their rate and peak voltage.
    if let Some(r) = loaded.records.first() {
        let p = &mut loaded.problem;
        let same_rate = a.rate.is_none() || (p.limits.rate * r.h - 1.0).abs() <= 1e-9;
        if a.rate.is_none() {
            p.limits.rate = 1.0 / r.h;
        }
        // The fit measured its count's integration error on its own records only. A designed
        // input may reach further up in frequency, and nothing measures its integration, so
        // the design takes at least the count the drive's rates alone ask for (on the docs'
        // worked example, a 3-427 Hz design integrated at the fit's 6 substeps instead of 18
        // had the predicted SE of Jz 16 % higher); at another rate, that count.
        let unmeasured =
            hd_ident::drive::compliant::substeps_for(&p.values, p.spec.n, 1.0 / p.limits.rate);
        p.spec.substeps = if same_rate { p.spec.substeps.max(unmeasured) } else { unmeasured };
        let peak = |x: &mut dyn Iterator<Item = &f64>| x.fold(0.0f64, |m, v| m.max(v.abs()));
        let voltage_driven = p.closed.as_ref().is_none_or(|l| l.amplifier == Amplifier::Voltage);
        if a.voltage.is_none() && voltage_driven {
            p.limits.voltage = peak(&mut loaded.records.iter().flat_map(|r| r.u.iter()));
        }
        if a.reference.is_none() && p.closed.is_some() {
            let refs = loaded.records.iter().filter_map(|r| r.closed.as_ref());
            p.limits.reference = Some(peak(&mut refs.flat_map(|c| c.reference.iter())));
        }
    }
    if let Some(l) = &loaded.problem.closed {
        let rate = loaded.problem.limits.rate;
        if (l.controller.h * rate - 1.0).abs() > 1e-9 {
            bail!(
                "--rate {}: the loop's controller runs at {} Hz; a closed-loop design is sampled at the controller's rate",
                num(rate),
                num(1.0 / l.controller.h)
            );
        }
    }
    match (&loaded.problem.closed, loaded.problem.limits.reference) {
        (Some(_), None) => bail!(
            "--reference: a closed-loop design needs the reference's peak [rad, on the fed-back encoder]"
        ),
        (None, Some(_)) => bail!(
            "--reference: a position reference needs a loop (--controller FILE.toml, or --fit of a closed-loop fit)"
        ),
        _ => {}
    }
    let problem = &loaded.problem;
    let slot = |name: &str| -> Result<usize> {
        let k = NAMES
            .iter()
            .position(|n| n.eq_ignore_ascii_case(name))
            .ok_or_else(|| anyhow::anyhow!("--a-params {name}: not a parameter"))?;
        problem.free.iter().position(|&f| f == k).ok_or_else(|| {
            anyhow::anyhow!("--a-params {name}: not a free parameter of this design")
        })
    };
    let criterion =
        match a.criterion.as_deref().unwrap_or(if a.fit.is_some() { "targeted" } else { "d" }) {
            "targeted" => targeted(problem),
            "d" | "D" => Criterion::D,
            "a" | "A" => {
                if a.a_params.is_empty() {
                    bail!("--criterion a: name the parameters with --a-params");
                }
                Criterion::A(a.a_params.iter().map(|n| slot(n)).collect::<Result<_>>()?)
            }
            other => bail!("--criterion {other}: expected targeted, d or a"),
        };
    let bar = ProgressBar::new((families.len() * a.evaluations) as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} design {pos}/{len} candidates {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let done = std::sync::atomic::AtomicU64::new(0);
    let outcome = match &a.input {
        Some(path) => {
            let column = if problem.closed.is_some() { "reference" } else { "u" };
            let cols = hd_io::read_columns(path, &["t", column])?;
            given_rate(path, &cols[0], problem.limits.rate)?;
            hd_ident::design::given(problem, criterion, &cols[1])
        }
        None => design(problem, criterion, &families, a.evaluations, &|f, _, c| {
            bar.set_position(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            bar.set_message(format!("({}; criterion {c:.4e})", f.name()));
        }),
    };
    bar.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    let check =
        if a.check > 0 { Some(super::design_check::check(&a, &loaded, &outcome)?) } else { None };
    super::design_out::write(&a.out, &loaded, &outcome, secs, check.as_ref())
}

/// An input given with `--input` is played at the design's rate: its time column must step
/// by 1/`rate` (within 0.1 %) and hold at least 20 samples.
fn given_rate(path: &std::path::Path, t: &[f64], rate: f64) -> Result<()> {
    if t.len() < 20 {
        bail!("{}: {} samples; expected an input of at least 20 samples", path.display(), t.len());
    }
    let step = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    let off = (step * rate - 1.0).abs();
    if off.is_nan() || off > 1e-3 {
        bail!(
            "{}: column 't' steps by {} s on average; expected the design's sample period 1/{} Hz = {} s (give --rate, or resample the input)",
            path.display(),
            num(step),
            num(rate),
            num(1.0 / rate)
        );
    }
    if let Some(k) = t.windows(2).position(|w| ((w[1] - w[0]) * rate - 1.0).abs() > 1e-3) {
        bail!(
            "{}: column 't', row {}: step {} s; expected a uniform sample period of {} s",
            path.display(),
            k + 2,
            num(t[k + 1] - t[k]),
            num(1.0 / rate)
        );
    }
    Ok(())
}
