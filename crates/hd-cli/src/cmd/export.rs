//! `hdw export fmu`: the drive as a co-simulation FMU (FMI 2.0 or 3.0) for Simulink,
//! Modelica tools and FMPy. The archive holds modelDescription.xml and
//! resources/model.toml (both from hd-fmu) and the hd-fmu shared library cargo built.

use super::control_args::ControlArgs;
use super::model_args::ModelArgs;
use super::simulate::SimulateArgs;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use hd_fmu::{CONFIG_FILE, FmiVersion, MODEL_IDENTIFIER};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Export the drive for other tools.
#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(subcommand)]
    what: ExportWhat,
}

#[derive(Subcommand, Debug)]
enum ExportWhat {
    /// A co-simulation FMU (FMI 2.0 or 3.0) of the drive, as `hdw simulate` runs it.
    Fmu(FmuArgs),
}

/// Write a co-simulation FMU of the drive.
#[derive(Args, Debug)]
#[command(
    after_help = "The FMU runs the drive exactly as `hdw simulate` would (same laws, solver and tolerances,\nthe controller when the params select one), one communication step at a time.\n  inputs      u [V] (open loop) and T_load [N·m], held over each communication step\n  outputs     the trace columns: i, theta_j, omega_j, theta_z, omega_z, theta, z, s, Tb, Tf, K, C0\n              (closed loop also u, ref, error, u_ff, tf_hat, tb_hat)\n  parameters  every registry parameter, start values from --params/--set\nThe FMU's binary is hd-fmu's shared library, built by cargo beside hdw\n(target/<profile>/libhd_fmu.so); --lib or $HDW_FMU_LIB name another one.\n\nExample:\n  hdw export fmu --out out/drive.fmu\n  hdw export fmu --stiffness maxwell-slip --set ms_n=10 --fmi 3 --out out/slip.fmu\n  hdw datasheet --k1 6.7e4 --k2 1.1e5 --k3 1.2e5 --t1 29 --t2 108 --hysteresis-loss 1 --out out/ds\n  hdw export fmu --params out/ds/catalogue.toml --out out/catalogue.fmu\n  python -c \"import fmpy; fmpy.dump('out/drive.fmu')\""
)]
pub struct FmuArgs {
    /// Parameters, stiffness law, variant and the solver inside the FMU (as `hdw simulate`
    /// takes them; --set gives start values).
    #[command(flatten)]
    pub model: ModelArgs,
    /// FMI version: 2 (Simulink, Modelica tools) or 3.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
    pub fmi: u8,
    /// Stop time of the FMU's default experiment [s].
    #[arg(long, default_value_t = 0.2)]
    pub t_end: f64,
    /// Closed-loop control (its reference runs inside the FMU).
    #[command(flatten)]
    pub control: ControlArgs,
    /// The FMU binary to pack [default: libhd_fmu.so beside the hdw executable].
    #[arg(long, value_name = "FILE.so")]
    pub lib: Option<PathBuf>,
    /// The FMU file to write.
    #[arg(long, value_name = "FILE.fmu")]
    pub out: PathBuf,
}

/// Run `hdw export …`.
pub fn run(args: ExportArgs) -> Result<()> {
    match args.what {
        ExportWhat::Fmu(a) => run_fmu(a),
    }
}

fn run_fmu(a: FmuArgs) -> Result<()> {
    let version = if a.fmi == 3 { FmiVersion::Fmi3 } else { FmiVersion::Fmi2 };
    let lib = find_library(a.lib.as_deref())?;
    let binary = std::fs::read(&lib).with_context(|| format!("cannot read {}", lib.display()))?;
    let out = a.out.clone();
    // The run configuration exactly as `hdw simulate` checks it from the same options.
    let sim = SimulateArgs {
        model: a.model,
        input: "constant".to_string(),
        voltage: 0.0,
        freq: 50.0,
        t_end: a.t_end,
        dt_out: 0.0,
        cycles: 5,
        no_trace: true,
        max_output_values: 0,
        control: a.control,
        out: PathBuf::new(),
    };
    let cfg = super::simulate::config(&sim)?;
    let toml = hd_fmu::config::to_toml(&cfg).map_err(anyhow::Error::msg)?;
    let token = hd_fmu::config::token(&toml);
    let xml = hd_fmu::model_description(&hd_fmu::config::for_fmu(&cfg), version, &token);
    let so = format!("{}/{MODEL_IDENTIFIER}.so", version.binary_dir());
    let files: [(&str, &[u8], u32); 3] = [
        ("modelDescription.xml", xml.as_bytes(), 0o644),
        (&so, &binary, 0o755),
        (&format!("resources/{CONFIG_FILE}"), toml.as_bytes(), 0o644),
    ];
    let bytes = zip_files(&files)?;
    hd_io::atomic::write_atomically(&out, |f| {
        f.write_all(&bytes).map_err(|e| hd_io::IoError::fs(&out, e))
    })?;
    let what = match &cfg.controller {
        Some(_) => "closed loop, input T_load",
        None => "open loop, inputs u and T_load",
    };
    eprintln!(
        "wrote {} (FMI {}, co-simulation, {} variant, {} stiffness, {what}; {} kB)",
        out.display(),
        a.fmi,
        cfg.variant,
        cfg.stiffness.name(),
        bytes.len() / 1024
    );
    Ok(())
}

/// The archive of `files` (name, contents, Unix mode), deflated.
fn zip_files(files: &[(&str, &[u8], u32)]) -> Result<Vec<u8>> {
    use zip::write::SimpleFileOptions;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, data, mode) in files {
        let options = SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .unix_permissions(*mode);
        zip.start_file(*name, options).with_context(|| format!("cannot add {name} to the FMU"))?;
        zip.write_all(data)?;
    }
    Ok(zip.finish().context("cannot finish the FMU archive")?.into_inner())
}

/// The FMU binary: `--lib`, `$HDW_FMU_LIB`, or libhd_fmu.so where cargo put it beside
/// the running hdw (target/<profile>/, or its deps/ folder).
fn find_library(given: Option<&Path>) -> Result<PathBuf> {
    let name = format!("lib{MODEL_IDENTIFIER}.so");
    if let Some(p) =
        given.map(Path::to_path_buf).or_else(|| std::env::var_os("HDW_FMU_LIB").map(PathBuf::from))
    {
        if p.is_file() {
            return Ok(p);
        }
        bail!("FMU binary {} does not exist (expected hd-fmu's {name})", p.display());
    }
    let exe = std::env::current_exe().context("cannot locate the hdw executable")?;
    let dir = exe.parent().map(Path::to_path_buf).unwrap_or_default();
    // A test binary runs from target/<profile>/deps/.
    let candidates = [dir.join(&name), dir.join("deps").join(&name), dir.join("..").join(&name)];
    if let Some(p) = candidates.iter().find(|p| p.is_file()) {
        return Ok(p.clone());
    }
    let profile = if cfg!(debug_assertions) { "" } else { "--release " };
    bail!(
        "the FMU binary {name} is not beside hdw (looked in {}); build it with `cargo build {profile}-p hd-fmu`, or name it with --lib",
        dir.display()
    )
}
