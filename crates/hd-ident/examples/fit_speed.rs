//! Time the identifier's core on the records of the fit-speed benchmark (issue 36), in
//! release, without file output: `cargo run --release -p hd-ident --example fit_speed --
//! tribometer [asymmetric]` fits all LuGre parameters to the shipped tribometer
//! recording (speed from the position, as `hdw fit friction --position-column` does);
//! `… -- synth-hysteresis N FILE` writes a noisy sum-of-sines record of N samples over
//! 50 s (as `hdw synth hysteresis --samples N --duration 50`) as raw little-endian f64
//! triples, and `… -- hysteresis FILE` fits the memory law to it. Prints the fit time and
//! RMS; run it under `/usr/bin/time -v` for the peak memory.

use hd_ident::derivative::{DEFAULT_ORDER, choose_half_window, savitzky_golay_derivative};
use hd_ident::fit_hysteresis;
use hd_ident::synth::{HysteresisExcitation, Noise, synth_hysteresis};
use hd_ident::{Fixed, FrictionOptions, HysteresisData, TransientData, fit_friction_with};
use hd_model::Params;
use std::io::{Read, Write};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("tribometer") => {
            let asymmetric = args.get(1).is_some_and(|a| a == "asymmetric");
            let path =
                concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/tribometer-reciprocating.txt");
            let text = std::fs::read_to_string(path)?;
            let (mut t, mut x, mut f) = (Vec::new(), Vec::new(), Vec::new());
            for line in text.lines().skip(1) {
                let c: Vec<f64> = line.split('\t').map(|c| c.trim().parse().unwrap()).collect();
                t.push(c[0]);
                x.push(c[2] * 1e-3);
                f.push(c[3] * -1e-6);
            }
            let h = choose_half_window(&t, &x, DEFAULT_ORDER).half_window;
            let v = savitzky_golay_derivative(&t, &x, h, DEFAULT_ORDER)?;
            let d = TransientData::new(t, v, f)?;
            let opts = FrictionOptions { asymmetric, offset: asymmetric };
            let t0 = Instant::now();
            let fit = fit_friction_with(None, Some(&d), &Fixed::none(), opts)?;
            let wall = t0.elapsed().as_secs_f64();
            println!("{}", fit.report.table());
            for e in &fit.report.refinement_ends {
                println!("end: {e}");
            }
            println!(
                "tribometer asymmetric={asymmetric}: fit {wall:.3} s, RMS {:.4}",
                fit.report.rms
            );
        }
        Some("synth-hysteresis") => {
            let n: usize = args[1].parse()?;
            let exc = HysteresisExcitation { samples: n, duration: 50.0, ..Default::default() };
            let s = synth_hysteresis(&Params::default(), &exc, &Noise { relative: 0.01, seed: 1 })?;
            let mut out = std::io::BufWriter::new(std::fs::File::create(&args[2])?);
            for i in 0..n {
                for c in &s.columns[..3] {
                    out.write_all(&c[i].to_le_bytes())?;
                }
            }
        }
        Some("hysteresis") => {
            let file = std::fs::File::open(&args[1])?;
            let n = file.metadata()?.len() as usize / 24;
            let mut input = std::io::BufReader::new(file);
            let mut cols = [Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n)];
            let mut row = [0u8; 24];
            for _ in 0..n {
                input.read_exact(&mut row)?;
                for (c, b) in cols.iter_mut().zip(row.chunks_exact(8)) {
                    c.push(f64::from_le_bytes(b.try_into()?));
                }
            }
            let [t, th, y] = cols;
            let d = HysteresisData::new(t, th, y)?;
            let t0 = Instant::now();
            let fit = fit_hysteresis(&d, &Fixed::none())?;
            let wall = t0.elapsed().as_secs_f64();
            println!("{}", fit.report.table());
            println!("hysteresis {n} samples: fit {wall:.3} s, RMS {:.4}", fit.report.rms);
        }
        _ => eprintln!(
            "usage: fit_speed tribometer [asymmetric] | synth-hysteresis N FILE | hysteresis FILE"
        ),
    }
    Ok(())
}
