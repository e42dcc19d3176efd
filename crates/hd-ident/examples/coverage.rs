//! Empirical coverage of the 95 % intervals over many noise seeds.
//! `cargo run -p hd-ident --example coverage -- hysteresis|friction SEEDS [NAME=VALUE]...`

use hd_ident::synth::{HysteresisExcitation, Noise, SteadySweep, TransientExcitation};
use hd_ident::synth::{synth_hysteresis, synth_steady, synth_transient};
use hd_ident::{
    FitReport, Fixed, HysteresisData, SteadyData, TransientData, fit_friction, fit_hysteresis,
};
use hd_model::Params;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let kind = args[0].clone();
    let seeds: u64 = args[1].parse()?;
    let mut p = Params::default();
    let mut amplitude = 1e-3;
    let mut rel = 0.01;
    let mut samples = 20_000;
    for a in &args[2..] {
        if let Some(v) = a.strip_prefix("amp=") {
            amplitude = v.parse()?;
        } else if let Some(v) = a.strip_prefix("noise=") {
            rel = v.parse()?;
        } else if let Some(v) = a.strip_prefix("samples=") {
            samples = v.parse()?;
        } else {
            p.apply_assignment(a)?;
        }
    }
    let names: Vec<&str> = if kind == "hysteresis" {
        vec!["a", "b", "c", "mem_A", "mem_B"]
    } else {
        vec!["Tc", "Ts", "ws", "sigma2", "sigma0", "sigma1"]
    };
    let mut covered = vec![0; names.len()];
    let mut worst = vec![0.0f64; names.len()];
    let mut z2 = vec![0.0f64; names.len()];
    let mut time = 0.0;
    for seed in 1..=seeds {
        let noise = Noise { relative: rel, seed };
        let report: FitReport = if kind == "hysteresis" {
            let exc = HysteresisExcitation { amplitude, samples, ..Default::default() };
            let c = synth_hysteresis(&p, &exc, &noise)?.columns;
            let d = HysteresisData::new(c[0].clone(), c[1].clone(), c[2].clone())?;
            fit_hysteresis(&d, &Fixed::none())?.report
        } else {
            let s = synth_steady(&p, &SteadySweep::default(), &noise)?.columns;
            let t = synth_transient(
                &p,
                &TransientExcitation::default(),
                &Noise { relative: 0.01, seed: seed + 1000 },
            )?
            .columns;
            let sd = SteadyData::new(s[0].clone(), s[1].clone())?;
            let td = TransientData::new(t[0].clone(), t[1].clone(), t[2].clone())?;
            fit_friction(Some(&sd), Some(&td), &Fixed::none())?.report
        };
        time += report.wall_time_s;
        for (k, n) in names.iter().enumerate() {
            let e = report.parameters.get(n).unwrap();
            let truth = p.get(n)?;
            if e.ci95.is_some_and(|[lo, hi]| lo <= truth && truth <= hi) {
                covered[k] += 1;
            }
            if let Some(se) = e.std_error {
                z2[k] += ((e.value - truth) / se).powi(2);
            }
            let rel =
                if truth != 0.0 { (e.value / truth - 1.0).abs() } else { (e.value - truth).abs() };
            worst[k] = worst[k].max(rel);
        }
    }
    for (k, n) in names.iter().enumerate() {
        println!(
            "{n:>7}: covered {}/{seeds}, worst rel. error {:.3} %, rms z {:.2}",
            covered[k],
            100.0 * worst[k],
            (z2[k] / seeds as f64).sqrt()
        );
    }
    println!("mean fit time {:.3} s", time / seeds as f64);
    Ok(())
}
