//! `hdw plot`: heatmaps and line plots of result tables, and trace signals of chosen runs,
//! drawn with `hd-plot` from data aggregated in `hd-io`.

use anyhow::{Context, Result, bail};
use clap::Args;
use hd_io::explore::{AggFn, Curve, Dataset, Key, Kind, label};
use hd_plot::Series;
use std::path::{Path, PathBuf};

/// Most runs plotted from a traces file when no --run is given.
const MAX_DEFAULT_RUNS: usize = 10;
/// Most facet files one command writes.
const MAX_FACETS: usize = 50;

/// Plot result tables: heatmaps, lines, facets; trace signals and Tb–θ loops of runs.
#[derive(Args, Debug)]
#[command(
    after_help = "Run tables (runs.parquet, a folder of shards or a pattern):\n  --x COL --y COL --color METRIC   heatmap of METRIC over the distinct (x, y) values\n  --x COL --line METRIC [--by COL]  METRIC against x, one curve per value of --by\nRows that share a cell or a point are combined with --agg (default mean); the command says\nwhen it combined more than one. --facet COL writes one file per value of COL, named\nOUT-COL-VALUE.svg (or .png) beside OUT.\n\nTraces (traces.parquet, the trace.parquet of `hdw simulate`, or a folder with --run/--loop):\n  --run RUN_ID... --x t --line theta_z   a signal against time, one curve per run\n  --run RUN_ID... --loop                 the Tb–θ hysteresis loop of each run\nWithout --run, every run of the file is drawn if there are at most 10.\n\nExample:\n  hdw plot out/table4 --filter 'part == damped-sine' --x Kbar --y C0bar --color thz_amp --log-x --log-y --out out/plots/amp.svg\n  hdw plot out/table4 --filter 'part == full-sine' --x c --line thz_amp --by friction_scale --out amp.png\n  hdw plot out/table4 --filter 'part in [damped-sine, damped-step]' --x Kbar --y C0bar --color tb_peak --facet part --out damped.svg\n  hdw plot out/seed-voltage --x voltage --line thz_amp --by variant --out v.svg\n  hdw study studies/step.toml --out out/step-study   # a study that keeps its traces\n  hdw plot out/step-study --run 06c86012071f63bd --x t --line theta_z --out thz.svg\n  hdw plot out/demo/trace.parquet --loop --out loop.svg"
)]
pub struct PlotArgs {
    /// A Parquet file, a folder or a pattern such as 'DIR/runs-*.parquet'.
    #[arg(value_name = "FILE_OR_DIR")]
    pub source: String,
    /// Keep rows where EXPR holds, e.g. 'Kbar > 5e5' (repeatable; see `hdw explore --help`).
    #[arg(long, value_name = "EXPR")]
    pub filter: Vec<String>,
    /// Column on the x axis (traces: default t).
    #[arg(long, value_name = "COL")]
    pub x: Option<String>,
    /// Column on the y axis of a heatmap.
    #[arg(long, value_name = "COL")]
    pub y: Option<String>,
    /// Metric shown as colour in a heatmap over --x and --y.
    #[arg(long, value_name = "METRIC", conflicts_with = "line")]
    pub color: Option<String>,
    /// Metric (or trace signal) drawn as a line against --x.
    #[arg(long, value_name = "METRIC")]
    pub line: Option<String>,
    /// One curve per value of this column (run tables; traces use run_id).
    #[arg(long, value_name = "COL")]
    pub by: Option<String>,
    /// One file per value of this column.
    #[arg(long, value_name = "COL")]
    pub facet: Option<String>,
    /// How rows sharing a cell or point are combined: mean, median, min, max, count, sum, std.
    #[arg(long, default_value = "mean", value_name = "FN")]
    pub agg: String,
    /// Runs to draw from a traces file (repeatable).
    #[arg(long = "run", value_name = "RUN_ID")]
    pub runs: Vec<String>,
    /// Draw the torque–deflection loop Tb against theta of each run.
    #[arg(long = "loop")]
    pub hysteresis_loop: bool,
    /// Logarithmic x axis.
    #[arg(long)]
    pub log_x: bool,
    /// Logarithmic y axis (heatmaps).
    #[arg(long)]
    pub log_y: bool,
    /// Plot title (default: what is plotted).
    #[arg(long)]
    pub title: Option<String>,
    /// Output file; the extension (.svg or .png) picks the format.
    #[arg(long, value_name = "FILE.svg|png")]
    pub out: PathBuf,
}

/// What to draw, checked before any data is read.
#[derive(Debug, PartialEq)]
pub enum Plan {
    /// A heatmap of `value` over `x` and `y`.
    Heatmap { x: String, y: String, value: String },
    /// `value` against `x`, one curve per `by`.
    Lines { x: String, value: String, by: Option<String> },
    /// Trace signal `y` against `x` for the chosen runs.
    Trace { x: String, y: String },
}

