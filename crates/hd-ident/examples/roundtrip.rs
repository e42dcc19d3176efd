//! Synthesise data from the model and fit it back: prints the fit tables and timings.
//! `cargo run -p hd-ident --example roundtrip --release`

use hd_ident::synth::{HysteresisExcitation, Noise, SteadySweep, TransientExcitation};
use hd_ident::synth::{synth_hysteresis, synth_steady, synth_transient};
use hd_ident::{Fixed, HysteresisData, SteadyData, TransientData, fit_friction, fit_hysteresis};
use hd_model::Params;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut p = Params::default();
    let args: Vec<String> = std::env::args().skip(1).collect();
    for a in &args {
        p.apply_assignment(a)?;
    }
    let noise = Noise { relative: 0.01, seed: 3 };
    let t0 = Instant::now();
    let s = synth_hysteresis(&p, &HysteresisExcitation::default(), &noise)?;
    println!("synth hysteresis {:.3} s", t0.elapsed().as_secs_f64());
    let c = s.columns;
    let data = HysteresisData::new(c[0].clone(), c[1].clone(), c[2].clone())?;
    let fit = fit_hysteresis(&data, &Fixed::none())?;
    println!("{}", fit.report.table());

    let st = synth_steady(&p, &SteadySweep::default(), &noise)?;
    let sd = SteadyData::new(st.columns[0].clone(), st.columns[1].clone())?;
    let t0 = Instant::now();
    let tr = synth_transient(&p, &TransientExcitation::default(), &noise)?;
    println!("synth transient {:.3} s ({} rows)", t0.elapsed().as_secs_f64(), tr.columns[0].len());
    let td =
        TransientData::new(tr.columns[0].clone(), tr.columns[1].clone(), tr.columns[2].clone())?;
    let fit = fit_friction(Some(&sd), Some(&td), &Fixed::none())?;
    println!("{}", fit.report.table());
    Ok(())
}
