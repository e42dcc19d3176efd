//! Fit times: a 20 000-sample hysteresis record, and a friction fit on a 100-point steady
//! sweep plus a 15 001-sample time series (both stages). Data are synthesised once, outside
//! the timed loop, from the shipped data sets' recipes (data/README.md).

use criterion::{Criterion, criterion_group, criterion_main};
use hd_ident::synth::{HysteresisExcitation, Noise, SteadySweep, TransientExcitation};
use hd_ident::synth::{synth_hysteresis, synth_steady, synth_transient};
use hd_ident::{Fixed, HysteresisData, SteadyData, TransientData, fit_friction, fit_hysteresis};
use hd_model::Params;
use std::hint::black_box;

fn bench_fits(c: &mut Criterion) {
    let p = Params::default();
    let noise = Noise { relative: 0.01, seed: 1 };
    let h = synth_hysteresis(&p, &HysteresisExcitation::default(), &noise).unwrap().columns;
    let hyst = HysteresisData::new(h[0].clone(), h[1].clone(), h[2].clone()).unwrap();
    assert_eq!(hyst.len(), 20_000);
    c.bench_function("fit hysteresis, 20000 samples", |b| {
        b.iter(|| fit_hysteresis(black_box(&hyst), &Fixed::none()).unwrap())
    });

    let mut f = Params::default();
    for s in ["Tc=0.2", "Ts=0.35", "ws=0.02", "sigma2=0.05", "sigma0=8e4", "sigma1=0.5"] {
        f.apply_assignment(s).unwrap();
    }
    let s = synth_steady(&f, &SteadySweep::default(), &noise).unwrap().columns;
    let steady = SteadyData::new(s[0].clone(), s[1].clone()).unwrap();
    let t = synth_transient(&f, &TransientExcitation::default(), &noise).unwrap().columns;
    let transient = TransientData::new(t[0].clone(), t[1].clone(), t[2].clone()).unwrap();
    c.bench_function("fit friction static, 100 points", |b| {
        b.iter(|| fit_friction(Some(black_box(&steady)), None, &Fixed::none()).unwrap())
    });
    c.bench_function("fit friction both stages, 100 + 15001 samples", |b| {
        b.iter(|| fit_friction(Some(black_box(&steady)), Some(&transient), &Fixed::none()).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench_fits
}
criterion_main!(benches);