/// Check the options into a plan.
pub fn plan(a: &PlotArgs) -> Result<Plan> {
    let traces = a.hysteresis_loop || !a.runs.is_empty();
    if a.hysteresis_loop {
        if a.x.is_some() || a.line.is_some() || a.y.is_some() || a.color.is_some() {
            bail!("--loop draws Tb against theta; drop --x, --y, --line and --color");
        }
        return Ok(Plan::Trace { x: "theta".into(), y: "Tb".into() });
    }
    if traces {
        let Some(y) = &a.line else { bail!("--run needs --line SIGNAL (e.g. theta_z) or --loop") };
        return Ok(Plan::Trace { x: a.x.clone().unwrap_or_else(|| "t".into()), y: y.clone() });
    }
    match (&a.x, &a.y, &a.color, &a.line) {
        (Some(x), Some(y), Some(c), None) => {
            Ok(Plan::Heatmap { x: x.clone(), y: y.clone(), value: c.clone() })
        }
        (Some(_), None, Some(_), None) => bail!("--color needs both --x and --y (a heatmap)"),
        (Some(x), None, None, Some(l)) => {
            Ok(Plan::Lines { x: x.clone(), value: l.clone(), by: a.by.clone() })
        }
        (Some(_), Some(_), None, Some(_)) => {
            bail!("--y is for heatmaps (with --color); for several curves use --by COL")
        }
        (None, ..) if a.line.is_some() => {
            Ok(Plan::Trace { x: "t".into(), y: a.line.clone().unwrap_or_default() })
        }
        _ => bail!(
            "choose --x COL --y COL --color METRIC (heatmap), --x COL --line METRIC (lines), or --run/--loop (traces)"
        ),
    }
}

/// Run `hdw plot`.
pub fn run(args: PlotArgs) -> Result<()> {
    let plan = plan(&args)?;
    let func = AggFn::parse(&args.agg, "--agg")?;
    let want = matches!(plan, Plan::Trace { .. }).then_some(Kind::Traces);
    let ds = Dataset::open(&args.source, want)?.filtered(&args.filter)?;
    // A traces file holds signals of runs, not one row per run: draw them as traces.
    let plan = match (plan, ds.source().kind) {
        (Plan::Lines { x, value, by: None }, Kind::Traces) => Plan::Trace { x, y: value },
        (Plan::Trace { .. }, Kind::Runs) => {
            bail!(
                "--run, --loop and trace signals need a traces file, not a run table; e.g. DIR/traces.parquet"
            )
        }
        (p, _) => p,
    };
    if let Plan::Trace { x, y } = &plan {
        if args.facet.is_some() || args.by.is_some() {
            bail!("--facet and --by are for run tables; traces get one curve per --run");
        }
        return plot_traces(&args, ds, x, y);
    }
    if args.log_y && !matches!(plan, Plan::Heatmap { .. }) {
        bail!("--log-y is for heatmaps");
    }
    let Some(facet) = &args.facet else {
        return draw(&args, &plan, &ds, func, &args.out, "");
    };
    let values = ds.distinct(facet)?;
    if values.len() > MAX_FACETS {
        bail!(
            "--facet {facet}: {} values, more than {MAX_FACETS} files; filter first or facet by a swept column",
            values.len()
        );
    }
    for v in values {
        let part = ds.clone().where_in(facet, std::slice::from_ref(&v))?;
        let out = facet_path(&args.out, facet, &v);
        draw(&args, &plan, &part, func, &out, &format!(", {facet} = {v}"))?;
    }
    Ok(())
}

/// `DIR/NAME.svg` → `DIR/NAME-COL-VALUE.svg`, keeping only safe characters of the value.
pub fn facet_path(out: &Path, column: &str, value: &Key) -> PathBuf {
    let safe: String = value
        .to_string()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || "._+-".contains(c) { c } else { '_' })
        .collect();
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("plot");
    let ext = out.extension().and_then(|s| s.to_str()).unwrap_or("svg");
    out.with_file_name(format!("{stem}-{column}-{safe}.{ext}"))
}

/// Draw one heatmap or line figure to `out`.
fn draw(
    args: &PlotArgs,
    plan: &Plan,
    ds: &Dataset,
    func: AggFn,
    out: &Path,
    suffix: &str,
) -> Result<()> {
    let combined = match plan {
        Plan::Heatmap { x, y, value } => {
            let g = ds.grid(x, y, value, func)?;
            let title = args
                .title
                .clone()
                .unwrap_or_else(|| format!("{value} ({}) over {x} and {y}{suffix}", func.name()));
            let color_label = format!("{} ({})", label(value), func.name());
            if args.log_x {
                note_log_drops("--log-x", x, "columns of cells", &g.xs);
            }
            if args.log_y {
                note_log_drops("--log-y", y, "rows of cells", &g.ys);
            }
            hd_plot::heatmap(
                out,
                &title,
                &label(x),
                &label(y),
                &g.xs,
                &g.ys,
                &g.values,
                &color_label,
                args.log_x,
                args.log_y,
            )?;
            eprintln!("wrote {} ({} × {} cells)", out.display(), g.xs.len(), g.ys.len());
            g.most_per_cell
        }
        Plan::Lines { x, value, by } => {
            let (curves, most) = ds.curves(x, value, by.as_deref(), Some(func))?;
            let title = args
                .title
                .clone()
                .unwrap_or_else(|| format!("{value} ({}) against {x}{suffix}", func.name()));
            let y_label = format!("{} ({})", label(value), func.name());
            if args.log_x {
                let xs: Vec<f64> = curves.iter().flat_map(|c| c.x.iter().copied()).collect();
                note_log_drops("--log-x", x, "points", &xs);
            }
            hd_plot::line_plot(out, &title, &label(x), &y_label, &series(curves), args.log_x)?;
            eprintln!("wrote {}", out.display());
            most
        }
        Plan::Trace { .. } => 1,
    };
    if combined > 1 {
        eprintln!(
            "note: up to {combined} rows share a point and were combined with {}; separate them with --filter, --by or --facet",
            func.name()
        );
    }
    Ok(())
}

