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
    after_help = "The FMU runs the drive exactly as `hdw simulate` would (same laws, solver and tolerances,\nthe controller when the params select one), one communication step at a time; with\n--fixed-substeps M each step is M fixed Runge-Kutta substeps instead.\n  inputs      u [V] (open loop) and T_load [N·m], held over each communication step\n  outputs     the trace columns: i, theta_j, omega_j, theta_z, omega_z, theta, z, s, Tb, Tf, K, C0\n              (closed loop also u, ref, error, u_ff, tf_hat, tb_hat)\n  parameters  every registry parameter, start values from --params/--set\nThe FMU's binary is hd-fmu's shared library, built by cargo beside hdw\n(target/<profile>/libhd_fmu.so); --lib or $HDW_FMU_LIB name another one, which must be a\nLinux x86-64 ELF shared library exporting the FMI functions (anything else is refused).\n\nExample:\n  hdw export fmu --out out/drive.fmu\n  hdw export fmu --stiffness maxwell-slip --set ms_n=10 --fmi 3 --out out/slip.fmu\n  hdw export fmu --fixed-substeps 4 --out out/drive-fixed.fmu\n  hdw datasheet --k1 6.7e4 --k2 1.1e5 --k3 1.2e5 --t1 29 --t2 108 --hysteresis-loss 1 --out out/ds\n  hdw export fmu --params out/ds/catalogue.toml --out out/catalogue.fmu\n  python -c \"import fmpy; fmpy.dump('out/drive.fmu')\""
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
    /// Integrate each communication step in M fixed Runge–Kutta substeps (the bristle
    /// carried by its integrating factor, as the fits integrate) instead of the adaptive
    /// solver: a fixed cost per step, for real-time and HIL hosts. Open-loop drives of the
    /// `full` variant with an algebraic current (L = 0); keep (fastest rate × substep)
    /// well below 1, e.g. M ≥ 2 at 10 kHz for the seed drive.
    #[arg(long, value_name = "M", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub fixed_substeps: Option<u32>,
    /// The FMU binary to pack [default: libhd_fmu.so beside the hdw executable]: a Linux
    /// x86-64 ELF shared library exporting fmi2DoStep (FMI 2) or fmi3DoStep (FMI 3).
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
    let binary = read_library(&lib, version)?;
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
    if let Some(m) = a.fixed_substeps
        && let Err(e) = hd_model::compliant::fixed_drive(&cfg)
    {
        bail!("--fixed-substeps {m}: {e}");
    }
    let toml = hd_fmu::config::to_toml_fixed(&cfg, a.fixed_substeps).map_err(anyhow::Error::msg)?;
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
    let what = match a.fixed_substeps {
        Some(m) => format!("{what}; {m} fixed substeps per communication step"),
        None => what.to_string(),
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
        if std::fs::metadata(&p).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
            bail!("FMU binary {} does not exist (expected hd-fmu's {name})", p.display());
        }
        return Ok(p);
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

/// Largest FMU binary read [bytes]: hd-fmu's library is a few MB (tens with debug
/// information); anything far larger is not it.
const MAX_LIBRARY_BYTES: u64 = 1 << 30;

/// The bytes of the FMU binary at `path`, checked to be what the archive's platform folder
/// promises: a regular file, a 64-bit x86-64 ELF shared library (the folder is
/// `binaries/linux64` or `binaries/x86_64-linux`), exporting the FMI functions of
/// `version`. Anything else (a folder, a device, a text file, an executable, a macOS or
/// Windows library) is refused with the path and what was expected.
fn read_library(path: &Path, version: FmiVersion) -> Result<Vec<u8>> {
    let shown = path.display();
    let expected = format!(
        "expected hd-fmu's lib{MODEL_IDENTIFIER}.so, a Linux x86-64 ELF shared library for {}",
        version.binary_dir()
    );
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read FMU binary {shown}"))?;
    if meta.is_dir() {
        bail!("FMU binary {shown} is a folder: {expected}");
    }
    if !meta.is_file() {
        bail!("FMU binary {shown} is not a regular file (a device or pipe?): {expected}");
    }
    if meta.len() > MAX_LIBRARY_BYTES {
        bail!(
            "FMU binary {shown} is {} MB, more than the {} MB a shared library of hd-fmu could be: {expected}",
            meta.len() >> 20,
            MAX_LIBRARY_BYTES >> 20
        );
    }
    let bytes = std::fs::read(path).with_context(|| format!("cannot read FMU binary {shown}"))?;
    library_kind(&bytes)
        .map_err(|what| anyhow::anyhow!("FMU binary {shown} is {what}: {expected}"))?;
    // The dynamic symbol table names every exported function.
    let needed = match version {
        FmiVersion::Fmi2 => "fmi2DoStep",
        FmiVersion::Fmi3 => "fmi3DoStep",
    };
    if !bytes.windows(needed.len()).any(|w| w == needed.as_bytes()) {
        bail!(
            "FMU binary {shown} is a shared library without {needed}, not an FMU binary: {expected}"
        );
    }
    Ok(bytes)
}

/// Whether `bytes` are a 64-bit little-endian x86-64 ELF shared object; otherwise what
/// they are instead, in words.
fn library_kind(bytes: &[u8]) -> Result<(), String> {
    let u16_at = |i: usize| bytes.get(i..i + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let magic = bytes.get(..4).unwrap_or(bytes);
    if magic == b"\x7fELF" {
        if bytes.len() < 64 {
            return Err("a truncated ELF file".to_string());
        }
        if bytes[4] != 2 || bytes[5] != 1 {
            return Err("a 32-bit or big-endian ELF file".to_string());
        }
        match u16_at(16) {
            Some(3) => {}
            Some(1) => return Err("an ELF object file (.o), not a shared library".to_string()),
            Some(2) => return Err("an ELF executable, not a shared library".to_string()),
            Some(t) => return Err(format!("an ELF file of type {t}, not a shared library")),
            None => return Err("a truncated ELF file".to_string()),
        }
        return match u16_at(18) {
            Some(62) => Ok(()),
            Some(183) => Err("an ELF shared library for aarch64 (ARM), not x86-64".to_string()),
            Some(m) => Err(format!("an ELF shared library for machine {m}, not x86-64 (62)")),
            None => Err("a truncated ELF file".to_string()),
        };
    }
    const MACH_O: [[u8; 4]; 5] = [
        [0xfe, 0xed, 0xfa, 0xce],
        [0xfe, 0xed, 0xfa, 0xcf],
        [0xce, 0xfa, 0xed, 0xfe],
        [0xcf, 0xfa, 0xed, 0xfe],
        [0xca, 0xfe, 0xba, 0xbe],
    ];
    if MACH_O.iter().any(|m| magic == m) {
        return Err("a Mach-O (macOS) binary; the FMU's binary folder is for Linux".to_string());
    }
    if magic.starts_with(b"MZ") {
        return Err("a PE (Windows) binary; the FMU's binary folder is for Linux".to_string());
    }
    if bytes.is_empty() {
        return Err("empty".to_string());
    }
    let text = bytes.iter().take(512).all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace());
    Err(if text {
        "a text file, not a shared library (no ELF magic)".to_string()
    } else {
        "not a shared library (no ELF magic)".to_string()
    })
}
