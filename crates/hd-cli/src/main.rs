//! `hdw`, the harmonic-drive workbench command line.
//!
//! Each subcommand lives in its own module under `cmd/`; arguments are checked into a
//! configuration before any work starts, errors go to stderr with a non-zero exit.

mod cmd;
mod report;
mod stages;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Nonlinear dynamics of harmonic (strain-wave) drives: simulate, sweep, identify, explore.
#[derive(Parser, Debug)]
#[command(
    name = "hdw",
    version,
    about,
    after_help = "Example:\n  hdw simulate --out out/demo        # the seed case: full model, 24 V, 50 Hz, 0.2 s\n  hdw simulate --variant damped --set Kbar=5e5 --voltage 12 --out out/soft\n\nEach subcommand's --help ends with a worked example."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate one run; writes trace.parquet, metrics.json and response.svg.
    Simulate(cmd::simulate::SimulateArgs),
    /// Fit parameters to recorded data, with uncertainty; writes fit.json and plots.
    Fit(cmd::fit::FitArgs),
    /// Write synthetic data from the model (CSV or Parquet) to check identifiability.
    Synth(cmd::synth::SynthArgs),
    /// Model parameters from a catalogue's stiffness data (K1, K2, K3, T1, T2, hysteresis loss).
    Datasheet(cmd::datasheet::DatasheetArgs),
    /// Run a study file: many runs in parallel → runs.parquet, study.json, report.md.
    Study(cmd::study::StudyArgs),
    /// Merge a study's shards (runs-shard-*.parquet) into runs.parquet and write its report.
    Report(cmd::report::ReportArgs),
    /// Global sensitivity (Sobol' indices, Morris screening); `--check ishigami` self-check.
    Sensitivity(cmd::sensitivity::SensitivityArgs),
    /// Summaries, filters, group-by tables and pivots of result tables (Parquet).
    Explore(cmd::explore::ExploreArgs),
    /// Heatmaps and line plots of result tables; trace signals and Tb–θ loops of runs.
    Plot(cmd::plot::PlotArgs),
    /// Export the drive for other tools: `hdw export fmu` writes a co-simulation FMU.
    Export(cmd::export::ExportArgs),
    /// Fit every log of a fleet (manifest or path pattern) → fits.parquet; drift and alarms.
    Fleet(cmd::fleet::FleetArgs),
    /// Design the next voltage test of a compliant drive: input.csv, design.json, report.md.
    Design(cmd::design::DesignArgs),
}

fn main() -> ExitCode {
    if let Err(why) = hd_model::cpu::check() {
        eprintln!("error: {why}");
        return ExitCode::FAILURE;
    }
    let cli = Cli::parse();
    // Ctrl-C, `kill` or a closed terminal: remove the temporaries of unfinished outputs
    // (and a study's lock) before exiting; what was committed stays.
    if let Err(e) = hd_io::pending::remove_on_signal() {
        eprintln!("error: cannot install the interrupt handler: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Fit(args) => cmd::fit::run(args),
        Command::Synth(args) => cmd::synth::run(args),
        Command::Datasheet(args) => cmd::datasheet::run(args),
        Command::Study(args) => cmd::study::run(args),
        Command::Report(args) => cmd::report::run(args),
        Command::Sensitivity(args) => cmd::sensitivity::run(args),
        Command::Explore(args) => cmd::explore::run(args),
        Command::Plot(args) => cmd::plot::run(args),
        Command::Export(args) => cmd::export::run(args),
        Command::Fleet(args) => cmd::fleet::run(args),
        Command::Design(args) => cmd::design::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Nothing was written into the folders this command created: leave no empty ones.
            hd_io::pending::remove_empty_created_dirs();
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