/// Say how many of `values` (of column `column`) a log axis leaves out: zero and negative
/// numbers have no place on it.
fn note_log_drops(flag: &str, column: &str, what: &str, values: &[f64]) {
    let dropped = values.iter().filter(|v| **v <= 0.0).count();
    if dropped > 0 {
        eprintln!(
            "note: {flag} leaves out {dropped} of {} {what} with {column} <= 0; plot without {flag}, or --filter '{column} > 0' to say so",
            values.len()
        );
    }
}

fn series(curves: Vec<Curve>) -> Vec<Series> {
    curves.into_iter().map(|c| Series::new(c.name, c.x, c.y)).collect()
}

/// Trace signals of the chosen runs, one curve per run.
fn plot_traces(args: &PlotArgs, ds: Dataset, x: &str, y: &str) -> Result<()> {
    let has_ids = ds.has_column("run_id");
    let ds = if !has_ids {
        if !args.runs.is_empty() {
            bail!("{} holds one run (no run_id column); drop --run", args.source);
        }
        ds
    } else if args.runs.is_empty() {
        let ids = ds.distinct("run_id")?;
        if ids.len() > MAX_DEFAULT_RUNS {
            let some: Vec<String> = ids.iter().take(5).map(Key::to_string).collect();
            bail!(
                "{} holds {} runs; choose some with --run (e.g. --run {})",
                args.source,
                ids.len(),
                some.join(" --run ")
            );
        }
        ds
    } else {
        let keys: Vec<Key> = args.runs.iter().map(|r| Key::Text(Some(r.clone()))).collect();
        let ds = ds.where_in("run_id", &keys)?;
        let found = ds.distinct("run_id")?;
        let missing: Vec<&String> =
            args.runs.iter().filter(|r| !found.contains(&Key::Text(Some((*r).clone())))).collect();
        if !missing.is_empty() {
            bail!(
                "no trace of run {} in {}",
                missing.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "),
                args.source
            );
        }
        ds
    };
    let by = has_ids.then_some("run_id");
    let (mut curves, _) = ds.curves(x, y, by, None)?;
    for c in &mut curves {
        c.name = c.name.trim_start_matches("run_id=").to_string();
    }
    let what = if args.hysteresis_loop {
        "Torque–deflection loop".to_string()
    } else {
        format!("{y} against {x}")
    };
    let title = args.title.clone().unwrap_or(what);
    if args.log_x {
        let xs: Vec<f64> = curves.iter().flat_map(|c| c.x.iter().copied()).collect();
        note_log_drops("--log-x", x, "points", &xs);
    }
    hd_plot::line_plot(&args.out, &title, &label(x), &label(y), &series(curves), args.log_x)
        .with_context(|| format!("plotting {}", args.source))?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: PlotArgs,
    }

    fn p(argv: &[&str]) -> Result<Plan> {
        plan(
            &Cli::try_parse_from([&["hdw", "runs.parquet", "--out", "a.svg"], argv].concat())?.args,
        )
    }

    #[test]
    fn options_become_one_plan() {
        let h = p(&["--x", "Kbar", "--y", "voltage", "--color", "thz_amp"]).unwrap();
        assert!(matches!(h, Plan::Heatmap { .. }));
        assert!(matches!(p(&["--x", "freq", "--line", "thz_amp"]).unwrap(), Plan::Lines { .. }));
        assert_eq!(
            p(&["--run", "r1", "--line", "theta_z"]).unwrap(),
            Plan::Trace { x: "t".into(), y: "theta_z".into() }
        );
        assert!(matches!(p(&["--loop"]).unwrap(), Plan::Trace { .. }));
        assert!(p(&["--x", "Kbar", "--color", "thz_amp"]).is_err());
        assert!(p(&["--loop", "--x", "t"]).is_err());
        assert!(p(&[]).is_err());
    }

    #[test]
    fn facet_file_names() {
        let k = Key::Num(5e5);
        assert_eq!(
            facet_path(Path::new("o/amp.svg"), "Kbar", &k),
            Path::new("o/amp-Kbar-500000.svg")
        );
        let v = Key::Text(Some("a b/c".into()));
        assert_eq!(facet_path(Path::new("x.png"), "variant", &v), Path::new("x-variant-a_b_c.png"));
    }
}
